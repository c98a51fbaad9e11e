"""Sensorless collision detection and hand guiding at joint 3 (seed 004): the evaluation.

The observer, the threshold identification and the two outer loops (Algorithm 1's reaction,
Algorithm 2's admittance) run inside the scenarios ``collision-hit`` and ``hand-guide``; they live
in :mod:`fsarm_sim.sim.outer_loops` (below the scenario registry and the runner; its docstring
describes the method) and are re-exported here. This module evaluates them over recorded runs:
the observer's residual, alarm intervals, detection delay and false alarms, the true external
torque of a scripted disturbance, hand guiding's travel and drift, and the scripted battery of
``fsarm collision``.

All torques are joint-side (q3), N*m; times in s.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from fsarm_sim.controllers.tendon_sheath_compliance import collision_monitor
from fsarm_sim.engine.model import SimConfig, read_structure
from fsarm_sim.errors import RunHealthError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.transmissions.base import TransmissionError
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.outer_loops import (
    ADMITTANCE_DAMPING_NMS,
    ADMITTANCE_INERTIA_KGM2,
    GAIN_RAD_S,
    IDENTIFICATION_DURATION_S,
    IDENTIFICATION_NAME,
    IDENTIFICATION_PAYLOADS_KG,
    LIMIT_MARGIN_RAD,
    MARGIN,
    Calibration,
    CollisionError,
    CollisionReaction,
    HandGuiding,
    JointThreeObserver,
    Simulator,
    check_positive,
    hand_guiding_loop,
    identification_reference,
    reaction_loop,
)
from fsarm_sim.sim.outer_loops import calibrate as calibrate_with
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, RunResult, Simulation, run_scenario
from fsarm_sim.studies.collision_alarms import SETTLE_TIME_CONSTANTS, detection_report
from fsarm_sim.studies.collision_alarms import Alarm as Alarm
from fsarm_sim.studies.collision_alarms import DetectionReport as DetectionReport
from fsarm_sim.studies.collision_alarms import alarms as alarms
from fsarm_sim.studies.collision_alarms import evaluate_detection as evaluate_detection
from fsarm_sim.studies.collision_alarms import external_torque as external_torque
from fsarm_sim.studies.collision_alarms import residual as residual

Array = npt.NDArray[np.float64]

# The collision-free identification run of the threshold, as a scenario (not registered).
IDENTIFICATION = scenarios.Scenario(
    IDENTIFICATION_NAME,
    "collision-free identification run of the detection threshold",
    IDENTIFICATION_DURATION_S,
    0.0,
    identification_reference,
)

__all__ = [
    "ADMITTANCE_DAMPING_NMS",
    "ADMITTANCE_INERTIA_KGM2",
    "GAIN_RAD_S",
    "IDENTIFICATION",
    "IDENTIFICATION_PAYLOADS_KG",
    "LIMIT_MARGIN_RAD",
    "MARGIN",
    "SETTLE_TIME_CONSTANTS",
    "Alarm",
    "Algorithm2Guiding",
    "Battery",
    "Calibration",
    "CollisionError",
    "CollisionReaction",
    "DetectionReport",
    "GuidingReport",
    "HandGuiding",
    "JointThreeObserver",
    "PositionModel",
    "alarms",
    "algorithm1_delta",
    "algorithm2_scenario",
    "calibrate",
    "evaluate_algorithm1",
    "evaluate_detection",
    "evaluate_guiding",
    "external_torque",
    "hand_guiding_loop",
    "identify_position_model",
    "reaction_loop",
    "residual",
    "run_battery",
    "without_disturbance",
]


def calibrate(
    config: SimConfig, gain_rad_s: float = GAIN_RAD_S, backend: Backend = DEFAULT_BACKEND
) -> Calibration:
    """delta_a for this arm and transmission (cached per configuration; payload ignored): the
    identification of :func:`fsarm_sim.sim.outer_loops.calibrate` on :class:`Simulation` runs, the
    threshold the scenarios' outer loops use."""
    return calibrate_with(Simulation, config, gain_rad_s, backend)


# "stays where it is left" (seed 004 Sec. V-B, the 004-hand-guiding claim): after each release
# joint 3 moves slower than this and drifts less than this until the next push or the end
# (estimate: the seed gives no number; 0.05 rad is 2.9 deg, a hand's placing accuracy)
HOLD_SPEED_RAD_S = 0.05
HOLD_DRIFT_RAD = 0.05
# "The motor can move following the change of the joint angle" (seed 004 Sec. V-B): over each
# push the motor-side shaft angle travels at least this share of the joint-side one, i.e. the
# motor, not the transmission's stretch, carries most of the joint's move (estimate: the seed
# gives no number; a motor held in place gives ~0, one that follows ~1)
MOTOR_FOLLOW_SHARE = 0.5


@dataclass(frozen=True)
class GuidingReport:
    """Hand guiding over the hand-guide scenario: motion during each push, drift after it."""

    pushes: tuple[dict[str, float], ...]
    human_work_j: float  # integral of tau_ext qd3: > 0 when the joint yields to the hand
    final_speed_rad_s: float
    q3_range_rad: tuple[float, float]

    def follows(self) -> bool:
        """Every push moved the joint its way."""
        return all(
            math.copysign(1.0, p["travel_rad"]) == math.copysign(1.0, p["mean_push_nm"])
            for p in self.pushes
        )

    def holds(self) -> bool:
        """After every release the joint stays (:data:`HOLD_SPEED_RAD_S`)."""
        return all(abs(p["speed_after_release_rad_s"]) < HOLD_SPEED_RAD_S for p in self.pushes)

    def stays(self) -> bool:
        """After every release the joint drifts less than :data:`HOLD_DRIFT_RAD`."""
        return all(abs(p["drift_after_release_rad"]) < HOLD_DRIFT_RAD for p in self.pushes)

    def motor_follows(self) -> bool:
        """Over every push the motor moved with the joint (:data:`MOTOR_FOLLOW_SHARE`)."""
        return all(p["motor_share"] >= MOTOR_FOLLOW_SHARE for p in self.pushes)

    def cycles(self) -> int:
        """Up-and-down cycles: consecutive pushes that moved the joint one way, then back."""
        signs = [math.copysign(1.0, p["travel_rad"]) for p in self.pushes]
        return sum(1 for a, b in zip(signs[::2], signs[1::2], strict=False) if a == -b)

    def as_dict(self) -> dict[str, object]:
        return {
            "pushes": list(self.pushes),
            "human_work_j": self.human_work_j,
            "final_speed_rad_s": self.final_speed_rad_s,
            "q3_range_rad": list(self.q3_range_rad),
        }


def _share(motor: float, joint: float) -> float:
    """The motor side's travel over the joint side's (both as shaft angles); 0 if the joint
    did not move."""
    return float(motor / joint) if joint != 0.0 else 0.0


def evaluate_guiding(
    result: RunResult, disturbance: scenarios.Disturbance, pushes: Sequence[tuple[float, float]]
) -> GuidingReport:
    """For each push (start, end): where joint 3 ended up (travel from the push's start to
    ``end + 0.5 s``, released and settled) and its drift from then to the next push or the end
    of the run."""
    c = result.columns
    t, q3, qd3 = c["t"], c["q3"], c["qd3"]
    th_m, th_s = c["theta_m"], c["theta_s"]
    tau = external_torque(result, disturbance)
    rows = []
    for i, (a, b) in enumerate(pushes):
        nxt = pushes[i + 1][0] if i + 1 < len(pushes) else float(t[-1])
        ia, ib = np.searchsorted(t, [a, b])
        settled = np.searchsorted(t, min(b + 0.5, nxt))
        ie = np.searchsorted(t, nxt) - 1
        rows.append(
            {
                "start_s": a,
                "end_s": b,
                "mean_push_nm": float(np.mean(tau[ia:ib])),
                "travel_rad": float(q3[settled] - q3[ia]),
                "drift_after_release_rad": float(q3[ie] - q3[settled]),
                "speed_after_release_rad_s": float(np.max(np.abs(qd3[settled : ie + 1]))),
                "motor_share": _share(th_m[settled] - th_m[ia], th_s[settled] - th_s[ia]),
            }
        )
    dt = np.diff(t, prepend=t[0])
    return GuidingReport(
        pushes=tuple(rows),
        human_work_j=float(np.sum(tau * qd3 * dt)),
        final_speed_rad_s=float(abs(qd3[-1])),
        q3_range_rad=(float(np.min(q3)), float(np.max(q3))),
    )


def without_disturbance(sc: scenarios.Scenario) -> scenarios.Scenario:
    """The same scenario, collision-free (same trajectory, same outer loop)."""
    return replace(sc, name=f"{sc.name} (no contact)", disturbance=None)


# --------------------------------------------------------------------------------------------
# Seed 004's own detector: Algorithm 1 on the identified position transmission (eq. 19)
# --------------------------------------------------------------------------------------------

# Joint speeds below this (rad/s) belong to neither direction when the branches are fitted.
DIRECTION_DEADBAND_RAD_S = 1e-3


@dataclass(frozen=True)
class PositionModel:
    """Eq. 19 identified without disturbance: ``theta_m = P q3^2 + Q q3 + M`` per direction of
    joint motion (``up``: qd3 > 0, the seed's p branch; ``down``: qd3 < 0, its r branch), the
    largest |delta| of Algorithm 1 over the identification (M.E.), and the threshold
    ``delta_a = MARGIN * M.E.`` (the seed's "maximum allowable error")."""

    up: tuple[float, float, float]
    down: tuple[float, float, float]
    max_error_rad: float
    threshold_rad: float
    runs: tuple[str, ...]

    def as_dict(self) -> dict[str, object]:
        return {
            "up_PQM": list(self.up),
            "down_PQM": list(self.down),
            "max_error_rad": self.max_error_rad,
            "threshold_rad": self.threshold_rad,
            "runs": list(self.runs),
        }


def algorithm1_delta(
    columns: dict[str, Array], up: tuple[float, float, float], down: tuple[float, float, float]
) -> Array:
    """Algorithm 1's monitor value ``delta`` per recorded row (nearer branch - motor angle)."""
    th1, th2 = columns["theta_m"], columns["q3"]
    out = np.empty(len(th1))
    prev = float(th1[0]) if len(th1) else 0.0
    for k in range(len(th1)):
        out[k], _, _ = collision_monitor(float(th1[k]), float(th2[k]), prev, math.inf, up, down)
        prev = float(th1[k])
    return out


def identify_position_model(
    columns: Sequence[dict[str, Array]], runs: Sequence[str], margin: float = MARGIN
) -> PositionModel:
    """Fit eq. 19 per direction over collision-free runs; M.E. and ``delta_a`` from them."""
    check_positive("margin", margin)
    th1 = np.concatenate([c["theta_m"] for c in columns])
    th2 = np.concatenate([c["q3"] for c in columns])
    w2 = np.concatenate([c["qd3"] for c in columns])
    coefs = []
    for sel in (w2 > DIRECTION_DEADBAND_RAD_S, w2 < -DIRECTION_DEADBAND_RAD_S):
        if np.count_nonzero(sel) < 3 or np.ptp(th2[sel]) <= 0.0:
            raise CollisionError(
                "the identification runs do not move joint 3 both ways: eq. 19 needs one fit "
                "per direction"
            )
        c = np.polyfit(th2[sel], th1[sel], 2)
        coefs.append((float(c[0]), float(c[1]), float(c[2])))
    up, down = coefs[0], coefs[1]
    worst = max(float(np.max(np.abs(algorithm1_delta(c, up, down)))) for c in columns)
    if worst <= 0.0:
        raise CollisionError("the identification runs gave no model error: no threshold")
    return PositionModel(up, down, worst, margin * worst, tuple(runs))


@functools.lru_cache(maxsize=16)
def position_model(config: SimConfig, backend: Backend = DEFAULT_BACKEND) -> PositionModel:
    """Eq. 19 identified on the observer's collision-free identification run at the
    configuration's payload (seed 004 identifies at its one load, Sec. III-IV), cached per
    configuration."""
    cols, runs = [], []
    dt = config.gains.ctrl_dt_s
    n_ticks = round(IDENTIFICATION_DURATION_S / dt) + 1
    ref = identification_reference(np.arange(n_ticks, dtype=np.float64) * dt)
    for payload in (config.payload_kg,):
        cfg = config
        try:
            c, _ = Simulation(cfg, ref, backend).run(IDENTIFICATION_DURATION_S, log_every_ticks=1)
        except TransmissionError as exc:
            runs.append(f"{IDENTIFICATION_NAME} @ {payload:g} kg skipped ({exc})")
            continue
        cols.append(c)
        runs.append(f"{IDENTIFICATION_NAME} @ {payload:g} kg")
    if not cols:
        raise CollisionError(f"no identification run possible: {'; '.join(runs)}")
    return identify_position_model(cols, runs)


def evaluate_algorithm1(
    run: str,
    result: RunResult,
    model: PositionModel,
    disturbance: scenarios.Disturbance | None = None,
    late_s: float = SETTLE_TIME_CONSTANTS / GAIN_RAD_S,
) -> DetectionReport:
    """Detection delay and false alarms of seed 004's Algorithm 1 over a recorded run (alarm:
    ``|delta| > delta_a``), in the observer's report format (torques read as rad of motor
    angle: ``peak_estimate_nm`` holds the largest |delta| in rad)."""
    d = algorithm1_delta(result.columns, model.up, model.down)
    return detection_report(run, result, d, model.threshold_rad, disturbance, late_s)


class Algorithm2Guiding:
    """Seed 004's Algorithm 2 on the arm's cascade (a scenario outer loop, once per tick).

    The seed commands the motor to the no-load position-transmission relation at the measured
    joint angle, ``theta_h`` (the nearer of its two identified branches), so a joint pushed by
    hand drags the motor along and stays where it is left. On our cascade the joint-3 reference
    is set to the joint encoder's reading (speed and acceleration 0): the motor command of the
    joint-3 controller is then the controller's own no-load relation at that angle (its copy
    of the transmission law and the arm's gravity stand in for eq. 19's fitted branches).
    """

    def __init__(self, sim: Simulator) -> None:
        self.sim = sim
        self.ref = sim.model.numeric(layout.REF_NAME).data.reshape(-1, layout.REF_COLS)
        self.qadr = int(read_structure(sim.model).qadr[2])

    def __call__(self, k: int) -> None:
        if k < self.ref.shape[0]:
            self.ref[k, 2] = float(self.sim.data.qpos[self.qadr])
            self.ref[k, 5] = 0.0
            self.ref[k, 8] = 0.0


def algorithm2_scenario() -> scenarios.Scenario:
    """``hand-guide`` with Algorithm 2 as its outer loop instead of the admittance."""
    hg = scenarios.get("hand-guide")
    return replace(hg, name=f"{hg.name} (Algorithm 2)", outer_loop=Algorithm2Guiding)


# --------------------------------------------------------------------------------------------
# The scripted battery (``fsarm collision``)
# --------------------------------------------------------------------------------------------

FREE_RUNS = ("fig14-sine", "p2p-payload")  # collision-free runs checked for false alarms


@dataclass(frozen=True)
class Battery:
    """Calibration, detection over the scripted runs, and hand guiding, for one configuration;
    beside the observer, seed 004's own Algorithm 1 on the same runs (``detection_alg1``)."""

    transmission: str
    calibration: Calibration
    gain_rad_s: float
    detection: tuple[DetectionReport, ...]
    guiding: GuidingReport | None
    guiding_skipped: str | None = None
    position_model: PositionModel | None = None
    detection_alg1: tuple[DetectionReport, ...] = ()
    position_model_skipped: str | None = None
    guiding_alg2: GuidingReport | None = None
    guiding_alg2_failed: str | None = None  # the Algorithm 2 run diverged (why)

    def as_dict(self) -> dict[str, object]:
        cal = self.calibration
        return {
            "transmission": self.transmission,
            "observer_gain_rad_s": self.gain_rad_s,
            "calibration": {
                "threshold_nm": cal.threshold_nm,
                "max_abs_residual_nm": cal.max_abs_residual_nm,
                "margin": cal.margin,
                "runs": list(cal.runs),
            },
            "detection": [d.as_dict() for d in self.detection],
            "algorithm1": {
                "position_model": self.position_model.as_dict() if self.position_model else None,
                "skipped": self.position_model_skipped,
                "detection": [d.as_dict() for d in self.detection_alg1],
                "units": "threshold and peak_estimate in rad of motor angle (delta)",
            },
            "hand_guiding": self.guiding.as_dict() if self.guiding else None,
            "hand_guiding_algorithm2": self.guiding_alg2.as_dict() if self.guiding_alg2 else None,
            "hand_guiding_algorithm2_failed": self.guiding_alg2_failed,
            "hand_guiding_skipped": self.guiding_skipped,
        }


def _detect(
    label: str,
    sc: str | scenarios.Scenario,
    config: SimConfig,
    backend: Backend,
    threshold_nm: float,
    dist: scenarios.Disturbance | None,
    model: PositionModel | None = None,
) -> tuple[DetectionReport, DetectionReport | None]:
    """The observer's report of one run and, with ``model``, Algorithm 1's on the same run."""
    try:
        res = run_scenario(sc, config, backend=backend)
    except (TransmissionError, RunHealthError) as exc:  # cannot hold the load / diverged
        window = dist.window_s if dist is not None else None
        skipped = DetectionReport(label, threshold_nm, window, None, None, None, 0.0, 0.0, str(exc))
        return skipped, (replace(skipped, threshold_nm=model.threshold_rad) if model else None)
    alg1 = evaluate_algorithm1(label, res, model, dist) if model is not None else None
    return evaluate_detection(label, res, threshold_nm, dist), alg1


def run_battery(config: SimConfig, backend: Backend = DEFAULT_BACKEND) -> Battery:
    """collision-hit, its collision-free twin, fig14-sine and p2p-payload through the observer
    and, on the same runs, seed 004's Algorithm 1 (eq. 19 identified on the collision-free
    identification runs); hand-guide through the admittance loop. A run the transmission cannot
    make (it cannot hold the scenario's load statically) is reported as skipped, with the
    reason."""
    cal = calibrate(config, backend=backend)
    thr = cal.threshold_nm
    model: PositionModel | None = None
    model_skipped: str | None = None
    try:
        model = position_model(config, backend)
    except CollisionError as exc:
        model_skipped = str(exc)
    hit = scenarios.get("collision-hit")
    twin = without_disturbance(hit)
    pairs = [
        _detect(hit.name, hit, config, backend, thr, hit.disturbance, model),
        _detect(twin.name, twin, config, backend, thr, None, model),
    ]
    pairs += [_detect(name, name, config, backend, thr, None, model) for name in FREE_RUNS]
    reports = [p[0] for p in pairs]
    alg1 = tuple(p[1] for p in pairs if p[1] is not None)
    hg = scenarios.get("hand-guide")
    assert hg.disturbance is not None
    guiding: GuidingReport | None = None
    guiding_alg2: GuidingReport | None = None
    guiding_skipped: str | None = None
    pushes = [(a, b) for a, b, _ in scenarios.HAND_PUSHES]
    guiding_alg2_failed: str | None = None
    try:
        res = run_scenario(hg, config, backend=backend)
    except (TransmissionError, RunHealthError) as exc:
        guiding_skipped = str(exc)
    else:
        guiding = evaluate_guiding(res, hg.disturbance, pushes)
        try:
            res2 = run_scenario(algorithm2_scenario(), config, backend=backend)
        except RunHealthError as exc:  # no position stiffness left on a torque cascade
            guiding_alg2_failed = str(exc)
        else:
            guiding_alg2 = evaluate_guiding(res2, hg.disturbance, pushes)
    return Battery(
        config.transmission,
        cal,
        GAIN_RAD_S,
        tuple(reports),
        guiding,
        guiding_skipped,
        position_model=model,
        detection_alg1=alg1,
        position_model_skipped=model_skipped,
        guiding_alg2=guiding_alg2,
        guiding_alg2_failed=guiding_alg2_failed,
    )
