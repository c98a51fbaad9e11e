"""Plant-only arm effects that are registry laws acting on the arm in their own ways: the payload
error (torques), the backlash (the transmitted twist), joint-3 friction and damping (MuJoCo model
writes); and older records' keys for them mapped onto the laws."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine.model import Effects, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant.effects import registry
from fsarm_sim.sim.simulation import Simulation, run_scenario

from conftest import hold_table, joint3_gravity_balance


def _fx(*texts: str, control: bool = True) -> Effects:
    """Effects with the laws of ``fsarm run --effect`` texts switched on."""
    return Effects(control=control, laws=registry.parse_laws(list(texts)))


def _gravity_bias(m: mujoco.MjModel, q: np.ndarray) -> np.ndarray:
    d = mujoco.MjData(m)
    st = read_structure(m)
    for j in range(3):
        d.qpos[st.qadr[j]] = q[j]
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_rne(m, d, 0, d.qfrc_bias)
    return np.array([d.qfrc_bias[st.dof[j]] for j in range(3)])


@pytest.mark.parametrize("dm", [2.0, -1.5])
def test_payload_error_equals_mujoco_gravity_of_that_mass(dm: float) -> None:
    """The kernel's extra gravity torque = MuJoCo's for a model that really carries dm more."""
    table = hold_table(0.0, 0.5, 0.3)
    base = 3.0
    plant = build_model(SimConfig(payload_kg=base, effects=_fx(f"payload_error={dm}")), table)
    heavier = build_model(SimConfig(payload_kg=base + dm), table)
    lighter = build_model(SimConfig(payload_kg=base), table)
    st = read_structure(plant)
    prm = plant.numeric(layout.PARAMS_NAME).data
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, 3)
        d = mujoco.MjData(plant)
        for j in range(3):
            d.qpos[st.qadr[j]] = q[j]
        d.qpos[st.qadr[3]] = d.qpos[st.qadr[2]] * st.coef_s / st.coef_m
        qfrc = np.zeros(plant.nv)
        physics.passive_forces(prm, d.qpos, d.qvel, d.act, qfrc, np.zeros(layout.N_USERDATA))
        bending, _ = physics.bending_torques(prm, d.qpos, d.qvel, d.act)
        expected = -(_gravity_bias(heavier, q) - _gravity_bias(lighter, q))
        got = np.array([0.0, qfrc[st.dof[1]] - bending, qfrc[st.dof[2]]])
        assert np.allclose(got, expected, atol=1e-9, rtol=1e-9)


def test_payload_error_is_unknown_to_the_controller() -> None:
    """A hidden payload error makes joint 3 track worse; the stated payload does not."""
    base = run_scenario("fig14-sine", duration_s=3.0, backend="native")
    hidden = run_scenario(
        "fig14-sine",
        SimConfig(effects=_fx("payload_error=5")),
        duration_s=3.0,
        backend="native",
    )
    stated = run_scenario("fig14-sine", duration_s=3.0, payload_kg=5.0, backend="native")
    e = {k: r.metrics["rmse_deg"]["q3"] for k, r in (("b", base), ("h", hidden), ("s", stated))}  # type: ignore[index]
    assert e["h"] > 2.0 * e["b"]
    assert e["s"] < e["h"]


def test_backlash_start_is_static_equilibrium_and_costs_tracking() -> None:
    """With play, the start takes it up on the loaded flank: the arm holds still at t = 0."""
    w = math.radians(2.0)
    cfg = SimConfig(effects=_fx(f"backlash={w}", control=False))
    sim = Simulation(cfg, hold_table(0.0, 0.8, 0.6))
    st = sim.structure
    mujoco.mj_forward(sim.model, sim.data)
    with_play = physics.shaft_torque(sim.params, sim.data.qpos, sim.data.qvel, sim.data.act)
    nominal = Simulation(SimConfig(effects=Effects(control=False)), hold_table(0.0, 0.8, 0.6))
    without = physics.shaft_torque(
        nominal.params, nominal.data.qpos, nominal.data.qvel, nominal.data.act
    )
    assert with_play == pytest.approx(without, rel=1e-9)
    twist_gap = (sim.data.qpos[st.qadr[3]] - nominal.data.qpos[st.qadr[3]]) * st.coef_m
    assert abs(twist_gap) == pytest.approx(w / 2, rel=1e-9)
    base = run_scenario("fig14-sine", duration_s=4.0, backend="native")
    play = run_scenario(
        "fig14-sine",
        SimConfig(effects=_fx(f"backlash={math.radians(3.0)}")),
        duration_s=4.0,
        backend="native",
    )
    assert play.metrics["rmse_deg"]["q3"] > base.metrics["rmse_deg"]["q3"]  # type: ignore[index]


def test_joint3_friction_and_damping_reach_mujoco() -> None:
    """The two laws MuJoCo applies itself: their values land in q3's dof fields, nowhere else."""
    cfg = SimConfig(effects=_fx("coulomb_friction=1.5", "viscous_damping=0.7"))
    m = build_model(cfg, hold_table(0.0, 0.5, 0.3))
    ref = build_model(SimConfig(), hold_table(0.0, 0.5, 0.3))
    st = read_structure(m)
    assert m.dof_frictionloss[st.dof[2]] - ref.dof_frictionloss[st.dof[2]] == pytest.approx(1.5)
    assert m.dof_damping[st.dof[2]] - ref.dof_damping[st.dof[2]] == pytest.approx(0.7)
    others = [i for i in range(m.nv) if i != st.dof[2]]
    assert np.array_equal(m.dof_frictionloss[others], ref.dof_frictionloss[others])
    assert np.array_equal(m.dof_damping[others], ref.dof_damping[others])


@pytest.mark.parametrize(
    "fx",
    [
        _fx("payload_error=nan"),
        _fx("payload_error=40"),
        _fx("backlash=-0.1"),
        _fx("coulomb_friction=inf"),
        _fx("backlash=0.01,1.0"),
        _fx("viscous_damping=-1"),
    ],
)
def test_bad_arm_effects_are_named_errors(fx: Effects) -> None:
    with pytest.raises(InvalidParameterError):
        build_model(SimConfig(effects=fx), hold_table(0.0, 0.5, 0.3))


def test_initial_state_unchanged_for_the_default_transmission() -> None:
    """The generalised start (static_twist) gives the eq. 8 twist tau / K exactly."""
    held, gravity = joint3_gravity_balance(build_model(SimConfig(), hold_table(0.0, 0.7, 0.5)))
    assert held == pytest.approx(gravity, rel=1e-12)


# ------------------------------------------------------------------ older records' keys


def test_older_records_keys_are_the_laws() -> None:
    """An ``effects`` entry with the keys older records wrote switches the same laws on, with
    the same values; a size of 0 leaves its law off (as it acted then)."""
    old = {
        "series": True,
        "control": False,
        "payload_error_kg": 0.5,
        "backlash_width_rad": 0.01,
        "backlash_center_rad": 0.002,
        "q3_friction_nm": 0.0,
        "q3_damping_nms": 0.3,
    }
    fx = Effects.from_entry(old)
    assert fx.control is False
    assert dict(fx.laws) == {
        "payload_error": (("dm_kg", 0.5),),
        "backlash": (("width_rad", 0.01), ("center_rad", 0.002)),
        "viscous_damping": (("b_nms", 0.3),),
    }
    # a centre without a width was no play then, and is none now
    assert Effects.from_entry({"backlash_width_rad": 0.0, "backlash_center_rad": 0.1}).laws == ()
    # the written form reads back as it was; a law given both ways is given twice
    assert Effects.from_entry({"laws": {"backlash": {"width_rad": 0.01}}}).laws == (
        ("backlash", (("width_rad", 0.01),)),
    )
    with pytest.raises(InvalidParameterError, match="given twice"):
        Effects.from_entry({"payload_error_kg": 1.0, "laws": {"payload_error": {"dm_kg": 1.0}}})
    with pytest.raises(InvalidParameterError, match=r"effects\.q3_friction_nm must be a number"):
        Effects.from_entry({"q3_friction_nm": "0.5"})
    with pytest.raises(InvalidParameterError, match=r"unknown key effects\.'spring'"):
        Effects.from_entry({"spring": 1.0})
