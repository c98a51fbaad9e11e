"""The Pinocchio model is the same robot as MuJoCo's, read from the same MJCF by another parser."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig, build_model, build_spec, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import pinocchio_model as pm

TABLE = np.zeros((2, 9))
ODD_PAYLOAD_KG = 7.123456789  # more digits than MuJoCo's XML writer keeps


def _full_m(model: mujoco.MjModel, qpos: np.ndarray) -> np.ndarray:
    d = mujoco.MjData(model)
    d.qpos[:] = qpos
    with callbacks.suspended():
        mujoco.mj_forward(model, d)
    out = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, d, out)
    return out


def test_joints_are_mapped_by_name_to_mujoco_dofs() -> None:
    arm = pm.load_pinocchio_arm(SimConfig(), TABLE)
    mj = build_model(SimConfig(), TABLE)
    for name in pm.JOINT_NAMES:
        jid = arm.model.getJointId(name)
        mj_joint = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, name)
        assert arm.pin_v_index[arm.model.idx_vs[jid]] == mj.jnt_dofadr[mj_joint]
        assert arm.pin_q_index[arm.model.idx_qs[jid]] == mj.jnt_qposadr[mj_joint]


def test_payload_inertia_reaches_pinocchio_at_full_precision() -> None:
    """MuJoCo's XML writer rounds to 6 digits; run_mjcf restores the spec's doubles."""
    cfg = SimConfig(payload_kg=ODD_PAYLOAD_KG)
    q = np.array([0.3, -0.7, 1.1, 2.0])
    mj_m = _full_m(build_model(cfg, TABLE), q)
    arm = pm.load_pinocchio_arm(cfg, TABLE)
    assert np.max(np.abs(mj_m - pm.mass_matrix(arm, q))) < 1e-12
    with callbacks.suspended():
        rounded = pm.parse_mjcf(build_spec(cfg, TABLE).to_xml())
    crude = dataclasses.replace(arm, model=rounded, data=rounded.createData())
    assert np.max(np.abs(mj_m - pm.mass_matrix(crude, q))) > 1e-10  # why run_mjcf exists


def test_gravity_comes_from_the_spec_because_the_parser_ignores_option_gravity() -> None:
    arm = pm.load_pinocchio_arm(SimConfig(), TABLE)
    spec = build_spec(SimConfig(), TABLE)
    np.testing.assert_array_equal(arm.model.gravity.linear, spec.option.gravity)
    root = ET.fromstring(arm.mjcf)
    opt = root.find("option")
    assert opt is not None
    opt.set("gravity", "0 0 -3")
    parsed = pm.parse_mjcf(ET.tostring(root, encoding="unicode"))
    assert parsed.gravity.linear[2] == pytest.approx(-9.81)  # ignored: so we must set it


def test_shaft_inertia_is_lumped_half_at_each_end_in_both_engines() -> None:
    """eq. 1 J enters as armature J/2 (1/i_G1)^2 on the rotor and J/2 i_G2^2 on q3: both engines
    read it from the MJCF, and a rigidly spinning shaft carries kinetic energy J w^2 / 2."""
    j = 2.3e-6
    cfg = SimConfig(shaft=dataclasses.replace(load_catalogue().shaft(), inertia_kgm2=j))
    base, lumped = build_model(SimConfig(), TABLE), build_model(cfg, TABLE)
    st = read_structure(lumped)
    d_arm = lumped.dof_armature - base.dof_armature
    assert d_arm[st.dof[3]] == pytest.approx(0.5 * j / st.i_g1**2, rel=1e-12)
    assert d_arm[st.dof[2]] == pytest.approx(0.5 * j * st.i_g2**2, rel=1e-12)
    arm = pm.load_pinocchio_arm(cfg, TABLE)
    assert not arm.has_tendon_inertia
    q = np.array([0.1, 0.2, 0.3, 4.0])
    d = mujoco.MjData(lumped)
    d.qpos[:] = q
    mujoco.mj_forward(lumped, d)
    full = np.zeros((4, 4))
    mujoco.mj_fullM(lumped, d, full)
    np.testing.assert_allclose(pm.mass_matrix(arm, q), full, rtol=0, atol=1e-12)
    # rigid spin of the shaft (no twist): theta_m' = theta_s' = w
    w = 2.0
    v = np.zeros(4)
    v[st.dof[3]], v[st.dof[2]] = w * st.i_g1, w / st.i_g2
    extra = 0.5 * v @ (np.diag(d_arm) @ v)
    assert extra == pytest.approx(0.5 * j * w * w, rel=1e-12)


def test_aba_equals_crba_solve_in_both_code_paths() -> None:
    """ABA (no tendon inertia) and the CRBA solve must give the same accelerations."""
    arm = pm.load_pinocchio_arm(SimConfig(payload_kg=5.0), TABLE)
    rng = np.random.default_rng(7)
    for _ in range(10):
        q, v, tau = rng.uniform(-1, 1, 4), rng.uniform(-3, 3, 4), rng.uniform(-20, 20, 4)
        aba = pm.forward_dynamics(arm, q, v, tau)
        solve = np.linalg.solve(pm.mass_matrix(arm, q), tau - pm.bias(arm, q, v))
        np.testing.assert_allclose(aba, solve, rtol=1e-10, atol=1e-9)


def test_damping_follows_the_config_switch() -> None:
    on = pm.load_pinocchio_arm(SimConfig(), TABLE)
    off = pm.load_pinocchio_arm(SimConfig(joint_damping=False), TABLE)
    mj = build_model(SimConfig(), TABLE)
    np.testing.assert_array_equal(on.damping, mj.dof_damping)
    assert not off.damping.any()


@pytest.mark.parametrize("bad", [np.zeros(3), np.array([0.0, np.nan, 0.0, 0.0])])
def test_bad_state_vectors_raise_named_errors(bad: np.ndarray) -> None:
    arm = pm.load_pinocchio_arm(SimConfig(), TABLE)
    with pytest.raises(InvalidParameterError, match="length 4"):
        pm.bias(arm, bad, np.zeros(4))


def test_a_second_top_level_body_is_refused_not_silently_dropped() -> None:
    """Pinocchio's parser keeps only the first body under <worldbody> (toolchain.md)."""
    arm = pm.load_pinocchio_arm(SimConfig(), TABLE)
    root = ET.fromstring(arm.mjcf)
    world = root.find("worldbody")
    link1 = root.find(".//body[@name='link1']")
    rotor = root.find(".//body[@name='j3_rotor']")
    assert world is not None and link1 is not None and rotor is not None
    link1.remove(rotor)
    world.append(rotor)
    split = pm.parse_mjcf(ET.tostring(root, encoding="unicode"))
    assert split.nv == 3
    mj = pm.compile_spec(SimConfig(), TABLE)
    with pytest.raises(ModelStructureError, match="first body"):
        pm._joint_maps(split, mj)


def test_pinocchio_is_a_real_second_opinion() -> None:
    """Changing a link mass in Pinocchio alone changes its mass matrix (nothing is shared)."""
    arm = pm.load_pinocchio_arm(SimConfig(), TABLE)
    q = np.array([0.1, 0.5, -0.4, 0.0])
    before = pm.mass_matrix(arm, q)
    jid = arm.model.getJointId("q3")
    old = arm.model.inertias[jid]
    arm.model.inertias[jid] = pin.Inertia(old.mass * 1.01, old.lever, old.inertia)
    assert np.max(np.abs(pm.mass_matrix(arm, q) - before)) > 1e-4
