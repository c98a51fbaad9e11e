"""The discrepancy workflow: replay a record with the nominal model, find where it disagrees
beyond the noise, name the missing effect(s), add them with fitted parameters, and show the
held-out gap shrink.

One core for every setup (:mod:`.core`: forward selection behind the :class:`~.setup_protocol.Setup`
protocol, judged by the rules of :mod:`.selection`; output :mod:`.report`), two kinds of setups:

* the benches (:mod:`.bench_setup`): ``series_bench`` (blocked output: a replay of the input's
  history; inertia load: the load simulated in segments from its measured state) and
  ``parallel_bench``, replayed by the Numba engine (:mod:`.replay`), candidates fitted grey-box
  (:mod:`.candidates`), model file :mod:`.benchmodel` (shared with ``fsarm synth``), the
  recorded inputs' own errors :mod:`.input_errors` (the synthetic batteries that test all this
  live in the repository's ``tests/batteries``);
* the arm (:mod:`.arm`): records replayed closed loop by the simulator (:mod:`.arm_fit`), model
  file :mod:`.arm_modelfile`, synthetic records :mod:`.arm_synth`.

Entry points: :func:`diagnose_record` (``fsarm diagnose``: any record), :func:`diagnose` (the
benches), :func:`.arm.diagnose_arm` (the arm); residual statistics in :mod:`.residuals`; the
effect text of ``fsarm synth --effect`` in :mod:`.effect_text`.
"""

from __future__ import annotations

from typing import Any

from fsarm_sim.discrepancy.bench_setup import diagnose
from fsarm_sim.discrepancy.core import Diagnosis, Setup, UnsupportedSetupError
from fsarm_sim.records.measured import Dataset

__all__ = ["Diagnosis", "Setup", "UnsupportedSetupError", "diagnose", "diagnose_record"]


def diagnose_record(ds: Dataset, *, max_effects: int | None = None) -> Diagnosis[Any]:
    """Diagnose a record of any setup: the benches' :func:`diagnose` or the arm's
    :func:`.arm.diagnose_arm` (at most its own ``MAX_EFFECTS``). ``max_effects``: None, each
    setup's default."""
    if ds.setup == "arm":
        from fsarm_sim.discrepancy import arm

        n = arm.MAX_EFFECTS if max_effects is None else min(max_effects, arm.MAX_EFFECTS)
        return arm.diagnose_arm(ds, max_effects=n)
    return diagnose(ds) if max_effects is None else diagnose(ds, max_effects=max_effects)
