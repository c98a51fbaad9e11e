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

import itertools
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import ArmStructure, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout as L
from fsarm_sim.kernels import physics
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import check_duration, initial_state, raise_on_warning
from fsarm_sim.studies import energy_check
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
        return self.mj.numeric(L.PARAMS_NAME).data

    @property
    def reference(self) -> FloatArray:
        return self.mj.numeric(L.REF_NAME).data

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
    return np.zeros((n_ticks, L.REF_COLS))


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
    d.time = 0.5 * float(pair.params[L.P_CTRL_DT])  # between control ticks
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
    physics.passive_forces(pair.params, s.qpos, s.qvel, s.act, tau, np.zeros(L.N_USERDATA))
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
        (L.P_DOF_Q1, L.P_DOF_Q2, L.P_DOF_Q3),
        (L.P_MADR_Q1, L.P_MADR_Q2, L.P_MADR_Q3),
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


# --- check 4: the elastic-joint structure of seed 000 eq. 5-7 ---------------------------------
#
# Coordinates x = (q1, q2, q3, theta) with theta = theta_m = rotor / i_G1, the shaft input angle
# after the 16:1 gearbox: qpos = T x, T = diag(1, 1, 1, i_G1), so M_x = T^T M T and tau_x = T^T tau.
# In x the rigid-body inertia is [[M_SEA, S], [S^T, B33]] with S the theta column (eq. 5-7):
#   S(1,3) = I_r3,zz i_G1 (rotor axis parallel to joint 1), S(2,3) = S(3,3) = 0,
#   B(3,3) = I_r3,zz i_G1^2, B(1,1), B(2,2) = the reflected rotor inertias (armature of q1, q2),
#   M_R(1,1) = m_r3 r3^2 (joint-3 motor on link 1), K_SEA(3,3) = K_s i_G2^2, K_PEA(2,2) = K_b.
# Seed 000 neglects the eq. 1 shaft inertia J; the rigid part measured here excludes it.

MOTOR3_BODIES = ("j3_motor_housing", "j3_rotor")  # joint-3 motor on link 1 (fsarm.xml)
ROTOR_BODY = "j3_rotor"
TOL_STRUCTURE = 1e-9  # relative to each entry's scale
STIFFNESS_PROBE_RAD = 1e-6  # finite-difference step for K (the springs are piecewise linear)


@dataclass(frozen=True)
class StructureEntry:
    """One entry of eq. 5-7: measured (Pinocchio / MuJoCo forces) vs implied by the MJCF."""

    name: str
    measured: float
    expected: float
    scale: float
    unit: str

    @property
    def error(self) -> float:
        return abs(self.measured - self.expected) / self.scale


@dataclass(frozen=True)
class ElasticJointStructure:
    entries: tuple[StructureEntry, ...]
    m_sea_home: FloatArray  # link-side inertia at the home pose, kg m^2
    k_sea_pos: FloatArray  # 4x4 stiffness in x, winding side, at the straight upright pose
    k_sea_neg: FloatArray

    @property
    def max_error(self) -> float:
        return max(e.error for e in self.entries)


def _x_transform(pair: Pair) -> FloatArray:
    """T with qvel = T xdot (MuJoCo dof order; theta = rotor / i_G1)."""
    t = np.eye(pair.mj.nv)
    t[pair.st.dof[3], pair.st.dof[3]] = pair.st.i_g1
    return t


def _x_order(pair: Pair) -> list[int]:
    return [pair.st.dof[0], pair.st.dof[1], pair.st.dof[2], pair.st.dof[3]]


def rigid_mass_x(pair: Pair, qpos: FloatArray, arm: pm.PinocchioArm | None = None) -> FloatArray:
    """Pinocchio's rigid-body mass matrix in x = (q1, q2, q3, theta), rows in that order."""
    t = _x_transform(pair)
    m_x = t.T @ pm.rigid_mass_matrix(arm or pair.arm, qpos) @ t
    idx = _x_order(pair)
    return np.asarray(m_x[np.ix_(idx, idx)], dtype=np.float64)


def _body(m: mujoco.MjModel, name: str) -> int:
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
    if b < 0:
        raise ModelStructureError(f"the MJCF has no body named '{name}', which check 4 needs")
    return int(b)


def _is_ancestor(m: mujoco.MjModel, ancestor: int, body: int) -> bool:
    while body > 0:
        if body == ancestor:
            return True
        body = int(m.body_parentid[body])
    return False


@dataclass(frozen=True)
class _Kinematics:
    """MuJoCo kinematics at the home pose: what the MJCF implies, nothing from Pinocchio."""

    axis: FloatArray  # joint axes (4, 3), world
    anchor: FloatArray  # joint anchors (4, 3)
    com: FloatArray  # body COMs (nbody, 3)
    inertia: FloatArray  # rotor inertia about its COM, world (3, 3)
    rotor_mass: float


def _home_kinematics(pair: Pair) -> _Kinematics:
    m = pair.mj
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    joints = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in pm.JOINT_NAMES]
    b = _body(m, ROTOR_BODY)
    rot = d.ximat[b].reshape(3, 3)
    return _Kinematics(
        axis=np.array([d.xaxis[j] for j in joints]),
        anchor=np.array([d.xanchor[j] for j in joints]),
        com=np.array(d.xipos),
        inertia=rot @ np.diag(m.body_inertia[b]) @ rot.T,
        rotor_mass=float(m.body_mass[b]),
    )


def _implied_rotor_coupling(pair: Pair, k: _Kinematics, i: int) -> float:
    """M[q_i, rotor] the MJCF implies: rotor spatial inertia projected on both joint axes."""
    m = pair.mj
    b = _body(m, ROTOR_BODY)
    joint = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, pm.JOINT_NAMES[i])
    if i != 3 and not _is_ancestor(m, int(m.jnt_bodyid[joint]), int(m.body_parentid[b])):
        return 0.0  # the joint does not move the rotor
    c = k.com[b]
    lin_i = np.cross(k.axis[i], c - k.anchor[i])
    lin_r = np.cross(k.axis[3], c - k.anchor[3])
    return float(k.rotor_mass * lin_i @ lin_r + k.axis[i] @ k.inertia @ k.axis[3])


def _inertial_entries(pair: Pair, qs: list[FloatArray]) -> list[StructureEntry]:
    m, st = pair.mj, pair.st
    k = _home_kinematics(pair)
    home = rigid_mass_x(pair, np.zeros(m.nq))
    s_exp = [_implied_rotor_coupling(pair, k, i) * st.i_g1 for i in range(3)]
    i_rzz = float(k.axis[3] @ k.inertia @ k.axis[3])
    b33_exp = (_implied_rotor_coupling(pair, k, 3) + m.dof_armature[st.dof[3]]) * st.i_g1**2
    s_scale = abs(s_exp[0]) if s_exp[0] != 0.0 else 1.0
    drift_s = max(float(np.max(np.abs(rigid_mass_x(pair, q)[:3, 3] - home[:3, 3]))) for q in qs)
    drift_b = max(abs(rigid_mass_x(pair, q)[3, 3] - home[3, 3]) for q in qs)
    cos_axes = float(abs(k.axis[0] @ k.axis[3]))
    return [
        StructureEntry("S(1,3) = I_r3,zz i_G1", home[0, 3], s_exp[0], s_scale, "kg m^2"),
        StructureEntry("S(2,3) = 0", home[1, 3], s_exp[1], s_scale, "kg m^2"),
        StructureEntry("S(3,3) = 0", home[2, 3], s_exp[2], s_scale, "kg m^2"),
        StructureEntry("S constant in q (C1 = C2 = 0)", drift_s, 0.0, s_scale, "kg m^2"),
        StructureEntry("rotor axis parallel to joint 1: 1 - |cos|", 1.0 - cos_axes, 0.0, 1.0, "-"),
        StructureEntry("B(3,3) = I_r3,zz i_G1^2", home[3, 3], b33_exp, b33_exp, "kg m^2"),
        StructureEntry("B(3,3) constant in q", drift_b, 0.0, b33_exp, "kg m^2"),
        StructureEntry("I_r3,zz (for S, B)", home[0, 3] / st.i_g1, i_rzz, i_rzz, "kg m^2"),
        *_armature_entries(pair),
        _motor_mass_entry(pair, k),
    ]


def _entry(
    name: str, measured: float, expected: float, fallback: float, unit: str
) -> StructureEntry:
    """An entry relative to its own value (or to ``fallback`` where it should be zero)."""
    scale = abs(float(expected)) if expected != 0.0 else fallback
    return StructureEntry(name, float(measured), float(expected), scale, unit)


def _armature_entries(pair: Pair) -> list[StructureEntry]:
    """B(1,1), B(2,2): Pinocchio's mass matrix minus the same model without armature."""
    m, st = pair.mj, pair.st
    bare = pm.parse_mjcf(pair.arm.mjcf)
    bare.armature[:] = 0.0
    no_arm = replace(pair.arm, model=bare, data=bare.createData())
    q = np.zeros(m.nq)
    diff = rigid_mass_x(pair, q) - rigid_mass_x(pair, q, no_arm)
    arm = [float(m.dof_armature[d]) for d in st.dof[:3]]
    fallback = max(arm) if max(arm) > 0.0 else 1.0  # kg m^2
    off = float(np.max(np.abs(diff - np.diag(np.diag(diff)))))
    return [
        _entry("B(1,1) = I_r1,zz i_1^2 (q1 armature)", diff[0, 0], arm[0], fallback, "kg m^2"),
        _entry("B(2,2) = I_r2,zz i_2^2 (q2 armature)", diff[1, 1], arm[1], fallback, "kg m^2"),
        _entry("q3 armature (hypoid, not in seed 000's B)", diff[2, 2], arm[2], fallback, "kg m^2"),
        _entry("B off-diagonal = 0", off, 0.0, fallback, "kg m^2"),
    ]


def _motor_mass_entry(pair: Pair, k: _Kinematics) -> StructureEntry:
    """M_R(1,1) = m_r3 r3^2: Pinocchio's M(1,1) minus the same model with the motor massless."""
    m = pair.mj
    root = ET.fromstring(pair.arm.mjcf)
    expected = 0.0
    for name in MOTOR3_BODIES:
        b = _body(m, name)
        lever = np.cross(k.axis[0], k.com[b] - k.anchor[0])
        expected += float(m.body_mass[b] * lever @ lever)
        el = root.find(f".//body[@name='{name}']/inertial")
        if el is None:
            raise ModelStructureError(f"body '{name}' needs an explicit <inertial> for check 4")
        el.set("mass", "0")
    light = pm.parse_mjcf(ET.tostring(root, encoding="unicode"))
    no_motor = replace(pair.arm, model=light, data=light.createData())
    q = np.zeros(m.nq)
    measured = rigid_mass_x(pair, q)[0, 0] - rigid_mass_x(pair, q, no_motor)[0, 0]
    return _entry("M_R(1,1) = m_r3 r3^2", measured, expected, 1.0, "kg m^2")


def passive_at(pair: Pair, x: FloatArray) -> FloatArray:
    """MuJoCo's qfrc_passive (callbacks on) at rest at x, branches relaxed, slip unloaded; in x."""
    m, st = pair.mj, pair.st
    d = mujoco.MjData(m)
    for i in range(3):
        d.qpos[st.qadr[i]] = x[i]
    d.qpos[st.qadr[3]] = st.i_g1 * x[3]
    for adr in st.act_branch:
        d.act[adr] = x[1]  # relaxed conduit branches: the static (eq. 4) stiffness
    d.time = 0.5 * float(pair.params[L.P_CTRL_DT])
    with callbacks.active("python"):
        mujoco.mj_forward(m, d)
    raise_on_warning(d)
    tau_x = _x_transform(pair).T @ d.qfrc_passive
    return np.asarray(tau_x[_x_order(pair)], dtype=np.float64)


def stiffness_x(pair: Pair, side: int) -> FloatArray:
    """-d tau_x / d x at the straight, untwisted pose; twist probes on the given side only."""
    h = STIFFNESS_PROBE_RAD
    out = np.zeros((4, 4))
    zero = passive_at(pair, np.zeros(4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = h
        if j < 2:  # q1, q2: no twist, central difference
            out[:, j] = -(passive_at(pair, e) - passive_at(pair, -e)) / (2 * h)
        else:  # q3 raises theta_s (twist falls), theta raises the twist
            step = e * (side if j == 3 else -side)
            out[:, j] = -(passive_at(pair, step) - zero) / float(step[j])
    return out


def implied_stiffness_x(pair: Pair, side: int) -> FloatArray:
    """K_SEA + K_PEA in x from the shaft parameters (eq. 3 at phi_B = 0, eq. 4).

    K_s is the plant's spring: eq. 3, less the slip elements' apparent stiffness while they are
    on (``ShaftParams.k_spring``; the probe leaves the elements unloaded)."""
    sh, fx, g2 = pair.config.shaft, pair.config.effects, pair.st.i_g2
    spring = sh.k_spring(0.0, side) if fx.slip else sh.k_series(0.0, side)
    ks = spring if fx.series else 0.0
    k = np.zeros((4, 4))
    k[1, 1] = sh.kb if fx.bending else 0.0
    k[2:, 2:] = ks * np.array([[g2 * g2, -g2], [-g2, 1.0]])
    return k


def _k_entry(name: str, measured: float, expected: float, fallback: float) -> StructureEntry:
    return _entry(name, measured, expected, fallback, "N*m/rad")


def _stiffness_entries(pair: Pair) -> tuple[list[StructureEntry], FloatArray, FloatArray]:
    entries: list[StructureEntry] = []
    mats = []
    for side, tag in ((1, "winding, K_sp"), (-1, "unwinding, K_sn")):
        meas, exp = stiffness_x(pair, side), implied_stiffness_x(pair, side)
        nonzero = np.abs(exp[exp != 0.0])
        fallback = float(nonzero.min()) if nonzero.size else 1.0  # N*m/rad
        pattern = float(np.max(np.abs(meas - exp) * (exp == 0.0)))
        entries += [
            _k_entry(f"K_SEA(3,3) = K_s i_G2^2 ({tag})", meas[2, 2], exp[2, 2], fallback),
            _k_entry(f"K(q3, theta) = -K_s i_G2 ({tag})", meas[2, 3], exp[2, 3], fallback),
            _k_entry(f"K(theta, theta) = K_s ({tag})", meas[3, 3], exp[3, 3], fallback),
            _k_entry(f"K_PEA(2,2) = K_b ({tag})", meas[1, 1], exp[1, 1], fallback),
            _k_entry(
                f"K = 0 elsewhere: no spring on q1, joints 1-2 rigid (K_SEA = inf) ({tag})",
                pattern,
                0.0,
                fallback,
            ),
        ]
        mats.append(meas)
    return entries, mats[0], mats[1]


def elastic_structure(pair: Pair, n_q: int = 8, seed: int = 4) -> ElasticJointStructure:
    """Measure the eq. 5-7 entries and compare them with what the MJCF and shaft imply."""
    rng = np.random.default_rng(seed)
    qs = [random_state(pair, rng).qpos for _ in range(max(n_q, 1))]
    k_entries, k_pos, k_neg = _stiffness_entries(pair)
    entries = [*_inertial_entries(pair, qs), *k_entries]
    home = rigid_mass_x(pair, np.zeros(pair.mj.nq))
    return ElasticJointStructure(tuple(entries), home[:3, :3].copy(), k_pos, k_neg)


def check_structure(structure: ElasticJointStructure) -> CheckResult:
    worst = max(structure.entries, key=lambda e: e.error)
    return CheckResult(
        "structure",
        "eq. 5-7 structure: S, B, M_R, K_SEA, K_PEA vs the MJCF",
        structure.max_error,
        TOL_STRUCTURE,
        "relative",
        f"{len(structure.entries)} entries; worst: {worst.name}",
    )


# --- check 6: closed-loop trajectories, MuJoCo vs an independent Pinocchio integration ------
#
# The reference integrates the same closed loop with its own fixed-step RK4: Pinocchio ABA, the
# same constitutive forces and state rates (physics.passive_forces / state_rate), the same
# controller (physics.control_tick fed with Pinocchio's bias and inertia diagonal), zero-order
# hold between control ticks, the same reference table and initial state.
#
# MuJoCo's RK4 calls mjcb_control at every stage; its fourth stage of the step that ends on a
# control tick sits exactly on that tick. physics.control keeps the held output there (P_RK4), so
# MuJoCo's closed loop is a true zero-order hold like the reference's, and the two can be compared
# step for step at the same dt (applying tick k+1 in that stage would make the loop only first
# order: this check would find it).

STATE_ACT_DYN = int(mujoco.mjtDyn.mjDYN_USER)


@dataclass(frozen=True)
class ArmState:
    qpos: FloatArray
    qvel: FloatArray
    act: FloatArray

    def moved(self, h: float, rate: ArmState) -> ArmState:
        return ArmState(
            self.qpos + h * rate.qpos, self.qvel + h * rate.qvel, self.act + h * rate.act
        )


def _check_integrable(m: mujoco.MjModel) -> None:
    if m.nq != m.nv or np.any(
        (m.jnt_type != mujoco.mjtJoint.mjJNT_HINGE) & (m.jnt_type != mujoco.mjtJoint.mjJNT_SLIDE)
    ):
        raise ModelStructureError("the reference integrator supports hinge and slide joints only")
    for a in range(m.nu):
        if int(m.actuator_dyntype[a]) not in (int(mujoco.mjtDyn.mjDYN_NONE), STATE_ACT_DYN):
            raise ModelStructureError("actuator states must be dyntype 'user' (mjcb_act_dyn)")


def state_rates(
    pair: Pair, x: ArmState, tau_ctrl: FloatArray, state_act: tuple[int, ...]
) -> ArmState:
    """d/dt (qpos, qvel, act) on Pinocchio: ABA with the shaft forces, damping and motor forces."""
    prm, m = pair.params, pair.mj
    tau = np.zeros(m.nv)
    ud = np.zeros(L.N_USERDATA)
    physics.passive_forces(prm, x.qpos, x.qvel, x.act, tau, ud)
    tau += tau_ctrl - pair.arm.damping * x.qvel
    act_dot = np.zeros(m.na)
    for adr in state_act:
        act_dot[adr] = physics.state_rate(prm, x.qpos, x.qvel, x.act, adr, ud)
    return ArmState(x.qvel.copy(), pm.forward_dynamics(pair.arm, x.qpos, x.qvel, tau), act_dot)


def control_forces(
    pair: Pair, k: int, x: ArmState, mem: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Control tick k on Pinocchio's model terms: (generalized motor forces, new memory)."""
    m, st = pair.mj, pair.st
    bias = pm.bias(pair.arm, x.qpos, x.qvel)
    full = pm.mass_matrix(pair.arm, x.qpos)
    mass = np.zeros(m.nM)
    for i in range(3):
        mass[st.madr[i]] = full[st.dof[i], st.dof[i]]
    mem_out = mem.copy()
    out = np.zeros(3)
    physics.control_tick(
        pair.params,
        pair.reference,
        k,
        x.qpos,
        x.qvel,
        bias,
        mass,
        mem,
        mem_out,
        out,
        np.zeros(L.N_LOG),
    )
    ctrl = np.zeros(m.nu)
    ctrl[list(st.ctrl)] = out
    return actuator_forces(m, ctrl, x.act), mem_out


def rk4_step(pair: Pair, x: ArmState, h: float, tau_ctrl: FloatArray) -> ArmState:
    """One classic RK4 step with the control held (zero-order hold)."""
    acts = pair.state_act
    k1 = state_rates(pair, x, tau_ctrl, acts)
    k2 = state_rates(pair, x.moved(0.5 * h, k1), tau_ctrl, acts)
    k3 = state_rates(pair, x.moved(0.5 * h, k2), tau_ctrl, acts)
    x4 = x.moved(h, k3)
    k4 = state_rates(pair, x4, tau_ctrl, acts)
    rate = ArmState(
        (k1.qpos + 2 * k2.qpos + 2 * k3.qpos + k4.qpos) / 6.0,
        (k1.qvel + 2 * k2.qvel + 2 * k3.qvel + k4.qvel) / 6.0,
        (k1.act + 2 * k2.act + 2 * k3.act + k4.act) / 6.0,
    )
    nxt = x.moved(h, rate)
    return ArmState(nxt.qpos, nxt.qvel, _clamp_act(pair.mj, nxt.act))


def _clamp_act(m: mujoco.MjModel, act: FloatArray) -> FloatArray:
    out = act.copy()
    for a in range(m.nu):
        adr = int(m.actuator_actadr[a])
        if adr >= 0 and m.actuator_actlimited[a]:
            out[adr] = min(max(out[adr], m.actuator_actrange[a, 0]), m.actuator_actrange[a, 1])
    return out


def substeps(pair: Pair, dt: float) -> int:
    ctrl_dt = float(pair.params[L.P_CTRL_DT])
    n = round(ctrl_dt / dt)
    if n < 1 or abs(n * dt - ctrl_dt) > 1e-9 * ctrl_dt:
        raise InvalidParameterError(
            f"time step {dt:g} s must divide the control period {ctrl_dt:g} s a whole number of times"
        )
    return n


def start_state(pair: Pair) -> tuple[ArmState, FloatArray]:
    """simulation.initial_state on the MuJoCo side, copied: (state, controller memory)."""
    d = mujoco.MjData(pair.mj)
    initial_state(pair.mj, d, pair.st)
    mem = np.array(d.userdata[L.U_MEM : L.U_MEM + L.N_MEM])
    return ArmState(d.qpos.copy(), d.qvel.copy(), d.act.copy()), mem


def integrate_pinocchio(pair: Pair, n_ticks: int, dt: float) -> FloatArray:
    """qpos at every control tick (n_ticks + 1 rows) of the Pinocchio closed loop."""
    _check_integrable(pair.mj)
    n_sub = substeps(pair, dt)
    x, mem = start_state(pair)
    out = np.empty((n_ticks + 1, pair.mj.nq))
    out[0] = x.qpos
    for k in range(n_ticks):
        tau_ctrl, mem = control_forces(pair, k, x, mem)
        for _ in range(n_sub):
            x = rk4_step(pair, x, dt, tau_ctrl)
        if not (np.all(np.isfinite(x.qpos)) and np.all(np.isfinite(x.qvel))):
            raise InvalidParameterError(f"Pinocchio reference diverged at tick {k} (dt = {dt:g} s)")
        out[k + 1] = x.qpos
    return out


def integrate_mujoco(
    config: SimConfig, ref_table: FloatArray, n_ticks: int, dt: float, integrator: str
) -> FloatArray:
    """qpos at every control tick of MuJoCo's own closed loop (Python callbacks)."""
    m = build_model(config.with_(integrator=integrator, timestep_s=dt), ref_table)
    d = mujoco.MjData(m)
    initial_state(m, d, read_structure(m))
    n_sub = round(config.gains.ctrl_dt_s / dt)
    out = np.empty((n_ticks + 1, m.nq))
    out[0] = d.qpos
    with callbacks.active("python"):
        for k in range(n_ticks):
            mujoco.mj_step(m, d, nstep=n_sub)
            out[k + 1] = d.qpos
    raise_on_warning(d)
    return out


TRAJECTORY_SCENARIO = "fig14-sine"
TRAJECTORY_DTS = (1e-3, 5e-4, 2.5e-4)  # s; each divides the 1 ms control period
TOL_SAME_DT_RAD = 1e-9  # MuJoCo RK4 vs the Pinocchio RK4 loop, same dt
TOL_TRAJECTORY_RAD = 1e-4  # MuJoCo RK4 at the largest dt vs the converged zero-order-hold loop
MIN_ORDER_MUJOCO = 3.5  # MuJoCo's RK4 closed loop is fourth order too (zero-order hold)
MIN_ORDER_REFERENCE = 3.5  # the reference RK4 is itself fourth order


@dataclass(frozen=True)
class ConvergenceRow:
    dt_s: float
    mujoco_vs_reference_rad: float  # MuJoCo RK4 vs converged zero-order-hold reference
    pinocchio_vs_reference_rad: float  # Pinocchio RK4 (zero-order hold) at dt vs reference
    mujoco_vs_pinocchio_same_dt_rad: float  # MuJoCo RK4 vs Pinocchio RK4, same dt
    order_mujoco: float | None  # observed order from the previous (larger) dt
    order_pinocchio: float | None


@dataclass(frozen=True)
class TrajectoryStudy:
    scenario: str
    duration_s: float
    reference_dt_s: float
    rows: tuple[ConvergenceRow, ...]
    mujoco_euler_default_rad: float  # the simulator's default (Euler, 1 ms) vs the reference


def _q_error(a: FloatArray, b: FloatArray, qadr: tuple[int, ...]) -> float:
    cols = list(qadr[:3])
    return float(np.max(np.abs(a[:, cols] - b[:, cols])))


def _order(e_big: float, e_small: float, dt_big: float, dt_small: float) -> float:
    if e_small <= 0.0 or e_big <= 0.0:
        return float("nan")
    return math.log(e_big / e_small) / math.log(dt_big / dt_small)


def trajectory_study(
    duration_s: float,
    dts: tuple[float, ...] = TRAJECTORY_DTS,
    config: SimConfig | None = None,
    arm: pm.PinocchioArm | None = None,
) -> TrajectoryStudy:
    """Run fig14-sine on MuJoCo (RK4 at each dt) and on Pinocchio; errors on q1..q3 (rad).

    ``arm`` replaces the Pinocchio model (tests use it to show that a wrong model fails).
    """
    if not dts or any(b >= a for a, b in itertools.pairwise(dts)):
        raise InvalidParameterError(
            f"time steps must be a decreasing, non-empty sequence, got {dts}"
        )
    sc = scenarios.get(TRAJECTORY_SCENARIO)
    cfg = config or SimConfig(payload_kg=sc.payload_kg)
    n_ticks = round(duration_s / cfg.gains.ctrl_dt_s)
    if n_ticks < 1:
        raise InvalidParameterError(
            f"duration must cover at least one control tick, got {duration_s!r} s"
        )
    table = sc.reference(np.arange(n_ticks + 1, dtype=np.float64) * cfg.gains.ctrl_dt_s)
    pair = make_pair(cfg, table, TRAJECTORY_SCENARIO)
    if arm is not None:
        pair.arm = arm
    ref_dt = dts[-1] / 2.0
    reference = integrate_pinocchio(pair, n_ticks, ref_dt)
    qadr = pair.st.qadr
    rows: list[ConvergenceRow] = []
    for i, dt in enumerate(dts):
        mj = integrate_mujoco(cfg, table, n_ticks, dt, "RK4")
        zoh = integrate_pinocchio(pair, n_ticks, dt)
        e_mj, e_pin = _q_error(mj, reference, qadr), _q_error(zoh, reference, qadr)
        prev = rows[-1] if rows else None
        rows.append(
            ConvergenceRow(
                dt_s=dt,
                mujoco_vs_reference_rad=e_mj,
                pinocchio_vs_reference_rad=e_pin,
                mujoco_vs_pinocchio_same_dt_rad=_q_error(mj, zoh, qadr),
                order_mujoco=_order(prev.mujoco_vs_reference_rad, e_mj, dts[i - 1], dt)
                if prev
                else None,
                order_pinocchio=_order(prev.pinocchio_vs_reference_rad, e_pin, dts[i - 1], dt)
                if prev
                else None,
            )
        )
    euler = integrate_mujoco(cfg, table, n_ticks, cfg.gains.ctrl_dt_s, "Euler")
    return TrajectoryStudy(
        TRAJECTORY_SCENARIO,
        n_ticks * cfg.gains.ctrl_dt_s,
        ref_dt,
        tuple(rows),
        _q_error(euler, reference, qadr),
    )


def _orders(values: list[float | None]) -> float:
    real = [v for v in values if v is not None]
    return min(real) if real else float("nan")


def check_trajectory(study: TrajectoryStudy) -> list[CheckResult]:
    rows = study.rows
    same = max(r.mujoco_vs_pinocchio_same_dt_rad for r in rows)
    dts = ", ".join(f"{r.dt_s:g}" for r in rows)
    results = [
        CheckResult(
            "trajectory_same_dt",
            "trajectory, same dt: MuJoCo RK4 vs Pinocchio RK4 (both zero-order hold)",
            same,
            TOL_SAME_DT_RAD,
            "rad",
            f"{study.scenario}, {study.duration_s:g} s, dt = {dts} s; max |q_mj - q_pin|, q1-q3",
        ),
        CheckResult(
            "trajectory",
            "trajectory: MuJoCo RK4 vs converged zero-order-hold Pinocchio loop",
            rows[0].mujoco_vs_reference_rad,
            TOL_TRAJECTORY_RAD,
            "rad",
            f"at dt = {rows[0].dt_s:g} s; reference RK4 at {study.reference_dt_s:g} s",
        ),
    ]
    if len(rows) > 1:
        results += [
            CheckResult(
                "order_mujoco",
                "convergence order of MuJoCo RK4 toward the reference (at least)",
                _orders([r.order_mujoco for r in rows]),
                MIN_ORDER_MUJOCO,
                "-",
                "fourth order expected with a zero-order-hold controller",
                at_least=True,
            ),
            CheckResult(
                "order_reference",
                "convergence order of the Pinocchio RK4 reference (at least)",
                _orders([r.order_pinocchio for r in rows]),
                MIN_ORDER_REFERENCE,
                "-",
                "fourth order expected with a zero-order-hold controller",
                at_least=True,
            ),
        ]
    return results


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
