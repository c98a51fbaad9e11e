"""Sensorless collision detection and hand guiding at joint 3 from its two encoders (seed 004).

Seed 004 (tendon-sheath actuator) detects collisions and guides the joint by hand with no force
sensor: a position-transmission model identified without disturbance (its eq. 19, Tables 1-2)
predicts the motor angle from the joint angle; the difference to the measured motor angle is the
monitor value delta (Algorithm 1), and hand guiding drives the motor to the predicted value
(Algorithm 2). Here the same idea runs on *any* joint-3 transmission through its interface
(:mod:`fsarm_sim.transmissions.base`), on the arm's two joint-3 encoders:

* Measured transmission torque (the virtual torque sensor of the transmission, the controller's
  copy of its law): ``tau_tr = sensor_torque(tr, theta_m - theta_s, q2)`` with
  ``theta_m = rotor / i_G1`` and ``theta_s = i_G2 q3``; on q3 it acts as ``i_G2 tau_tr``.
* Expected torque - a generalized-momentum observer on joint 3 (De Luca's residual, the method of
  the collision work seed 004 cites as [32], [33]), with the arm's rigid-body model (the MJCF the
  controller's computed-torque loops use, payload included):

      p3 = sum_j M_3j(q) qd_j,        dp3/dt = i_G2 tau_tr - d3 qd3 - b3(q, qd) + (dM/dt qd)_3 + tau_ext
      r_k = K_O (p3_k - p3_0 - sum_{i<k} (beta_i + r_i) dt),
      beta = i_G2 tau_tr - d3 qd3 - b3 + (dM/dt qd)_3

  ``b = C(q, qd) qd + g(q)`` (``mj_rne``), ``d3`` the MJCF's joint-3 viscous damping, joint rates
  by backward differences of the encoder angles, dM/dt by a backward difference of M's row.
  ``r`` follows the external joint-3 torque through a first-order lag of bandwidth K_O:
  ``dr/dt = K_O (tau_ext - r)``. *Why an observer and not the torque expected from the
  reference:* it uses the measured motion, so it does not see the controller's tracking error
  (every transient of the cascade, and the collision reaction itself, would otherwise show up
  as "external torque"), and it needs no acceleration (no double differentiation of encoders).
* Algorithm 1 (detection): ``delta = r``; ``|delta| <= delta_a``: run normally, else alarm and
  the reaction of line 8, ``theta_c = theta_1(t-)`` - the motor holds where it is: the joint-3
  reference freezes at the measured q3 of the alarm tick (:func:`reaction_loop`).
  The seed takes the nearer of its two direction branches (P/R, the hysteresis of the sheath);
  the interface has one law, so the transmission's hysteresis stays in ``r`` and the threshold
  must cover it.
* Threshold ``delta_a`` (seed: "the maximum allowable error", above its identification's maximal
  error M.E. of Tables 1-2): identified like the seed's model, on collision-free identification
  runs (:func:`calibrate`): ``delta_a = MARGIN * max |r|`` over them.
* Algorithm 2 (hand guiding): the seed's motor follows the joint to the no-load relation, so
  the joint yields to the hand and stays where it is left. On our position-controlled cascade
  the equivalent is an admittance outer loop that moves joint 3's reference with the estimated
  external torque: ``M_a qdd_r + D_a qd_r = dz(r, delta_a)`` (dead zone: model error alone never
  moves the arm), written into the reference rows tick by tick (:func:`hand_guiding_loop`); the
  joint stops when the hand lets go (``qd_r -> 0`` with time constant ``M_a / D_a``). The dead
  zone is the identification's largest ``|r|`` without margin: the torque analogue of the seed's
  nearest-branch rule, which moves the motor only once the joint leaves the identified band.

All torques are joint-side (q3), N*m; times in s.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim import layout as L
from fsarm_sim import references as R
from fsarm_sim import scenarios
from fsarm_sim.errors import FsarmError
from fsarm_sim.model import PAYLOAD_MAX_KG, SimConfig, build_model, read_structure
from fsarm_sim.simulation import Backend, RunResult, Simulation, run_scenario
from fsarm_sim.transmissions.base import TransmissionError

Array = npt.NDArray[np.float64]
DEG = math.pi / 180.0

# Observer bandwidth K_O, rad/s. Estimate: ~16 Hz, above the seed's ~6 Hz compliant-control
# bandwidth (seed 004 Sec. V-C) and far below the 1 kHz tick (K_O dt = 0.1), so r is a clean
# first-order filter of the external torque (a hit is seen within a few ms).
GAIN_RAD_S = 100.0
# delta_a = MARGIN * (largest |r| on the collision-free identification runs). Estimate: 2 covers
# trajectories and poses the identification did not contain (checked on fig14-sine, p2p-payload
# and the collision-free twin of collision-hit by tests/test_collision.py).
MARGIN = 2.0
# Admittance of hand guiding. Estimates: a 10 N*m push moves the joint at 0.25 rad/s (~14 deg/s,
# a slow hand-guiding speed), and the joint settles within M_a / D_a = 0.1 s of release, far
# slower than the joint-3 position loop (wn = 25 rad/s) so the loop can follow.
ADMITTANCE_DAMPING_NMS = 40.0  # D_a, N*m*s/rad
ADMITTANCE_INERTIA_KGM2 = 4.0  # M_a, kg*m^2
LIMIT_MARGIN_RAD = 0.1  # hand guiding stops this far inside joint 3's range (estimate)
# After a scripted contact ends, alarms within this time still belong to it (the observer's
# first-order lag decays to < 1 % in 5 / K_O).
SETTLE_TIME_CONSTANTS = 5.0


class CollisionError(FsarmError, ValueError):
    """A bad observer gain, threshold or detection input."""


def _check_positive(name: str, value: float) -> float:
    if not isinstance(value, int | float) or not math.isfinite(value) or value <= 0.0:
        raise CollisionError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


# --------------------------------------------------------------------------------------------
# The observer
# --------------------------------------------------------------------------------------------


class JointThreeObserver:
    """Generalized-momentum residual of joint 3 from the encoders (module docstring).

    Feed one sample per control tick, in order, with :meth:`update`; it returns ``r`` (N*m).
    """

    def __init__(
        self, model: mujoco.MjModel, config: SimConfig, gain_rad_s: float = GAIN_RAD_S
    ) -> None:
        self.gain = _check_positive("observer gain", gain_rad_s)
        self.dt = config.gains.ctrl_dt_s
        if self.gain * self.dt >= 1.0:
            raise CollisionError(
                f"observer gain {gain_rad_s:g} rad/s is too high for the control period "
                f"{self.dt:g} s: gain * dt must stay below 1"
            )
        self.model = model
        self.structure = st = read_structure(model)
        self.transmission = config.transmission_model()
        self.block = config.transmission_blocks()[1]  # the controller's copy of the law
        # the MJCF's joint-3 damping; a discrepancy effect on top of it is unknown to the observer
        self.damping = float(model.dof_damping[st.dof[2]]) - config.effects.q3_damping_nms
        self._data = mujoco.MjData(model)
        self._full = np.zeros((model.nv, model.nv))
        self._bias = np.zeros(model.nv)
        self._qadr = list(st.qadr[:3])
        self._dof = list(st.dof[:3])
        self._q_prev: Array | None = None
        self._row_prev = np.zeros(3)
        self._p0 = 0.0
        self._sum = 0.0
        self.r = 0.0

    def _dynamics(self, q: Array, qd: Array) -> tuple[Array, float]:
        """Row 3 of M(q) over joints 1-3, and b3 = (C qd + g)_3."""
        d, m = self._data, self.model
        d.qpos[self._qadr] = q
        d.qvel[:] = 0.0
        d.qvel[self._dof] = qd
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_crb(m, d)
        mujoco.mj_comVel(m, d)
        mujoco.mj_fullM(m, d, self._full)
        mujoco.mj_rne(m, d, 0, self._bias)
        i = self._dof[2]
        return self._full[i, self._dof].copy(), float(self._bias[i])

    def update(self, q: Sequence[float], theta_m: float) -> float:
        """One tick: joint encoders ``q`` = (q1, q2, q3), motor encoder ``theta_m`` (rad)."""
        qk = np.asarray(q, dtype=np.float64)
        qd = np.zeros(3) if self._q_prev is None else (qk - self._q_prev) / self.dt
        row, b3 = self._dynamics(qk, qd)
        p = float(row @ qd)
        if self._q_prev is None:
            self._p0, self._row_prev = p, row
        mdot_qd = float((row - self._row_prev) @ qd) / self.dt
        twist = theta_m - self.structure.coef_s * qk[2]
        tau_tr = self.transmission.sensor_torque(self.block, twist, qk[1])
        beta = self.structure.coef_s * tau_tr - self.damping * qd[2] - b3 + mdot_qd
        self.r = self.gain * (p - self._p0 - self._sum)
        self._sum += (beta + self.r) * self.dt
        self._q_prev, self._row_prev = qk, row
        return self.r

    def update_from(self, data: mujoco.MjData) -> float:
        """One tick from a running simulation's state (what its encoders read)."""
        st = self.structure
        q = data.qpos[self._qadr]
        return self.update(q, st.coef_m * data.qpos[st.qadr[3]])


def residual(result: RunResult, gain_rad_s: float = GAIN_RAD_S) -> Array:
    """The observer's ``r`` over a recorded run (one row per control tick, as recorded)."""
    c = result.columns
    t = c["t"]
    if len(t) > 1 and not np.allclose(np.diff(t), result.config.gains.ctrl_dt_s):
        raise CollisionError(
            "the observer needs one recorded row per control tick (log_every_ticks = 1)"
        )
    model = build_model(result.config, np.zeros((1, L.REF_COLS)))
    obs = JointThreeObserver(model, result.config, gain_rad_s)
    q = np.stack([c["q1"], c["q2"], c["q3"]], axis=1)
    return np.array([obs.update(q[k], c["theta_m"][k]) for k in range(len(t))])


# --------------------------------------------------------------------------------------------
# Alarms, threshold
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Alarm:
    """One interval with ``|r| > delta_a``."""

    start_s: float
    end_s: float
    peak_nm: float


def alarms(t: Array, r: Array, threshold_nm: float) -> list[Alarm]:
    """Intervals of ``|r| > threshold_nm`` (Algorithm 1 line 6), in time order."""
    _check_positive("threshold", threshold_nm)
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


@dataclass(frozen=True)
class Calibration:
    """The detection threshold, identified on collision-free runs (module docstring)."""

    threshold_nm: float
    max_abs_residual_nm: float
    margin: float
    runs: tuple[str, ...]


def _identification(t: Array) -> Array:
    """Joint 3 over 0-90 deg at 94 deg/s peak while joint 2 swings 15-60 deg (bend and gravity
    change): the seed identifies its model on sinusoids without disturbance (Sec. III-IV)."""
    return R.stack(
        (
            R.hold(t, 0.0),
            R.cosine_sweep(t, 15.0 * DEG, 60.0 * DEG, 6.0),
            R.cosine_sweep(t, 0.0, 90.0 * DEG, 3.0),
        )
    )


IDENTIFICATION = scenarios.Scenario(
    "collision-identification",
    "collision-free identification run of the detection threshold",
    6.0,
    0.0,
    _identification,
)
IDENTIFICATION_PAYLOADS_KG = (0.0, PAYLOAD_MAX_KG)  # no payload and the rated one


@functools.lru_cache(maxsize=16)
def _calibrate(config: SimConfig, gain_rad_s: float, backend: Backend) -> Calibration:
    worst = 0.0
    runs = []
    for payload in IDENTIFICATION_PAYLOADS_KG:
        label = f"{IDENTIFICATION.name} @ {payload:g} kg"
        try:
            res = run_scenario(IDENTIFICATION, config, payload_kg=payload, backend=backend)
        except TransmissionError as exc:  # e.g. a spring that cannot carry the rated payload
            runs.append(f"{label} skipped ({exc})")
            continue
        worst = max(worst, float(np.max(np.abs(residual(res, gain_rad_s)))))
        runs.append(label)
    threshold = MARGIN * worst
    if threshold <= 0.0:
        raise CollisionError(
            f"no threshold for {config.transmission}: the identification runs gave no residual "
            f"({'; '.join(runs)})"
        )
    return Calibration(threshold, worst, MARGIN, tuple(runs))


def calibrate(
    config: SimConfig, gain_rad_s: float = GAIN_RAD_S, backend: Backend = "python"
) -> Calibration:
    """delta_a for this arm and transmission (cached per configuration; payload ignored)."""
    return _calibrate(config.with_(payload_kg=0.0), gain_rad_s, backend)


# --------------------------------------------------------------------------------------------
# Outer loops (scenario hooks, once per control tick)
# --------------------------------------------------------------------------------------------


def _ref_rows(sim: Simulation) -> Array:
    return sim.model.numeric(L.REF_NAME).data.reshape(-1, L.REF_COLS)  # a view: writes land


class CollisionReaction:
    """Algorithm 1 online: on the first alarm, joint 3 holds the measured angle (line 8)."""

    def __init__(self, sim: Simulation, threshold_nm: float, gain_rad_s: float = GAIN_RAD_S):
        self.sim = sim
        self.threshold = _check_positive("threshold", threshold_nm)
        self.observer = JointThreeObserver(sim.model, sim.config, gain_rad_s)
        self.ref = _ref_rows(sim)
        self.detected_tick: int | None = None
        self.hold_rad = 0.0

    def __call__(self, k: int) -> None:
        r = self.observer.update_from(self.sim.data)
        if self.detected_tick is None and abs(r) > self.threshold:
            self.detected_tick = k
            self.hold_rad = float(self.sim.data.qpos[self.observer.structure.qadr[2]])
        if self.detected_tick is not None and k < self.ref.shape[0]:
            self.ref[k, 2], self.ref[k, 5], self.ref[k, 8] = self.hold_rad, 0.0, 0.0


class HandGuiding:
    """Algorithm 2 online as an admittance on joint 3's reference (module docstring)."""

    def __init__(
        self,
        sim: Simulation,
        threshold_nm: float,
        gain_rad_s: float = GAIN_RAD_S,
        damping_nms: float = ADMITTANCE_DAMPING_NMS,
        inertia_kgm2: float = ADMITTANCE_INERTIA_KGM2,
    ) -> None:
        self.sim = sim
        self.threshold = _check_positive("dead zone", threshold_nm)
        self.damping = _check_positive("admittance damping", damping_nms)
        self.inertia = _check_positive("admittance inertia", inertia_kgm2)
        self.observer = JointThreeObserver(sim.model, sim.config, gain_rad_s)
        self.ref = _ref_rows(sim)
        self.dt = sim.config.gains.ctrl_dt_s
        st = self.observer.structure
        jnt = int(sim.model.dof_jntid[st.dof[2]])
        lo, hi = sim.model.jnt_range[jnt]
        self.limits = (float(lo) + LIMIT_MARGIN_RAD, float(hi) - LIMIT_MARGIN_RAD)
        self.q = float(self.ref[0, 2])
        self.qd = 0.0

    def __call__(self, k: int) -> None:
        r = self.observer.update_from(self.sim.data)
        u = math.copysign(abs(r) - self.threshold, r) if abs(r) > self.threshold else 0.0
        qdd = (u - self.damping * self.qd) / self.inertia
        self.qd += qdd * self.dt
        self.q += self.qd * self.dt
        if not self.limits[0] <= self.q <= self.limits[1]:
            self.q = min(max(self.q, self.limits[0]), self.limits[1])
            self.qd = qdd = 0.0
        if k < self.ref.shape[0]:
            self.ref[k, 2], self.ref[k, 5], self.ref[k, 8] = self.q, self.qd, qdd


def reaction_loop(sim: Simulation) -> CollisionReaction:
    """Scenario outer loop: Algorithm 1 with the identified threshold of this configuration."""
    cal = calibrate(sim.config, backend=sim.backend)
    return CollisionReaction(sim, cal.threshold_nm)


def hand_guiding_loop(sim: Simulation) -> HandGuiding:
    """Scenario outer loop: Algorithm 2 (admittance), dead zone = the identified error band."""
    cal = calibrate(sim.config, backend=sim.backend)
    return HandGuiding(sim, cal.max_abs_residual_nm)


# --------------------------------------------------------------------------------------------
# Evaluation
# --------------------------------------------------------------------------------------------


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


def run_battery(config: SimConfig, backend: Backend = "python") -> Battery:
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
