"""Plant-only arm effects (model.Effects: payload error, backlash, joint-3 friction/damping)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine.model import Effects, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.sim.simulation import Simulation, run_scenario

from conftest import hold_table, joint3_gravity_balance


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
    plant = build_model(SimConfig(payload_kg=base, effects=Effects(payload_error_kg=dm)), table)
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
        SimConfig(effects=Effects(payload_error_kg=5.0)),
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
    cfg = SimConfig(effects=Effects(backlash_width_rad=w, control=False))
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
        SimConfig(effects=Effects(backlash_width_rad=math.radians(3.0))),
        duration_s=4.0,
        backend="native",
    )
    assert play.metrics["rmse_deg"]["q3"] > base.metrics["rmse_deg"]["q3"]  # type: ignore[index]


def test_joint3_friction_and_damping_reach_mujoco() -> None:
    cfg = SimConfig(effects=Effects(q3_friction_nm=1.5, q3_damping_nms=0.7))
    m = build_model(cfg, hold_table(0.0, 0.5, 0.3))
    ref = build_model(SimConfig(), hold_table(0.0, 0.5, 0.3))
    st = read_structure(m)
    assert m.dof_frictionloss[st.dof[2]] - ref.dof_frictionloss[st.dof[2]] == pytest.approx(1.5)
    assert m.dof_damping[st.dof[2]] - ref.dof_damping[st.dof[2]] == pytest.approx(0.7)


@pytest.mark.parametrize(
    "fx",
    [
        Effects(payload_error_kg=math.nan),
        Effects(payload_error_kg=40.0),
        Effects(backlash_width_rad=-0.1),
        Effects(q3_friction_nm=math.inf),
        Effects(backlash_center_rad=1.0),
    ],
)
def test_bad_arm_effects_are_named_errors(fx: Effects) -> None:
    with pytest.raises(InvalidParameterError):
        build_model(SimConfig(effects=fx), hold_table(0.0, 0.5, 0.3))


def test_initial_state_unchanged_for_the_default_transmission() -> None:
    """The generalised start (static_twist) gives the eq. 8 twist tau / K exactly."""
    held, gravity = joint3_gravity_balance(build_model(SimConfig(), hold_table(0.0, 0.7, 0.5)))
    assert held == pytest.approx(gravity, rel=1e-12)
