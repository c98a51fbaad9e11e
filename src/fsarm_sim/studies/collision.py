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

from collections.abc import Sequence
from dataclasses import dataclass, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import SimConfig, build_model, read_structure
from fsarm_sim.kernels import layout as L
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
    check_positive,
    hand_guiding_loop,
    identification_reference,
    observer_residual,
    reaction_loop,
)
from fsarm_sim.sim.outer_loops import calibrate as calibrate_with
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, RunResult, Simulation, run_scenario

Array = npt.NDArray[np.float64]

# After a scripted contact ends, alarms within this time still belong to it (the observer's
# first-order lag decays to < 1 % in 5 / K_O).
SETTLE_TIME_CONSTANTS = 5.0

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
    "Battery",
    "Calibration",
    "CollisionError",
    "CollisionReaction",
    "DetectionReport",
    "GuidingReport",
    "HandGuiding",
    "JointThreeObserver",
    "alarms",
    "calibrate",
    "evaluate_detection",
    "evaluate_guiding",
    "external_torque",
    "hand_guiding_loop",
    "reaction_loop",
    "residual",
    "run_battery",
    "without_disturbance",
]


def residual(result: RunResult, gain_rad_s: float = GAIN_RAD_S) -> Array:
    """The observer's ``r`` over a recorded run (one row per control tick, as recorded)."""
    return observer_residual(result.columns, result.config, gain_rad_s)


def calibrate(
    config: SimConfig, gain_rad_s: float = GAIN_RAD_S, backend: Backend = DEFAULT_BACKEND
) -> Calibration:
    """delta_a for this arm and transmission (cached per configuration; payload ignored): the
    identification of :func:`fsarm_sim.sim.outer_loops.calibrate` on :class:`Simulation` runs, the
    threshold the scenarios' outer loops use."""
    return calibrate_with(Simulation, config, gain_rad_s, backend)


# --------------------------------------------------------------------------------------------
# Alarms
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Alarm:
    """One interval with ``|r| > delta_a``."""

    start_s: float
    end_s: float
    peak_nm: float


def alarms(t: Array, r: Array, threshold_nm: float) -> list[Alarm]:
    """Intervals of ``|r| > threshold_nm`` (Algorithm 1 line 6), in time order."""
    check_positive("threshold", threshold_nm)
    if len(t) != len(r):
        raise CollisionError(f"t and r differ in length ({len(t)} vs {len(r)})")
    over = np.abs(r) > threshold_nm
    out: list[Alarm] = []
    k, n = 0, len(t)
    while k < n:
        if not over[k]:
            k += 1
            continue
        j = k
        while j + 1 < n and over[j + 1]:
            j += 1
        seg = r[k : j + 1]
        out.append(Alarm(float(t[k]), float(t[j]), float(seg[np.argmax(np.abs(seg))])))
        k = j + 1
    return out


def external_torque(result: RunResult, dist: scenarios.Disturbance) -> Array:
    """The true external joint-3 torque a scripted disturbance applied, per recorded row."""
    c, cfg = result.columns, result.config
    model = build_model(cfg, np.zeros((1, L.REF_COLS)))
    st = read_structure(model)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, dist.site)
    if site < 0:
        raise CollisionError(f"the arm has no site named {dist.site!r}")
    body = int(model.site_bodyid[site])
    d = mujoco.MjData(model)
    qfrc = np.zeros(model.nv)
    out = np.empty(len(c["t"]))
    for k, t in enumerate(c["t"]):
        for j in range(3):
            d.qpos[st.qadr[j]] = c[f"q{j + 1}"][k]
        mujoco.mj_kinematics(model, d)
        mujoco.mj_comPos(model, d)
        f = d.site_xmat[site].reshape(3, 3) @ np.asarray(dist.force_n(float(t)), dtype=np.float64)
        qfrc[:] = 0.0
        mujoco.mj_applyFT(model, d, f, np.zeros(3), d.site_xpos[site], body, qfrc)
        out[k] = qfrc[st.dof[2]]
    return out


@dataclass(frozen=True)
class DetectionReport:
    """Detection over one run: delay after the scripted contact, alarms outside it."""

    run: str
    threshold_nm: float
    contact_s: tuple[float, float] | None
    detected_s: float | None  # first alarm inside the contact (+ settling), s
    delay_s: float | None
    false_alarms: int | None  # alarms starting outside the contact (+ settling); None: skipped
    peak_external_nm: float  # true |tau_ext| on q3 (0 without a disturbance)
    peak_estimate_nm: float  # largest |r|
    skipped: str | None = None  # why the run could not be made with this transmission

    def as_dict(self) -> dict[str, object]:
        return {
            "run": self.run,
            "threshold_nm": self.threshold_nm,
            "contact_s": list(self.contact_s) if self.contact_s else None,
            "detected_s": self.detected_s,
            "delay_s": self.delay_s,
            "false_alarms": self.false_alarms,
            "peak_external_nm": self.peak_external_nm,
            "peak_estimate_nm": self.peak_estimate_nm,
            "skipped": self.skipped,
        }


def evaluate_detection(
    run: str,
    result: RunResult,
    threshold_nm: float,
    disturbance: scenarios.Disturbance | None = None,
    gain_rad_s: float = GAIN_RAD_S,
) -> DetectionReport:
    """Detection delay and false alarms of Algorithm 1 over a recorded run."""
    r = residual(result, gain_rad_s)
    t = result.columns["t"]
    found = alarms(t, r, threshold_nm)
    window = disturbance.window_s if disturbance is not None else None
    detected = None
    false = 0
    late = SETTLE_TIME_CONSTANTS / gain_rad_s
    for a in found:
        inside = window is not None and window[0] <= a.start_s <= window[1] + late
        if inside and detected is None:
            detected = a.start_s
        elif not inside:
            false += 1
    peak_ext = (
        float(np.max(np.abs(external_torque(result, disturbance))))
        if disturbance is not None
        else 0.0
    )
    return DetectionReport(
        run=run,
        threshold_nm=threshold_nm,
        contact_s=window,
        detected_s=detected,
        delay_s=None if detected is None or window is None else detected - window[0],
        false_alarms=false,
        peak_external_nm=peak_ext,
        peak_estimate_nm=float(np.max(np.abs(r))) if len(r) else 0.0,
    )


@dataclass(frozen=True)
class GuidingReport:
    """Hand guiding over the hand-guide scenario: motion during each push, drift after it."""

    pushes: tuple[dict[str, float], ...]
    human_work_j: float  # integral of tau_ext qd3: > 0 when the joint yields to the hand
    final_speed_rad_s: float
    q3_range_rad: tuple[float, float]

    def as_dict(self) -> dict[str, object]:
        return {
            "pushes": list(self.pushes),
            "human_work_j": self.human_work_j,
            "final_speed_rad_s": self.final_speed_rad_s,
            "q3_range_rad": list(self.q3_range_rad),
        }


def evaluate_guiding(
    result: RunResult, disturbance: scenarios.Disturbance, pushes: Sequence[tuple[float, float]]
) -> GuidingReport:
    """For each push (start, end): where joint 3 ended up (travel from the push's start to
    ``end + 0.5 s``, released and settled) and its drift from then to the next push or the end
    of the run."""
    c = result.columns
    t, q3, qd3 = c["t"], c["q3"], c["qd3"]
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
# The scripted battery (``fsarm collision``)
# --------------------------------------------------------------------------------------------

FREE_RUNS = ("fig14-sine", "p2p-payload")  # collision-free runs checked for false alarms


@dataclass(frozen=True)
class Battery:
    """Calibration, detection over the scripted runs, and hand guiding, for one configuration."""

    transmission: str
    calibration: Calibration
    gain_rad_s: float
    detection: tuple[DetectionReport, ...]
    guiding: GuidingReport | None
    guiding_skipped: str | None = None

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
            "hand_guiding": self.guiding.as_dict() if self.guiding else None,
            "hand_guiding_skipped": self.guiding_skipped,
        }


def _detect(
    label: str,
    sc: str | scenarios.Scenario,
    config: SimConfig,
    backend: Backend,
    threshold_nm: float,
    dist: scenarios.Disturbance | None,
) -> DetectionReport:
    try:
        res = run_scenario(sc, config, backend=backend)
    except TransmissionError as exc:
        window = dist.window_s if dist is not None else None
        return DetectionReport(label, threshold_nm, window, None, None, None, 0.0, 0.0, str(exc))
    return evaluate_detection(label, res, threshold_nm, dist)


def run_battery(config: SimConfig, backend: Backend = DEFAULT_BACKEND) -> Battery:
    """collision-hit, its collision-free twin, fig14-sine and p2p-payload through Algorithm 1;
    hand-guide through Algorithm 2. A run the transmission cannot make (it cannot hold the
    scenario's load statically) is reported as skipped, with the reason."""
    cal = calibrate(config, backend=backend)
    thr = cal.threshold_nm
    hit = scenarios.get("collision-hit")
    twin = without_disturbance(hit)
    reports = [
        _detect(hit.name, hit, config, backend, thr, hit.disturbance),
        _detect(twin.name, twin, config, backend, thr, None),
    ]
    reports += [_detect(name, name, config, backend, thr, None) for name in FREE_RUNS]
    hg = scenarios.get("hand-guide")
    assert hg.disturbance is not None
    try:
        res = run_scenario(hg, config, backend=backend)
    except TransmissionError as exc:
        return Battery(config.transmission, cal, GAIN_RAD_S, tuple(reports), None, str(exc))
    pushes = [(a, b) for a, b, _ in scenarios.HAND_PUSHES]
    guiding = evaluate_guiding(res, hg.disturbance, pushes)
    return Battery(config.transmission, cal, GAIN_RAD_S, tuple(reports), guiding)
