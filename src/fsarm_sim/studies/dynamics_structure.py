"""Seed 000 eq. 5-7 structure (S, B, M_R, K_SEA, K_PEA) measured on Pinocchio / MuJoCo vs the MJCF
(check 4).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from fsarm_sim.engine import callbacks
from fsarm_sim.errors import ModelStructureError
from fsarm_sim.kernels import layout
from fsarm_sim.sim.simulation import raise_on_warning
from fsarm_sim.studies import pinocchio_model as pm
from fsarm_sim.studies.dynamics_pointwise import CheckResult, FloatArray, Pair, random_state

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
    d.time = 0.5 * float(pair.params[layout.P_CTRL_DT])
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
