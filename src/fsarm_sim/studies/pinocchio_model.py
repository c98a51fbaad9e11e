"""Pinocchio model of the arm, built from the very MJCF MuJoCo compiles: the independent referee.

``load_pinocchio_arm(config, ref_table)`` writes ``model.build_spec(config, ref_table)`` to a
temporary MJCF file and parses it with ``pin.buildModelFromMJCF`` - the same geometry, masses,
payload and armatures, read by a second, independent parser and run through independent
algorithms (CRBA, RNEA, ABA). Nothing is copied from the compiled MuJoCo model.

What Pinocchio's MJCF parser does not read, and how it is added here (each from the same spec):

* fixed tendons: any ``tendon_armature`` an MJCF gives is added to the mass matrix as
  ``J a a^T``, ``a`` the tendon's joint coefficients (toolchain.md: tendons are not read). The
  eq. 1 shaft inertia J is *not* a tendon armature: ``model.build_spec`` lumps it into the
  armature of the rotor and q3, which Pinocchio reads;
* ``<option gravity>``: set from the spec (Pinocchio keeps its own default otherwise);
* joint damping *is* parsed (``model.damping``) but no Pinocchio algorithm applies it: callers
  subtract ``damping * v`` themselves (zero when ``SimConfig.joint_damping`` is off);
* fsarm's callback forces (shaft torques, bending moments): callers add them as generalized forces.

MuJoCo's XML writer prints numbers with 6 significant digits, so a computed value such as the
payload inertia ``m (3 r^2 + h^2) / 12`` would reach Pinocchio rounded (an error of ~3e-9 kg m^2
in the mass matrix). :func:`run_mjcf` therefore rewrites every ``<inertial>`` and the joints'
``armature``/``damping`` with the spec's own doubles at full precision (still one source of
numbers: the spec).

All vectors and matrices this module returns are in MuJoCo's dof order; joints are mapped by name.
"""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig, build_spec
from fsarm_sim.errors import InvalidParameterError, ModelStructureError

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

JOINT_NAMES = ("q1", "q2", "q3", "j3_rotor")  # MuJoCo DOF order of the arm (fsarm.xml)


@dataclass(frozen=True)
class PinocchioArm:
    """A Pinocchio model of the arm plus what Pinocchio does not read, in MuJoCo's dof order."""

    model: pin.Model
    data: pin.Data
    pin_q_index: IntArray  # q_pin = qpos[pin_q_index]
    pin_v_index: IntArray  # v_pin = qvel[pin_v_index]; mj_vec[pin_v_index] = pin_vec
    tendon_inertia: FloatArray  # sum over fixed tendons of armature * a a^T (nv x nv)
    damping: FloatArray  # viscous joint damping per dof, N*m*s/rad (0 if switched off)
    mjcf: str  # the MJCF text Pinocchio parsed

    @property
    def nv(self) -> int:
        return int(self.model.nv)

    @property
    def has_tendon_inertia(self) -> bool:
        return bool(self.tendon_inertia.any())


def _fmt(values: object) -> str:
    """Numbers at full (round-trip) precision, space separated."""
    return " ".join(repr(float(x)) for x in np.atleast_1d(np.asarray(values, dtype=np.float64)))


def run_mjcf(spec: mujoco.MjSpec) -> str:
    """``spec.to_xml()`` with inertials and joint armature/damping at full precision."""
    with callbacks.suspended():  # to_xml compiles the spec; callbacks must not see it half-built
        root = ET.fromstring(spec.to_xml())
    for el in root.iter("body"):
        name = el.get("name")
        inertial = el.find("inertial")
        if name is None or inertial is None:
            continue
        body = spec.body(name)
        inertial.set("mass", _fmt(body.mass))
        inertial.set("pos", _fmt(body.ipos))
        if "quat" in inertial.attrib:
            inertial.set("quat", _fmt(body.iquat))
        if "diaginertia" in inertial.attrib:
            inertial.set("diaginertia", _fmt(body.inertia))
        if "fullinertia" in inertial.attrib:
            inertial.set("fullinertia", _fmt(body.fullinertia))
    for el in root.iter("joint"):
        name = el.get("name")
        if name is None or el.get("joint") is not None:
            continue  # tendon/actuator references also use the tag name "joint"
        joint = spec.joint(name)
        if joint is None:
            continue
        if "armature" in el.attrib:
            el.set("armature", _fmt(joint.armature))
        if "damping" in el.attrib:
            el.set("damping", _fmt(joint.damping[0]))
    return ET.tostring(root, encoding="unicode")


def parse_mjcf(text: str) -> pin.Model:
    """Pinocchio model of an MJCF text (the parser needs a file)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fsarm_run.xml"
        path.write_text(text)
        return pin.buildModelFromMJCF(str(path))


def compile_spec(config: SimConfig, ref_table: FloatArray) -> mujoco.MjModel:
    """MuJoCo compile of the same spec, used only for names, tendon coefficients and nq/nv."""
    with callbacks.suspended():
        return build_spec(config, np.ascontiguousarray(ref_table, dtype=np.float64)).compile()


def _joint_maps(pm: pin.Model, mj: mujoco.MjModel) -> tuple[IntArray, IntArray]:
    """Index arrays mapping MuJoCo qpos/qvel to Pinocchio q/v, joints matched by name."""
    if pm.nq != mj.nq or pm.nv != mj.nv:
        raise ModelStructureError(
            f"Pinocchio parsed nq={pm.nq}, nv={pm.nv} but MuJoCo compiled nq={mj.nq}, nv={mj.nv}: "
            "Pinocchio's MJCF parser reads only the first body under <worldbody>; keep the whole "
            "robot under one root body (toolchain.md)"
        )
    q_index = np.full(pm.nq, -1, dtype=np.int64)
    v_index = np.full(pm.nv, -1, dtype=np.int64)
    for name in JOINT_NAMES:
        jid = pm.getJointId(name)
        mj_id = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid >= pm.njoints or mj_id < 0:
            raise ModelStructureError(f"joint '{name}' is missing in the Pinocchio or MuJoCo model")
        if pm.joints[jid].nq != 1 or pm.joints[jid].nv != 1:
            raise ModelStructureError(f"joint '{name}' must be a 1-DOF hinge in Pinocchio")
        q_index[pm.idx_qs[jid]] = int(mj.jnt_qposadr[mj_id])
        v_index[pm.idx_vs[jid]] = int(mj.jnt_dofadr[mj_id])
    if np.any(q_index < 0) or np.any(v_index < 0):
        raise ModelStructureError(
            f"the arm must have exactly the joints {JOINT_NAMES}; Pinocchio has {list(pm.names)[1:]}"
        )
    return q_index, v_index


def tendon_inertia_matrix(mj: mujoco.MjModel, config: SimConfig) -> FloatArray:
    """``sum_t armature_t a_t a_t^T`` over the fixed tendons, as ``model.build_model`` sets them.

    ``build_model`` overwrites the armature of ``shaft_twist`` with the shaft's eq. 1 inertia J;
    any other tendon keeps the armature its MJCF gives.
    """
    arm = np.array(mj.tendon_armature, dtype=np.float64)
    out = np.zeros((mj.nv, mj.nv))
    for t in range(mj.ntendon):
        if arm[t] == 0.0:
            continue
        a = np.zeros(mj.nv)
        for w in range(int(mj.tendon_adr[t]), int(mj.tendon_adr[t] + mj.tendon_num[t])):
            if mj.wrap_type[w] != mujoco.mjtWrap.mjWRAP_JOINT:
                raise ModelStructureError("only fixed tendons may carry armature in fsarm models")
            a[int(mj.jnt_dofadr[mj.wrap_objid[w]])] += float(mj.wrap_prm[w])
        out += arm[t] * np.outer(a, a)
    return out


def load_pinocchio_arm(config: SimConfig, ref_table: FloatArray) -> PinocchioArm:
    """Build the Pinocchio model of one run from the run's MJCF (see module docstring)."""
    config.validate()
    spec = build_spec(config, np.ascontiguousarray(ref_table, dtype=np.float64))
    text = run_mjcf(spec)
    pm = parse_mjcf(text)
    pm.gravity = pin.Motion(np.array(spec.option.gravity, dtype=np.float64), np.zeros(3))
    mj = compile_spec(config, ref_table)
    q_index, v_index = _joint_maps(pm, mj)
    damping = np.zeros(mj.nv)
    if config.joint_damping:
        damping[v_index] = np.array(pm.damping, dtype=np.float64)
    return PinocchioArm(
        model=pm,
        data=pm.createData(),
        pin_q_index=q_index,
        pin_v_index=v_index,
        tendon_inertia=tendon_inertia_matrix(mj, config),
        damping=damping,
        mjcf=text,
    )


def _check_vector(x: FloatArray, size: int, what: str) -> FloatArray:
    v = np.asarray(x, dtype=np.float64)
    if v.shape != (size,) or not np.isfinite(v).all():
        raise InvalidParameterError(
            f"{what} must be a finite vector of length {size} (MuJoCo order), got shape {v.shape}"
        )
    return v


def to_pin_q(arm: PinocchioArm, qpos: FloatArray) -> FloatArray:
    return _check_vector(qpos, arm.model.nq, "qpos")[arm.pin_q_index].copy()


def to_pin_v(arm: PinocchioArm, vec: FloatArray) -> FloatArray:
    return _check_vector(vec, arm.nv, "dof vector")[arm.pin_v_index].copy()


def from_pin_v(arm: PinocchioArm, vec: FloatArray) -> FloatArray:
    out = np.empty(arm.nv)
    out[arm.pin_v_index] = vec
    return out


def from_pin_matrix(arm: PinocchioArm, mat: FloatArray) -> FloatArray:
    out = np.empty((arm.nv, arm.nv))
    idx = arm.pin_v_index
    out[np.ix_(idx, idx)] = mat
    return out


def rigid_mass_matrix(arm: PinocchioArm, qpos: FloatArray) -> FloatArray:
    """CRBA mass matrix of the bodies + joint armature (no tendon inertia), full and symmetric."""
    upper = pin.crba(arm.model, arm.data, to_pin_q(arm, qpos))
    full = np.triu(upper) + np.triu(upper, 1).T  # pin.crba fills the upper triangle only
    return from_pin_matrix(arm, full)


def mass_matrix(arm: PinocchioArm, qpos: FloatArray) -> FloatArray:
    """Joint-space inertia incl. the eq. 1 shaft inertia J a a^T (what MuJoCo's qM holds)."""
    return rigid_mass_matrix(arm, qpos) + arm.tendon_inertia


def bias(arm: PinocchioArm, qpos: FloatArray, qvel: FloatArray) -> FloatArray:
    """Gravity + Coriolis/centrifugal: RNEA at zero acceleration (MuJoCo's qfrc_bias)."""
    tau = pin.rnea(arm.model, arm.data, to_pin_q(arm, qpos), to_pin_v(arm, qvel), np.zeros(arm.nv))
    return from_pin_v(arm, tau)


def forward_dynamics(
    arm: PinocchioArm, qpos: FloatArray, qvel: FloatArray, tau: FloatArray
) -> FloatArray:
    """Joint accelerations for generalized forces ``tau`` (everything except bias and inertia).

    ABA when no tendon carries inertia; otherwise ABA cannot represent the off-diagonal
    ``J a a^T`` coupling and the CRBA matrix plus it is solved against ``tau - RNEA(q, v, 0)``.
    """
    if not arm.has_tendon_inertia:
        acc = pin.aba(
            arm.model,
            arm.data,
            to_pin_q(arm, qpos),
            to_pin_v(arm, qvel),
            to_pin_v(arm, tau),
        )
        return from_pin_v(arm, acc)
    rhs = _check_vector(tau, arm.nv, "tau") - bias(arm, qpos, qvel)
    return np.asarray(np.linalg.solve(mass_matrix(arm, qpos), rhs), dtype=np.float64)
