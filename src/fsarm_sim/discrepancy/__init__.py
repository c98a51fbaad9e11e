"""The discrepancy workflow: replay a bench record with the nominal model, find where it
disagrees beyond the noise, name the missing effect(s), add them with fitted parameters, and show
the held-out gap shrink.

Entry point: :func:`diagnose` (``fsarm diagnose``). Modules: :mod:`.replay` (Numba replay of the
bench setups from the shared effect kernels), :mod:`.residuals` (noise floor, NRMSE, BIC,
signatures), :mod:`.candidates` (grey-box fits of each effect), :mod:`.selection` (forward
selection with held-out BIC), :mod:`.report` (JSON, model file, plots), :mod:`.benchmodel`
(the model file format shared with ``fsarm synth``), :mod:`.battery` (the synthetic battery).

Setups: ``series_bench`` (blocked output: a replay of the input's history; inertia load: the
load simulated in segments from its measured state) and ``parallel_bench``. ``arm`` datasets are
validated (:mod:`fsarm_sim.measured`) but not replayed yet; the plan: rebuild the run from the
sidecar (shaft, payload, gains, control period) with :func:`fsarm_sim.model.build_spec`, drive
it closed loop with the recorded references (q*_ref, qd*_ref, qdd*_ref columns -> the reference
table), compare q3 and the shaft twist theta_m - i_G2 q3 on held-out blocks; refit the nominal
parameters (stiffness per twist sign, K_b, the stated payload) by least squares over batched
MuJoCo rollouts (:mod:`fsarm_sim.batch`); candidates: ``payload_error``
(:mod:`fsarm_sim.effects.payload_error`, checked against MuJoCo's gravity) and the shaft/bending
effects through the simulator's own switches (Maxwell-slip, conduit). Coulomb friction, backlash,
delay and offsets on the arm need hooks in :func:`fsarm_sim.physics.shaft_torque` first.
"""

from __future__ import annotations

from fsarm_sim.discrepancy.selection import Diagnosis, UnsupportedSetupError, diagnose

__all__ = ["Diagnosis", "UnsupportedSetupError", "diagnose"]
