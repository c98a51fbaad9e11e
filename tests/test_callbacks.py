"""Callbacks: process-global, yet per-model; controller state survives extra callback calls."""

from __future__ import annotations

import threading

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import CallbackConflictError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import Simulation

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


def test_runs_in_threads_share_the_callbacks_and_match_a_run_alone() -> None:
    """Two runs stepping at once in two threads: each as if alone, callbacks restored after."""
    from fsarm_sim.sim.simulation import run_scenario

    alone = run_scenario("fig14-sine", duration_s=1.0).metrics["rmse_rad"]
    results: dict[int, object] = {}

    def work(i: int) -> None:
        try:
            results[i] = run_scenario("fig14-sine", duration_s=1.0).metrics["rmse_rad"]
        except Exception as exc:  # reported below, with the thread's own error
            results[i] = exc

    for _ in range(3):
        threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert results == {0: alone, 1: alone}
    assert mujoco.get_mjcb_control() is None and mujoco.get_mjcb_passive() is None
    mujoco.MjModel.from_xml_string(PENDULUM)  # no callback left behind


def test_building_a_model_waits_for_a_python_run_in_another_thread() -> None:
    """Compiling suspends the callbacks; it must not switch off another thread's run."""
    from fsarm_sim.sim.simulation import run_scenario

    alone = run_scenario("fig14-sine", duration_s=1.5).metrics["rmse_rad"]
    out: dict[str, object] = {}

    def run() -> None:
        out["run"] = run_scenario("fig14-sine", duration_s=1.5).metrics["rmse_rad"]

    t = threading.Thread(target=run)
    t.start()
    for _ in range(3):
        _sim(seconds=0.1)  # builds (compiles) a model while the other thread steps
    t.join()
    assert out["run"] == alone


def test_the_other_backend_in_another_thread_is_refused_by_name() -> None:
    errors: list[BaseException] = []

    def other() -> None:
        try:
            with callbacks.active("native"):
                pass
        except BaseException as exc:
            errors.append(exc)

    with callbacks.active("python"):
        t = threading.Thread(target=other)
        t.start()
        t.join()
    assert len(errors) == 1 and isinstance(errors[0], CallbackConflictError)
    assert "python" in str(errors[0])


def test_a_users_own_callback_is_chained_for_other_models() -> None:
    m = mujoco.MjModel.from_xml_string(PENDULUM)
    d = mujoco.MjData(m)
    calls: list[float] = []

    def mine(model: mujoco.MjModel, data: mujoco.MjData) -> None:
        calls.append(data.time)
        data.qfrc_passive[0] += 0.0

    mujoco.set_mjcb_passive(mine)
    try:
        with callbacks.active("python"):
            mujoco.mj_step(m, d)
            mujoco.mj_step(m, d)
        assert len(calls) == 2  # passed on for the foreign model
        assert mujoco.get_mjcb_passive() is mine  # and back after the block
        with callbacks.active("native"):  # cannot chain it: the Python path runs instead
            mujoco.mj_step(m, d)
        assert len(calls) == 3
        assert mujoco.get_mjcb_passive() is mine
    finally:
        mujoco.set_mjcb_passive(None)


def test_native_default_falls_back_to_the_python_path_with_a_message(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Where the compiled callbacks cannot be built, a run says so once and runs the reference
    path - the same physics - instead of crashing."""
    import importlib

    real = importlib.import_module

    def no_native(name: str, *args, **kwargs):  # type: ignore[no-untyped-def]
        if name == "fsarm_sim.engine.native":
            raise ImportError("no compiler here")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(callbacks.importlib, "import_module", no_native)
    monkeypatch.setattr(callbacks, "_native_failure", [])
    monkeypatch.setattr(callbacks, "_native", [])  # nothing loaded yet in this "process"
    monkeypatch.setenv("FSARM_PREBUILT", "0")  # and no prebuilt library either
    assert callbacks.DEFAULT_BACKEND == "native"
    base = _trajectory(_sim(), 50)
    sim = _sim()
    sim.backend = "native"
    assert np.array_equal(_trajectory(sim, 50), base)
    err = capsys.readouterr().err
    assert err.count("native (compiled) callbacks are not available") == 1
    assert "no compiler here" in err
