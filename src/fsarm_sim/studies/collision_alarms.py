"""The observer over a recorded run: its residual, alarm intervals, the true external torque of a scripted disturbance, detection delay and false alarms."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import build_model, read_structure
from fsarm_sim.kernels import layout
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.outer_loops import (
    GAIN_RAD_S,
    CollisionError,
    check_positive,
    observer_residual,
)
from fsarm_sim.sim.simulation import RunResult

Array = npt.NDArray[np.float64]


# After a scripted contact ends, alarms within this time still belong to it (the observer's
# first-order lag decays to < 1 % in 5 / K_O).
SETTLE_TIME_CONSTANTS = 5.0


def residual(result: RunResult, gain_rad_s: float = GAIN_RAD_S) -> Array:
    """The observer's ``r`` over a recorded run (one row per control tick, as recorded)."""
    return observer_residual(result.columns, result.config, gain_rad_s)


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
    model = build_model(cfg, np.zeros((1, layout.REF_COLS)))
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


def detection_report(
    run: str,
    result: RunResult,
    signal: Array,
    threshold: float,
    disturbance: scenarios.Disturbance | None,
    late_s: float,
) -> DetectionReport:
    """Detection delay and false alarms of the alarms ``|signal| > threshold`` over a recorded
    run: an alarm starting within the scripted contact (+ ``late_s`` of settling) detects it,
    any other is false."""
    found = alarms(result.columns["t"], signal, threshold)
    window = disturbance.window_s if disturbance is not None else None
    detected = None
    false = 0
    for a in found:
        inside = window is not None and window[0] <= a.start_s <= window[1] + late_s
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
        threshold_nm=threshold,
        contact_s=window,
        detected_s=detected,
        delay_s=None if detected is None or window is None else detected - window[0],
        false_alarms=false,
        peak_external_nm=peak_ext,
        peak_estimate_nm=float(np.max(np.abs(signal))) if len(signal) else 0.0,
    )


def evaluate_detection(
    run: str,
    result: RunResult,
    threshold_nm: float,
    disturbance: scenarios.Disturbance | None = None,
    gain_rad_s: float = GAIN_RAD_S,
) -> DetectionReport:
    """Detection delay and false alarms of Algorithm 1 over a recorded run."""
    r = residual(result, gain_rad_s)
    late = SETTLE_TIME_CONSTANTS / gain_rad_s
    return detection_report(run, result, r, threshold_nm, disturbance, late)
