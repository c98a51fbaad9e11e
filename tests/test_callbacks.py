"""Callbacks: process-global, yet per-model; controller state survives extra callback calls."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from fsarm_sim import callbacks, scenarios
from fsarm_sim.model import Gains, SimConfig
from fsarm_sim.shaft import load_catalogue
from fsarm_sim.simulation import Simulation

PENDULUM = """<mujoco><option timestep="0.002"/><worldbody><body><joint name="j" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body></worldbody>
<actuator><general name="a" joint="j" dyntype="user" gainprm="1"/></actuator></mujoco>"""


def _sim(config: SimConfig | None = None, seconds: float = 1.0) -> Simulation:
    cfg = config or SimConfig(shaft=load_catalogue().shaft(series_hysteresis=True))
    sc = scenarios.get("fig14-sine")
    n = round(seconds / cfg.gains.ctrl_dt_s) + 1
    return Simulation(cfg, sc.reference(np.arange(n) * cfg.gains.ctrl_dt_s))


def _trajectory(sim: Simulation, steps: int, between=None) -> np.ndarray:  # type: ignore[no-untyped-def]
    out = []
    for _ in range(steps):
        if between is not None:
            between(sim)
        sim.step()
        out.append(np.concatenate([sim.data.qpos, sim.data.qvel, sim.data.act]))
    return np.array(out)


def test_extra_forward_and_finite_differencing_do_not_disturb_controllers() -> None:
    base = _trajectory(_sim(), 400)

    def extra_forward(sim: Simulation) -> None:
        mujoco.mj_forward(sim.model, sim.data)
        mujoco.mj_forward(sim.model, sim.data)

    def finite_diff(sim: Simulation) -> None:
        nx = 2 * sim.model.nv + sim.model.na
        a = np.zeros((nx, nx))
        mujoco.mjd_transitionFD(sim.model, sim.data, 1e-6, True, a, None, None, None)

    np.testing.assert_array_equal(_trajectory(_sim(), 400, extra_forward), base)
    np.testing.assert_array_equal(_trajectory(_sim(), 400, finite_diff), base)


def test_rk4_runs_and_agrees_with_euler_at_small_step() -> None:
    """RK4 calls the control callback four times per step; ticks still happen once per period."""
    trajectories = []
    for integrator in ("RK4", "Euler"):
        cfg = SimConfig(integrator=integrator, timestep_s=2.5e-4, gains=Gains(ctrl_dt_s=1e-3))
        sim = _sim(cfg)
        sim.run(1.0)
        trajectories.append(sim.data.qpos.copy())
    assert np.allclose(trajectories[0][:3], trajectories[1][:3], atol=2e-4)


def test_two_models_in_one_process_do_not_mix() -> None:
    a = _sim(SimConfig(shaft=load_catalogue().shaft(9.0, 450.0)))
    b = _sim(SimConfig(shaft=load_catalogue().shaft(5.0, 300.0)))
    a_alone = _trajectory(_sim(SimConfig(shaft=load_catalogue().shaft(9.0, 450.0))), 300)
    interleaved = []
    for _ in range(300):
        a.step()
        b.step()
        interleaved.append(np.concatenate([a.data.qpos, a.data.qvel, a.data.act]))
    np.testing.assert_array_equal(np.array(interleaved), a_alone)
    assert not np.allclose(a.data.qpos, b.data.qpos)


def test_foreign_models_are_left_alone() -> None:
    m = mujoco.MjModel.from_xml_string(PENDULUM)
    d = mujoco.MjData(m)
    d.qpos[0] = 0.5
    with callbacks.active("python"):
        for _ in range(100):
            mujoco.mj_step(m, d)
    with callbacks.suspended():
        d2 = mujoco.MjData(m)
        d2.qpos[0] = 0.5
        for _ in range(100):
            mujoco.mj_step(m, d2)
    np.testing.assert_array_equal(d.qpos, d2.qpos)
    assert d.act[0] == pytest.approx(0.0)


def test_callbacks_only_while_active() -> None:
    """Python callbacks must not stay installed: with them, mujoco 3.17 cannot compile models."""
    _sim().run(0.01)
    assert mujoco.get_mjcb_control() is None
    assert mujoco.get_mjcb_passive() is None
    mujoco.MjModel.from_xml_string(PENDULUM)  # compiling other models still works
    callbacks.install_python()
    assert mujoco.get_mjcb_control() is not None
    callbacks.uninstall()
    assert mujoco.get_mjcb_control() is None
