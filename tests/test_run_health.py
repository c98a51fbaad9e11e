"""Long runs stay right to their last minute; a run that goes wrong ends with a named error.

The control clock (physics.control) counts physics steps: ``data.time`` alone drifts by rounding
(MuJoCo adds h to it every step), and a clock that compared it with multiples of the control
period froze the controllers after 334 s at 1 ms and after 5 s at 10 us (issue 17).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import (
    CallbackBypassError,
    InvalidParameterError,
    RunHealthError,
)
from fsarm_sim.kernels import layout, physics
from fsarm_sim.sim import run_memory, scenarios, simulation
from fsarm_sim.sim.simulation import Simulation, check_clock, run_scenario

HOUR_S = 3600.0
MINUTE_S = 60.0


def _fig14(seconds: float, cfg: SimConfig | None = None, backend: str = "native") -> Simulation:
    cfg = cfg or SimConfig()
    n = round(seconds / cfg.gains.ctrl_dt_s) + 1
    table = scenarios.get("fig14-sine").reference(np.arange(n) * cfg.gains.ctrl_dt_s)
    return Simulation(cfg, table, backend)  # type: ignore[arg-type]


def _rmse_deg(cols: dict[str, np.ndarray], joint: str, mask: np.ndarray) -> float:
    e = cols[joint][mask] - cols[f"{joint}_ref"][mask]
    return math.degrees(float(np.sqrt(np.mean(e * e))))


def test_data_time_drifts_but_the_clock_ticks_every_period() -> None:
    """Feed the kernel the times MuJoCo produces late in an hour at 10 us: exactly one tick per
    control period, although the summed time has left the old tolerance far behind."""
    h, per_tick = 1e-5, 100
    sim = _fig14(1.0, backend="python")
    d = sim.data
    prm = sim.params.copy()
    prm[layout.P_TIMESTEP] = h
    prm[layout.P_STEPS_PER_TICK] = per_tick
    prm[layout.P_CTRL_DT] = h * per_tick
    ref = sim.model.numeric(layout.REF_NAME).data.copy()
    ud = np.zeros(layout.N_USERDATA)
    ctrl = np.zeros(sim.model.nu)
    with callbacks.active("python"):
        mujoco.mj_forward(sim.model, d)  # bias and mass matrix of the start pose
    t = 3540.0
    ticks_started = []
    n_steps = 20_000
    for _ in range(n_steps):
        physics.control(prm, ref, t, d.qpos, d.qvel, d.act, d.qfrc_bias, d.M, ud, ctrl)
        ticks_started.append(ud[layout.U_TICK])
        t += h  # what mj_step does to data.time
    drift = t - (3540.0 + n_steps * h)
    assert abs(drift) > 1e-6 * per_tick * h  # the old rule's tolerance is long gone ...
    ticks = np.diff(np.array(ticks_started))
    assert ticks.sum() == n_steps / per_tick - 1  # ... yet one tick every 100 steps, no more
    assert set(np.flatnonzero(ticks) % per_tick) == {per_tick - 1}
    assert ud[layout.U_ACC + layout.A_COUNT] == n_steps  # and every step counted in the metrics


def test_an_hour_at_the_default_step_tracks_in_its_last_minute_as_in_its_first() -> None:
    sim = _fig14(HOUR_S)
    cols, _ = sim.run(HOUR_S, log_every_ticks=100)
    t = cols["t"]
    first, last = t < MINUTE_S, t >= HOUR_S - MINUTE_S
    second = (t >= MINUTE_S) & (t < 2 * MINUTE_S)  # after the shaft's slip elements settled
    for joint in ("q2", "q3"):
        rmse_first, rmse_last = _rmse_deg(cols, joint, first), _rmse_deg(cols, joint, last)
        assert rmse_last <= 1.05 * rmse_first + 1e-4, joint  # as well as the first, or better
        rmse_second = _rmse_deg(cols, joint, second)
        assert rmse_last == pytest.approx(rmse_second, rel=0.05, abs=1e-4), joint
    assert sim.step_index() == round(HOUR_S / 1e-3)
    assert sim.data.userdata[layout.U_TICK] == round(HOUR_S / 1e-3)
    assert math.degrees(sim.metrics()["rmse_rad"]["q3"]) < 0.5  # type: ignore[index]


def test_the_last_20_s_of_an_hour_at_10_us_track_as_its_first_20_s() -> None:
    """At 10 us the summed data.time is furthest off at the end of an hour: run its last 20 s
    (t0 = 3580 s, a whole number of fig14's 4 s periods, so the reference is the first 20 s's)
    beside its first 20 s (five periods each)."""
    window_s = 20.0
    cfg = SimConfig(timestep_s=1e-5, gains=Gains(ctrl_dt_s=1e-3))
    first = _fig14(window_s, cfg)
    cols_first, _ = first.run(window_s, log_every_ticks=10)
    late = _fig14(HOUR_S, cfg)
    late.start_at(HOUR_S - window_s)
    cols_last, _ = late.run(window_s, log_every_ticks=10)
    assert late.data.userdata[layout.U_TICK] == round(HOUR_S / 1e-3)
    for joint in ("q2", "q3"):
        a = _rmse_deg(cols_first, joint, np.ones(len(cols_first["t"]), bool))
        b = _rmse_deg(cols_last, joint, np.ones(len(cols_last["t"]), bool))
        assert b == pytest.approx(a, rel=0.02, abs=1e-5), joint
    np.testing.assert_allclose(cols_last["q3_ref"], cols_first["q3_ref"], atol=1e-9)


@pytest.mark.parametrize("log_every", [1, 7, 1000, 100_000])
def test_metrics_do_not_depend_on_logging(log_every: int) -> None:
    base = run_scenario("fig14-sine", duration_s=2.0, backend="native").metrics
    other = run_scenario(
        "fig14-sine", duration_s=2.0, backend="native", log_every_ticks=log_every
    ).metrics
    for key in ("rmse_rad", "max_abs_err_rad", "tau_estimate_rmse_nm", "motor_energy_j"):
        assert other[key] == base[key], key
    assert base["metric_samples"] == 2000


def test_kernel_metrics_equal_the_rows_when_every_step_is_logged() -> None:
    res = run_scenario("fig14-sine", duration_s=2.0, payload_kg=5.0)
    st = _fig14(0.1).structure
    from_rows = simulation.compute_metrics(res.columns, 2.0, 1.0, st)
    for key in ("rmse_rad", "max_abs_err_rad"):
        for j, v in res.metrics[key].items():  # type: ignore[union-attr]
            assert v == pytest.approx(from_rows[key][j], rel=1e-12), (key, j)  # type: ignore[index]
    assert res.metrics["peak_shaft_torque_nm"] == pytest.approx(
        from_rows["peak_shaft_torque_nm"], rel=1e-12
    )
    assert res.metrics["motor_energy_j"] == pytest.approx(from_rows["motor_energy_j"], rel=0.01)


def test_a_diverging_run_ends_with_the_time_the_joint_and_the_state() -> None:
    """Joint 3 without its position loop stays behind its 0-90 deg reference: a named error
    giving time, joint and state, not exit 0 with a huge RMSE."""
    cfg = SimConfig(gains=Gains(wn_rad_s=(20.0, 20.0, 0.0)))
    with pytest.raises(RunHealthError, match=r"t = [\d.]+ s: joint q3 is .* deg from") as info:
        run_scenario("fig14-sine", cfg, duration_s=5.0)
    assert len(info.value.columns["t"]) > 10  # what was recorded up to the failure is kept


def test_a_stopped_clock_is_reported() -> None:
    sim = _fig14(1.0, backend="python")
    sim.params[layout.P_STEPS_PER_TICK] = 1e9  # the controllers now never tick again
    sim.step(600)
    with pytest.raises(RunHealthError, match=r"controllers stopped at t = 0.6000"):
        sim.health()
    sim = _fig14(1.0, backend="python")
    sim.params[layout.P_EN_CONTROL] = 0.0
    sim.step(10)  # the clock is in the control kernel: it stands still
    sim.params[layout.P_EN_CONTROL] = 1.0
    with pytest.raises(RunHealthError, match="control clock stopped"):
        sim.health()


def test_stepping_outside_the_callbacks_is_caught() -> None:
    sim = _fig14(1.0, backend="python")
    sim.run(0.05)
    for _ in range(20):
        mujoco.mj_step(sim.model, sim.data)  # no callbacks: no shaft, no controllers
    with pytest.raises(CallbackBypassError, match="without fsarm's callbacks"):
        check_clock(sim.model, sim.data)
    with pytest.raises(CallbackBypassError):
        sim.run(0.05)
    with pytest.raises(CallbackBypassError):
        sim.step()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"duration_s": 1e-9}, "shorter than one control period"),
        ({"duration_s": 1.0, "config": SimConfig(gains=Gains(ctrl_dt_s=5.0))}, "one control"),
        ({"config": SimConfig(timestep_s=1e-9)}, "physics steps"),
        ({"config": SimConfig(gains=Gains(ctrl_dt_s=0.0))}, "ctrl_dt_s"),
        ({"config": SimConfig(gains=Gains(ctrl_dt_s=math.nan))}, "ctrl_dt_s"),
        ({"log_every_ticks": 0}, ">= 1"),
        ({"log_every_ticks": -1}, ">= 1"),
        ({"log_every_ticks": 2.5}, "whole number"),
    ],
)
def test_run_sizes_and_clocks_that_cannot_work_are_refused(
    kwargs: dict[str, object], match: str
) -> None:
    with pytest.raises(InvalidParameterError, match=match):
        run_scenario("fig14-sine", **kwargs)  # type: ignore[arg-type]


def test_a_run_that_would_not_fit_in_memory_is_refused_before_it_starts(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(run_memory, "available_memory_bytes", lambda: 64 << 20)
    with pytest.raises(InvalidParameterError, match="--log-every"):
        run_scenario("fig14-sine", duration_s=600.0)
    run_scenario("fig14-sine", duration_s=0.5)  # a small one still runs
