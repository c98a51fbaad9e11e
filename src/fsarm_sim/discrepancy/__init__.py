"""The discrepancy workflow: replay a bench record with the nominal model, find where it
disagrees beyond the noise, name the missing effect(s), add them with fitted parameters, and show
the held-out gap shrink.

Entry point: :func:`diagnose` (``fsarm diagnose``). Modules: :mod:`.replay` (Numba replay of the
bench setups from the shared effect kernels), :mod:`.residuals` (noise floor, NRMSE, BIC,
signatures), :mod:`.candidates` (grey-box fits of each effect), :mod:`.selection` (forward
selection with held-out BIC), :mod:`.report` (JSON, model file, plots), :mod:`.benchmodel`
(the model file format shared with ``fsarm synth``), :mod:`.battery` (the synthetic battery).

Setups: ``series_bench`` (blocked output: a replay of the input's history; inertia load: the
load simulated in segments from its measured state) and ``parallel_bench``. ``arm`` records are
replayed closed loop by :mod:`.arm` (the simulator with the recorded references and the run's
controller; :func:`.arm.diagnose_arm`, which ``fsarm diagnose`` calls for ``setup == "arm"``;
output in :mod:`.arm_report`). :func:`diagnose` itself covers the benches only.
"""

from __future__ import annotations

from fsarm_sim.discrepancy.selection import Diagnosis, UnsupportedSetupError, diagnose

__all__ = ["Diagnosis", "UnsupportedSetupError", "diagnose"]
