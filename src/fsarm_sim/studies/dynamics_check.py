"""Pinocchio referees MuJoCo: mass matrix, bias, forward dynamics, eq. 5-7 structure, trajectories.

A MuJoCo number counts only once Pinocchio agrees with it. Each check states its tolerance and
the measured value (``CheckResult``); ``run_checks`` runs them all (``fsarm check-dynamics``).

1. mass matrix      ``mj_fullM``            vs ``pin.crba`` (+ J a a^T of the shaft tendon)
2. bias             ``qfrc_bias``           vs ``pin.rnea(q, v, 0)``
3. forward dynamics MuJoCo ``qacc`` with the shaft callbacks on vs ``pin.aba`` with the same
                    constitutive forces (``physics.passive_forces``) - joint damping + motor forces
4. structure        seed 000 eq. 5-7 (S, B, M_R, K_SEA, K_PEA) measured on Pinocchio / MuJoCo and
                    compared with the values the MJCF implies
5. controller       the bias and inertia diagonal ``physics.control`` reads vs Pinocchio's
6. trajectory       MuJoCo RK4 on ``fig14-sine`` vs an independent RK4 of the same closed loop
                    on Pinocchio ABA, with convergence orders in the time step
7. energy           per transmission, the free arm bent 45 deg with every dissipation off keeps
                    its total energy (``energy_drift_j``, :mod:`fsarm_sim.studies.energy_check`)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim.simulation import check_duration
from fsarm_sim.studies import energy_check
from fsarm_sim.studies.dynamics_pointwise import CheckResult
from fsarm_sim.studies.dynamics_pointwise import Pair as Pair
from fsarm_sim.studies.dynamics_pointwise import check_bias as check_bias
from fsarm_sim.studies.dynamics_pointwise import check_controller_inputs as check_controller_inputs
from fsarm_sim.studies.dynamics_pointwise import check_mass_matrix as check_mass_matrix
from fsarm_sim.studies.dynamics_pointwise import check_qacc as check_qacc
from fsarm_sim.studies.dynamics_pointwise import hold_table as hold_table
from fsarm_sim.studies.dynamics_pointwise import make_pair as make_pair
from fsarm_sim.studies.dynamics_pointwise import open_loop as open_loop
from fsarm_sim.studies.dynamics_structure import ElasticJointStructure
from fsarm_sim.studies.dynamics_structure import check_structure as check_structure
from fsarm_sim.studies.dynamics_structure import elastic_structure as elastic_structure
from fsarm_sim.studies.dynamics_trajectory import TRAJECTORY_DTS as TRAJECTORY_DTS
from fsarm_sim.studies.dynamics_trajectory import TrajectoryStudy
from fsarm_sim.studies.dynamics_trajectory import check_trajectory as check_trajectory
from fsarm_sim.studies.dynamics_trajectory import trajectory_study as trajectory_study

# --- all checks ------------------------------------------------------------------------------

DEFAULT_SAMPLES = 200
DEFAULT_DURATION_S = 4.0  # one period of the Fig. 14 sine (0 -> 90 deg -> 0)
MAX_TRAJECTORY_S = 60.0  # longer studies take hours (fine Pinocchio reference step)


@dataclass(frozen=True)
class DynamicsReport:
    checks: tuple[CheckResult, ...]
    structure: ElasticJointStructure
    trajectory: TrajectoryStudy | None
    samples: int
    models: tuple[str, ...]

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def measured(self, key: str) -> float:
        for c in self.checks:
            if c.key == key:
                return c.measured
        raise KeyError(key)

    def as_dict(self) -> dict[str, object]:
        qacc = next(c for c in self.checks if c.key == "qacc")
        out: dict[str, object] = {
            "passed": self.passed,
            "samples_per_model": self.samples,
            "models": list(self.models),
            "mass_matrix_max_abs_err": self.measured("mass_matrix"),
            "bias_max_abs_err": self.measured("bias"),
            "qacc_max_rel_err": qacc.measured,
            "qacc_max_abs_err": qacc.extra["max_abs_err"],
            "qacc_max_abs_err_links": qacc.extra["max_abs_err_links"],
            "controller_inputs_max_abs_err": self.measured("controller_inputs"),
            "structure_max_rel_err": self.structure.max_error,
            "structure": [
                {
                    "entry": e.name,
                    "measured": e.measured,
                    "expected": e.expected,
                    "unit": e.unit,
                    "rel_err": e.error,
                }
                for e in self.structure.entries
            ],
            "m_sea_home_kgm2": self.structure.m_sea_home.tolist(),
            "stiffness_x_winding": self.structure.k_sea_pos.tolist(),
            "stiffness_x_unwinding": self.structure.k_sea_neg.tolist(),
            "checks": [c.as_dict() for c in self.checks],
        }
        energy = next((c for c in self.checks if c.key == "energy"), None)
        if energy is not None:
            out["energy_drift_j"] = dict(energy.extra)
        if self.trajectory is not None:
            t = self.trajectory
            out.update(
                trajectory_max_abs_err_rad=t.rows[0].mujoco_vs_reference_rad,
                trajectory_same_dt_max_abs_err_rad=max(
                    r.mujoco_vs_pinocchio_same_dt_rad for r in t.rows
                ),
                trajectory_scenario=t.scenario,
                trajectory_duration_s=t.duration_s,
                trajectory_reference_dt_s=t.reference_dt_s,
                mujoco_euler_default_err_rad=t.mujoco_euler_default_rad,
                convergence=[r.__dict__ for r in t.rows],
            )
        return out


def check_models(shaft_inertia_kgm2: float = 0.0) -> list[tuple[str, SimConfig]]:
    """The runs checks 1-3 and 5 sample (controller off so the check sets the motor commands)."""
    if not math.isfinite(shaft_inertia_kgm2) or shaft_inertia_kgm2 < 0.0:
        raise InvalidParameterError(
            f"shaft inertia must be >= 0 kg m^2, got {shaft_inertia_kgm2!r}"
        )
    cat = load_catalogue()
    models = [
        ("default shaft, no payload", open_loop(SimConfig())),
        (
            "15 kg payload, Maxwell-slip hysteresis on",
            open_loop(SimConfig(payload_kg=15.0, shaft=cat.shaft(series_hysteresis=True))),
        ),
    ]
    if shaft_inertia_kgm2 > 0.0:
        shaft = replace(cat.shaft(), inertia_kgm2=shaft_inertia_kgm2)
        models.append(
            (
                f"eq. 1 shaft inertia J = {shaft_inertia_kgm2:g} kg m^2",
                open_loop(SimConfig(shaft=shaft)),
            )
        )
    return models


def run_checks(
    samples: int = DEFAULT_SAMPLES,
    duration_s: float = DEFAULT_DURATION_S,
    dts: tuple[float, ...] = TRAJECTORY_DTS,
    shaft_inertia_kgm2: float = 0.0,
    trajectory: bool = True,
    energy: bool = True,
    progress: Callable[[str, int, int], None] | None = None,
) -> DynamicsReport:
    """Every check of this module at the given size; ``progress(step, done, total)`` is called
    before each step (the CLI's progress bar)."""
    if samples < 1:
        raise InvalidParameterError(f"samples must be >= 1, got {samples}")
    if trajectory and check_duration(duration_s) > MAX_TRAJECTORY_S:
        raise InvalidParameterError(
            f"trajectory duration must be at most {MAX_TRAJECTORY_S:g} s (the study steps "
            f"Pinocchio at a fine reference step), got {duration_s!r}"
        )
    if not (math.isfinite(shaft_inertia_kgm2) and shaft_inertia_kgm2 >= 0.0):
        raise InvalidParameterError(
            f"shaft inertia must be a finite number of kg*m^2 >= 0 (0: skip), "
            f"got {shaft_inertia_kgm2!r}"
        )
    names = ["models", "mass matrix", "bias forces", "accelerations", "controller inputs"]
    names += ["trajectory (MuJoCo vs Pinocchio)"] * trajectory + ["energy"] * energy
    done = iter(range(len(names)))

    def step(name: str) -> None:
        if progress is not None:
            progress(name, next(done), len(names))

    step("models")
    models = check_models(shaft_inertia_kgm2)
    pairs = [make_pair(cfg, hold_table(), name) for name, cfg in models]
    structure = elastic_structure(pairs[0])
    step("mass matrix")
    checks = [check_mass_matrix(pairs, samples)]
    step("bias forces")
    checks.append(check_bias(pairs, samples))
    step("accelerations")
    checks += [check_qacc(pairs, samples), check_structure(structure)]
    step("controller inputs")
    checks.append(check_controller_inputs(pairs, samples))
    study = None
    if trajectory:
        step("trajectory (MuJoCo vs Pinocchio)")
        study = trajectory_study(duration_s, dts)
        checks += check_trajectory(study)
    if energy:
        step("energy")
        checks.append(check_energy())
    if progress is not None:
        progress("done", len(names), len(names))
    return DynamicsReport(tuple(checks), structure, study, samples, tuple(n for n, _ in models))


ENERGY_DRIFT_TOLERANCE_J = 1e-6


def check_energy() -> CheckResult:
    """6. Energy: for every transmission, the free arm bent 45 deg with every dissipation off
    keeps its total energy over 2 s (RK4, 50 us) - the -dV/dphi_B torque of each routed,
    bend-dependent law included (:mod:`fsarm_sim.studies.energy_check`)."""
    drifts = {n: energy_check.free_arm_energy_drift(n) for n in transmissions.names()}
    worst = max(drifts, key=lambda n: drifts[n].drift_j)
    return CheckResult(
        key="energy",
        name="energy of the free, undamped, bent arm (every transmission)",
        measured=max(r.drift_j for r in drifts.values()),
        tolerance=ENERGY_DRIFT_TOLERANCE_J,
        unit="J",
        detail=f"largest drift: {worst} ({drifts[worst].drift_j:.3g} J of "
        f"{drifts[worst].energy_j:.3g} J, bent {drifts[worst].bend_rad:.3g} rad)",
        extra={n: r.drift_j for n, r in drifts.items()},
    )
