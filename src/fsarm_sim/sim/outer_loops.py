"""Outer loops a scenario may run once per control tick; the sensorless contact loops of seed 004.

A scenario's ``outer_loop`` (:mod:`fsarm_sim.sim.scenarios`) is a factory: handed the running
simulation (:class:`Simulator`), it returns a tick hook that may rewrite the reference rows from
tick ``k`` on before the controller reads them. This module sits below the scenario registry and
the runner (:mod:`fsarm_sim.sim.simulation`) and imports neither: an outer loop sees the simulation it
is handed, never the runner's module.

The built-in loops are seed 004's (tendon-sheath actuator) collision detection and hand guiding
with no force sensor: a position-transmission model identified without disturbance (its eq. 19,
Tables 1-2) predicts the motor angle from the joint angle; the difference to the measured motor
angle is the monitor value delta (Algorithm 1), and hand guiding drives the motor to the
predicted value (Algorithm 2). Those algorithms *as written* (eq. 19 fitted per direction, the
nearer branch) are in :mod:`fsarm_sim.controllers.tendon_sheath_compliance` and run beside these
loops in ``fsarm collision`` (:mod:`fsarm_sim.studies.collision`). The loops here carry the same
idea to *any* joint-3 transmission through its interface
(:mod:`fsarm_sim.plant.transmissions.base`), on the arm's two joint-3 encoders, with a momentum
observer in place of the position model:

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
  runs (:func:`calibrate`): ``delta_a = MARGIN * max |r|`` over them. The identification runs on
  twins of the simulation the loop is handed (same class, configuration and backend).
* Algorithm 2 (hand guiding): the seed's motor follows the joint to the no-load relation, so
  the joint yields to the hand and stays where it is left. On our position-controlled cascade
  the equivalent is an admittance outer loop that moves joint 3's reference with the estimated
  external torque: ``M_a qdd_r + D_a qd_r = dz(r, delta_a)`` (dead zone: model error alone never
  moves the arm), written into the reference rows tick by tick (:func:`hand_guiding_loop`); the
  joint stops when the hand lets go (``qd_r -> 0`` with time constant ``M_a / D_a``). The dead
  zone is the identification's largest ``|r|`` without margin: the torque analogue of the seed's
  nearest-branch rule, which moves the motor only once the joint leaves the identified band.

The evaluation of these loops over recorded runs (detection delay, false alarms, guiding) is
:mod:`fsarm_sim.studies.collision`. All torques are joint-side (q3), N*m; times in s.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.callbacks import DEFAULT_BACKEND, Backend
from fsarm_sim.engine.model import (
    PAYLOAD_MAX_KG,
    SimConfig,
    build_model,
    law_model_writes,
    read_structure,
)
from fsarm_sim.errors import FsarmError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.transmissions.base import TransmissionError
from fsarm_sim.sim import references

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


# --------------------------------------------------------------------------------------------
# What an outer loop is handed, and what it returns
# --------------------------------------------------------------------------------------------

TickHook = Callable[[int], None]  # called before control tick k, may write data / reference rows


class Simulator(Protocol):
    """The running simulation an outer loop is handed (:class:`fsarm_sim.sim.simulation.Simulation`).

    Its class is also how a loop makes collision-free twins (``type(sim)(config, ref_table,
    backend)``), e.g. to identify a threshold for the configuration it runs in.
    """

    config: SimConfig
    backend: Backend
    model: mujoco.MjModel
    data: mujoco.MjData
    interrupted: bool

    def __init__(
        self, config: SimConfig, ref_table: Array, backend: Backend = DEFAULT_BACKEND
    ) -> None: ...

    def run(
        self, duration_s: float, log_every_ticks: int = 1, *, keep_partial: bool = False
    ) -> tuple[dict[str, Array], float]: ...


OuterLoop = Callable[[Simulator], TickHook]
SimulatorClass = Callable[[SimConfig, Array, Backend], Simulator]


class CollisionError(FsarmError, ValueError):
    """A bad observer gain, threshold or detection input."""


def check_positive(name: str, value: float) -> float:
    """``value`` as a float if it is a finite number > 0; else CollisionError naming ``name``."""
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
        self.gain = check_positive("observer gain", gain_rad_s)
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
        # the MJCF's joint-3 damping; an effect law's damping on top of it is unknown to the
        # observer
        self.damping = float(model.dof_damping[st.dof[2]])
        for name, joint, value in law_model_writes(config.effects):
            if name == "dof_damping" and joint == "q3":
                self.damping -= value
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


def observer_residual(
    columns: Mapping[str, Array], config: SimConfig, gain_rad_s: float = GAIN_RAD_S
) -> Array:
    """The observer's ``r`` over recorded columns (one row per control tick, as recorded)."""
    t = columns["t"]
    if len(t) > 1 and not np.allclose(np.diff(t), config.gains.ctrl_dt_s):
        raise CollisionError(
            "the observer needs one recorded row per control tick (log_every_ticks = 1)"
        )
    model = build_model(config, np.zeros((1, layout.REF_COLS)))
    obs = JointThreeObserver(model, config, gain_rad_s)
    q = np.stack([columns["q1"], columns["q2"], columns["q3"]], axis=1)
    return np.array([obs.update(q[k], columns["theta_m"][k]) for k in range(len(t))])


# --------------------------------------------------------------------------------------------
# The threshold, identified on collision-free runs
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Calibration:
    """The detection threshold, identified on collision-free runs (module docstring)."""

    threshold_nm: float
    max_abs_residual_nm: float
    margin: float
    runs: tuple[str, ...]


IDENTIFICATION_NAME = "collision-identification"
IDENTIFICATION_DURATION_S = 6.0
IDENTIFICATION_PAYLOADS_KG = (0.0, PAYLOAD_MAX_KG)  # no payload and the rated one


def identification_reference(t: Array) -> Array:
    """Joint 3 over 0-90 deg at 94 deg/s peak while joint 2 swings 15-60 deg (bend and gravity
    change): the seed identifies its model on sinusoids without disturbance (Sec. III-IV)."""
    return references.stack(
        (
            references.hold(t, 0.0),
            references.cosine_sweep(t, 15.0 * DEG, 60.0 * DEG, 6.0),
            references.cosine_sweep(t, 0.0, 90.0 * DEG, 3.0),
        )
    )


def _identification_columns(
    simulator: SimulatorClass, config: SimConfig, backend: Backend
) -> dict[str, Array]:
    """One collision-free identification run (no disturbance, no outer loop), every tick logged."""
    config.validate()
    dt = config.gains.ctrl_dt_s
    n_ticks = round(IDENTIFICATION_DURATION_S / dt) + 1
    twin = simulator(
        config, identification_reference(np.arange(n_ticks, dtype=np.float64) * dt), backend
    )
    cols, _ = twin.run(IDENTIFICATION_DURATION_S, log_every_ticks=1)  # Ctrl-C: raised, never cut
    return cols


@functools.lru_cache(maxsize=16)
def _calibrate(
    simulator: SimulatorClass, config: SimConfig, gain_rad_s: float, backend: Backend
) -> Calibration:
    worst = 0.0
    runs = []
    for payload in IDENTIFICATION_PAYLOADS_KG:
        label = f"{IDENTIFICATION_NAME} @ {payload:g} kg"
        cfg = config.with_(payload_kg=payload)
        try:
            cols = _identification_columns(simulator, cfg, backend)
        except TransmissionError as exc:  # e.g. a spring that cannot carry the rated payload
            runs.append(f"{label} skipped ({exc})")
            continue
        worst = max(worst, float(np.max(np.abs(observer_residual(cols, cfg, gain_rad_s)))))
        runs.append(label)
    threshold = MARGIN * worst
    if threshold <= 0.0:
        raise CollisionError(
            f"no threshold for {config.transmission}: the identification runs gave no residual "
            f"({'; '.join(runs)})"
        )
    return Calibration(threshold, worst, MARGIN, tuple(runs))


def calibrate(
    simulator: SimulatorClass,
    config: SimConfig,
    gain_rad_s: float = GAIN_RAD_S,
    backend: Backend = DEFAULT_BACKEND,
) -> Calibration:
    """delta_a for this arm and transmission, identified on runs of ``simulator`` (a simulation
    class, e.g. :class:`fsarm_sim.sim.simulation.Simulation`); cached per configuration, payload
    ignored."""
    return _calibrate(simulator, config.with_(payload_kg=0.0), gain_rad_s, backend)


# --------------------------------------------------------------------------------------------
# Outer loops (scenario hooks, once per control tick)
# --------------------------------------------------------------------------------------------


def _ref_rows(sim: Simulator) -> Array:
    return sim.model.numeric(layout.REF_NAME).data.reshape(
        -1, layout.REF_COLS
    )  # a view: writes land


class CollisionReaction:
    """Algorithm 1 online: on the first alarm, joint 3 holds the measured angle (line 8)."""

    def __init__(self, sim: Simulator, threshold_nm: float, gain_rad_s: float = GAIN_RAD_S):
        self.sim = sim
        self.threshold = check_positive("threshold", threshold_nm)
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
        sim: Simulator,
        threshold_nm: float,
        gain_rad_s: float = GAIN_RAD_S,
        damping_nms: float = ADMITTANCE_DAMPING_NMS,
        inertia_kgm2: float = ADMITTANCE_INERTIA_KGM2,
    ) -> None:
        self.sim = sim
        self.threshold = check_positive("dead zone", threshold_nm)
        self.damping = check_positive("admittance damping", damping_nms)
        self.inertia = check_positive("admittance inertia", inertia_kgm2)
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


def reaction_loop(sim: Simulator) -> CollisionReaction:
    """Scenario outer loop: Algorithm 1 with the identified threshold of this configuration."""
    cal = calibrate(type(sim), sim.config, backend=sim.backend)
    return CollisionReaction(sim, cal.threshold_nm)


def hand_guiding_loop(sim: Simulator) -> HandGuiding:
    """Scenario outer loop: Algorithm 2 (admittance), dead zone = the identified error band."""
    cal = calibrate(type(sim), sim.config, backend=sim.backend)
    return HandGuiding(sim, cal.max_abs_residual_nm)
