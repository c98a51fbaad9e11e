"""Pinocchio vs MuJoCo at random states: mass matrix, bias, forward dynamics, controller inputs
(checks 1-3, 5).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import ArmStructure, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.sim.simulation import raise_on_warning
from fsarm_sim.studies import pinocchio_model as pm

FloatArray = npt.NDArray[np.float64]

# Tolerances: double-precision round-off of two independent O(n) recursions on a 4-DOF arm is
# ~1e-15 relative; the entries are O(1-10) kg m^2 and O(100) N*m, so 1e-10 leaves a wide margin
# while any modelling difference (a rounded inertia, a missing armature) shows up far above it.
TOL_MASS = 1e-10  # kg m^2
TOL_BIAS = 1e-10  # N*m
TOL_QACC_REL = 1e-10  # |qacc error| / max(1, |qacc|): the rotor reaches ~1e5 rad/s^2
TOL_CTRL_INPUT = 1e-10  # N*m and kg m^2

# Random-state ranges (estimates spanning the operating envelope with margin):
TWIST_MAX_RAD = 1.0  # ~1.5x the prototype's rated twist (7.7 N*m / 12 N*m/rad)
TWIST_RATE_MAX = 5.0  # rad/s
JOINT_SPEED_MAX = 3.0  # rad/s, ~2x the nominal 1.31-1.48 rad/s of seed 000 Table III
BRANCH_OFFSET_MAX = 0.3  # rad, conduit branch state away from the bend angle
FREE_ACT_MAX = 0.1  # any unlimited state not otherwise known


@dataclass(frozen=True)
class CheckResult:
    """One check: what was compared, its tolerance and the measured value."""

    key: str
    name: str
    measured: float
    tolerance: float
    unit: str
    detail: str = ""
    at_least: bool = False  # True: the measured value must reach the tolerance (an order)
    extra: dict[str, float] = field(default_factory=dict)  # further numbers for the JSON report

    @property
    def passed(self) -> bool:
        if not math.isfinite(self.measured):
            return False
        if self.at_least:
            return self.measured >= self.tolerance
        return self.measured <= self.tolerance

    def as_dict(self) -> dict[str, object]:
        return {
            "key": self.key,
            "name": self.name,
            "measured": self.measured,
            "tolerance": self.tolerance,
            "comparison": ">=" if self.at_least else "<=",
            "unit": self.unit,
            "passed": self.passed,
            "detail": self.detail,
            **self.extra,
        }


@dataclass
class Pair:
    """The same run as a MuJoCo model (with fsarm's callbacks) and as a Pinocchio model."""

    config: SimConfig
    ref_table: FloatArray
    mj: mujoco.MjModel
    data: mujoco.MjData
    arm: pm.PinocchioArm
    st: ArmStructure
    label: str = ""

    @property
    def params(self) -> FloatArray:
        return self.mj.numeric(layout.PARAMS_NAME).data

    @property
    def reference(self) -> FloatArray:
        return self.mj.numeric(layout.REF_NAME).data

    @property
    def state_act(self) -> tuple[int, ...]:
        """act addresses whose rates come from mjcb_act_dyn (dyntype 'user')."""
        m = self.mj
        user = int(mujoco.mjtDyn.mjDYN_USER)
        return tuple(
            int(m.actuator_actadr[a]) for a in range(m.nu) if int(m.actuator_dyntype[a]) == user
        )


@dataclass(frozen=True)
class State:
    """A full MuJoCo state for one comparison (MuJoCo order)."""

    qpos: FloatArray
    qvel: FloatArray
    act: FloatArray
    ctrl: FloatArray


def make_pair(config: SimConfig, ref_table: FloatArray, label: str = "") -> Pair:
    """Build both models of one run (MuJoCo is stepped with fsarm's Python callbacks active)."""
    mj = build_model(config, ref_table)
    return Pair(
        config=config,
        ref_table=np.ascontiguousarray(ref_table, dtype=np.float64),
        mj=mj,
        data=mujoco.MjData(mj),
        arm=pm.load_pinocchio_arm(config, ref_table),
        st=read_structure(mj),
        label=label,
    )


def hold_table(n_ticks: int = 2) -> FloatArray:
    """A reference table that holds the home pose (for checks that never run the controller)."""
    return np.zeros((n_ticks, layout.REF_COLS))


def open_loop(config: SimConfig) -> SimConfig:
    """The same run with the controller off: ``ctrl`` stays whatever the check sets."""
    return config.with_(effects=replace(config.effects, control=False))


# --- random states -------------------------------------------------------------------------


def random_state(pair: Pair, rng: np.random.Generator) -> State:
    """A random state across the envelope: joint ranges, twist, speeds, internal states, motors."""
    m, st = pair.mj, pair.st
    qpos = np.zeros(m.nq)
    qvel = np.zeros(m.nv)
    for i, name in enumerate(pm.JOINT_NAMES[:3]):
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        lo, hi = m.jnt_range[j] if m.jnt_limited[j] else (-math.pi, math.pi)
        qpos[st.qadr[i]] = rng.uniform(lo, hi)
        qvel[st.dof[i]] = rng.uniform(-JOINT_SPEED_MAX, JOINT_SPEED_MAX)
    twist = rng.uniform(-TWIST_MAX_RAD, TWIST_MAX_RAD)
    rate = rng.uniform(-TWIST_RATE_MAX, TWIST_RATE_MAX)
    qpos[st.qadr[3]] = (st.coef_s * qpos[st.qadr[2]] + twist) / st.coef_m
    qvel[st.dof[3]] = (st.coef_s * qvel[st.dof[2]] + rate) / st.coef_m
    return State(qpos, qvel, _random_act(pair, qpos, rng), _random_ctrl(m, rng))


def _random_act(pair: Pair, qpos: FloatArray, rng: np.random.Generator) -> FloatArray:
    m, st = pair.mj, pair.st
    act = rng.uniform(-FREE_ACT_MAX, FREE_ACT_MAX, m.na)
    for a in range(m.nu):
        adr = int(m.actuator_actadr[a])
        if adr >= 0 and m.actuator_actlimited[a]:
            lo, hi = m.actuator_actrange[a]
            act[adr] = rng.uniform(lo, hi)
    bend = qpos[st.qadr[1]]
    for adr in st.act_branch:
        act[adr] = bend + rng.uniform(-BRANCH_OFFSET_MAX, BRANCH_OFFSET_MAX)
    return act


def _random_ctrl(m: mujoco.MjModel, rng: np.random.Generator) -> FloatArray:
    ctrl = np.zeros(m.nu)
    for a in range(m.nu):
        if m.actuator_ctrllimited[a]:
            lo, hi = m.actuator_ctrlrange[a]
            ctrl[a] = rng.uniform(lo, hi)
    return ctrl


def set_state(pair: Pair, s: State) -> None:
    """Load a state into the MuJoCo data and run mj_forward (callbacks on); fail on warnings."""
    d = pair.data
    mujoco.mj_resetData(pair.mj, d)
    d.qpos[:] = s.qpos
    d.qvel[:] = s.qvel
    d.act[:] = s.act
    d.ctrl[:] = s.ctrl
    d.time = 0.5 * float(pair.params[layout.P_CTRL_DT])  # between control ticks
    with callbacks.active("python"):
        mujoco.mj_forward(pair.mj, d)
    raise_on_warning(d)


# --- generalized forces the Pinocchio side adds ------------------------------------------------


def actuator_forces(m: mujoco.MjModel, ctrl: FloatArray, act: FloatArray) -> FloatArray:
    """Generalized forces of joint-transmission actuators with fixed gain and no bias."""
    out = np.zeros(m.nv)
    for a in range(m.nu):
        if int(m.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT):
            raise ModelStructureError("only joint-transmission actuators are supported")
        if int(m.actuator_gaintype[a]) != int(mujoco.mjtGain.mjGAIN_FIXED) or (
            int(m.actuator_biastype[a]) != int(mujoco.mjtBias.mjBIAS_NONE)
        ):
            raise ModelStructureError("only fixed-gain, bias-free actuators are supported")
        if int(m.actuator_dyntype[a]) == int(mujoco.mjtDyn.mjDYN_NONE):
            u = float(ctrl[a])
            if m.actuator_ctrllimited[a]:
                u = min(max(u, m.actuator_ctrlrange[a, 0]), m.actuator_ctrlrange[a, 1])
        else:
            u = float(act[m.actuator_actadr[a]])
        force = float(m.actuator_gainprm[a, 0]) * u
        if m.actuator_forcelimited[a]:
            force = min(max(force, m.actuator_forcerange[a, 0]), m.actuator_forcerange[a, 1])
        dof = int(m.jnt_dofadr[m.actuator_trnid[a, 0]])
        out[dof] += float(m.actuator_gear[a, 0]) * force
    return out


def applied_forces(pair: Pair, s: State) -> FloatArray:
    """Everything but bias and inertia: shaft constitutive forces - damping + motors."""
    tau = np.zeros(pair.mj.nv)
    physics.passive_forces(pair.params, s.qpos, s.qvel, s.act, tau, np.zeros(layout.N_USERDATA))
    tau -= pair.arm.damping * s.qvel
    tau += actuator_forces(pair.mj, s.ctrl, s.act)
    return tau


# --- checks 1, 2, 3, 5 -----------------------------------------------------------------------


def _states(pair: Pair, n: int, seed: int) -> list[State]:
    if n < 1:
        raise InvalidParameterError(f"number of random states must be >= 1, got {n}")
    rng = np.random.default_rng(seed)
    return [random_state(pair, rng) for _ in range(n)]


def _max_over(
    pairs: Iterable[Pair], n: int, seed: int, err: Callable[[Pair, State], float]
) -> float:
    return _max_over_many(pairs, n, seed, lambda p, s: (err(p, s),))[0]


def _max_over_many(
    pairs: Iterable[Pair],
    n: int,
    seed: int,
    err: Callable[[Pair, State], tuple[float, ...]],
) -> tuple[float, ...]:
    """Worst value of each error over ``n`` random states of every model."""
    worst: tuple[float, ...] = ()
    for pair in pairs:
        for s in _states(pair, n, seed):
            set_state(pair, s)
            e = err(pair, s)
            worst = tuple(max(a, b) for a, b in zip(worst, e, strict=True)) if worst else e
    return worst


def mass_matrix_error(pair: Pair, s: State) -> float:
    full = np.zeros((pair.mj.nv, pair.mj.nv))
    mujoco.mj_fullM(pair.mj, pair.data, full)
    return float(np.max(np.abs(full - pm.mass_matrix(pair.arm, s.qpos))))


def bias_error(pair: Pair, s: State) -> float:
    return float(np.max(np.abs(pair.data.qfrc_bias - pm.bias(pair.arm, s.qpos, s.qvel))))


def qacc_errors(pair: Pair, s: State) -> tuple[float, float, float]:
    """(relative |a_mj - a_pin| / max(1, |a_pin|), absolute, absolute on q1-q3), worst dof."""
    acc = pm.forward_dynamics(pair.arm, s.qpos, s.qvel, applied_forces(pair, s))
    diff = np.abs(pair.data.qacc - acc)
    links = list(pair.st.dof[:3])
    return (
        float(np.max(diff / np.maximum(1.0, np.abs(acc)))),
        float(np.max(diff)),
        float(np.max(diff[links])),
    )


def controller_input_error(pair: Pair, s: State) -> float:
    """What ``physics.control`` reads (bias[dof], M[madr] via the parameter vector) vs Pinocchio."""
    prm, d = pair.params, pair.data
    bias_pin = pm.bias(pair.arm, s.qpos, s.qvel)
    mass_pin = pm.mass_matrix(pair.arm, s.qpos)
    worst = 0.0
    for p_dof, p_madr, dof in zip(
        (layout.P_DOF_Q1, layout.P_DOF_Q2, layout.P_DOF_Q3),
        (layout.P_MADR_Q1, layout.P_MADR_Q2, layout.P_MADR_Q3),
        pair.st.dof[:3],
        strict=True,
    ):
        worst = max(worst, abs(d.qfrc_bias[int(prm[p_dof])] - bias_pin[dof]))
        worst = max(worst, abs(d.M[int(prm[p_madr])] - mass_pin[dof, dof]))
    return float(worst)


def check_mass_matrix(pairs: list[Pair], n: int, seed: int = 0) -> CheckResult:
    worst = _max_over(pairs, n, seed, mass_matrix_error)
    return CheckResult(
        "mass_matrix",
        "mass matrix: mj_fullM vs pin.crba (+ J a a^T)",
        worst,
        TOL_MASS,
        "kg m^2",
        f"max |M_mj - M_pin| over {n} random states x {len(pairs)} models",
    )


def check_bias(pairs: list[Pair], n: int, seed: int = 1) -> CheckResult:
    worst = _max_over(pairs, n, seed, bias_error)
    return CheckResult(
        "bias",
        "bias: qfrc_bias vs pin.rnea(q, v, 0)",
        worst,
        TOL_BIAS,
        "N*m",
        f"max |c_mj - c_pin| over {n} random states x {len(pairs)} models",
    )


def check_qacc(pairs: list[Pair], n: int, seed: int = 2) -> CheckResult:
    for pair in pairs:
        if pair.config.effects.control:
            raise InvalidParameterError(
                "the forward-dynamics check needs the controller off (dynamics_check.open_loop)"
            )
    rel, absolute, links = _max_over_many(pairs, n, seed, qacc_errors)
    return CheckResult(
        "qacc",
        "forward dynamics: MuJoCo qacc (callbacks) vs pin.aba",
        rel,
        TOL_QACC_REL,
        "relative",
        f"max |a_mj - a_pin| / max(1, |a_pin|) over {n} states x {len(pairs)} models "
        f"(shaft forces, damping, motors, random act); absolute {absolute:.3g} rad/s^2 "
        f"(q1-q3: {links:.3g})",
        extra={"max_abs_err": absolute, "max_abs_err_links": links},
    )


def check_controller_inputs(pairs: list[Pair], n: int, seed: int = 3) -> CheckResult:
    worst = _max_over(pairs, n, seed, controller_input_error)
    return CheckResult(
        "controller_inputs",
        "controller inputs: bias and M_ii read by physics.control vs Pinocchio",
        worst,
        TOL_CTRL_INPUT,
        "N*m | kg m^2",
        f"q1-q3 through fsarm_params' P_DOF_*/P_MADR_* over {n} states x {len(pairs)} models",
    )
