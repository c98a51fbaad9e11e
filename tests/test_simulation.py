"""Scenarios and the runner: every registered scenario runs; fig14-sine meets its target."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError, ScenarioNotFoundError, SimulationWarningError
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import Simulation, run_scenario


@pytest.mark.parametrize("name", sorted(scenarios.REGISTRY))
def test_every_scenario_runs(name: str) -> None:
    r = run_scenario(name, duration_s=1.0)
    for key, col in r.columns.items():
        assert np.all(np.isfinite(col)), key
    assert len(r.columns["t"]) == 1000
    assert r.metrics["rmse_rad"]["q3"] < 0.2  # type: ignore[index]


@pytest.mark.parametrize("payload", [0.0, 15.0])
def test_fig14_sine_tracks_within_one_degree(payload: float) -> None:
    r = run_scenario("fig14-sine", payload_kg=payload)
    rmse = r.metrics["rmse_deg"]
    assert isinstance(rmse, dict)
    assert rmse["q3"] <= 1.0
    # the reference really spans 0-90 deg at about the nominal speed
    assert np.ptp(r.columns["q3_ref"]) == pytest.approx(math.pi / 2, rel=1e-3)
    assert np.max(np.abs(r.columns["qd3_ref"])) == pytest.approx(math.radians(70.7), rel=0.01)
    # and the joint-2 pose bends the shaft
    assert np.all(np.abs(r.columns["phi_b"]) > 0.7)


def test_deterministic() -> None:
    a = run_scenario("p2p-payload", duration_s=1.5).columns
    b = run_scenario("p2p-payload", duration_s=1.5).columns
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


@pytest.mark.parametrize("bad", [math.nan, -1.0, 0.0, math.inf, 1e6])
def test_bad_duration(bad: float) -> None:
    with pytest.raises(InvalidParameterError, match="duration"):
        run_scenario("fig14-sine", duration_s=bad)


def test_unknown_scenario() -> None:
    with pytest.raises(ScenarioNotFoundError, match="fig14-sine"):
        run_scenario("fig15-sine")


def test_mujoco_warning_fails_the_run() -> None:
    """A bad state makes MuJoCo warn (and reset): the run must fail, not go on silently."""
    sim = Simulation(SimConfig(), scenarios.get("step-q3").reference(np.arange(0, 200) * 0.001))
    sim.data.qvel[0] = np.nan
    with pytest.raises(SimulationWarningError, match="mjWARN_BADQVEL"):
        sim.run(0.1)


def test_timestep_too_large_for_the_shaft() -> None:
    cfg = SimConfig(timestep_s=0.02)
    cfg = cfg.with_(gains=cfg.gains.__class__(ctrl_dt_s=0.02))
    with pytest.raises(InvalidParameterError, match="too large for the shaft"):
        Simulation(cfg, scenarios.get("step-q3").reference(np.arange(0, 200) * 0.02))


def test_logging_stride_and_no_logging() -> None:
    r = run_scenario("step-q3", duration_s=0.5, log_every_ticks=10)
    assert len(r.columns["t"]) == 50
    assert r.columns["t"][1] == pytest.approx(0.01)


def test_interrupted_run_keeps_finished_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C during a long run: the finished part is returned, marked as interrupted."""
    import mujoco

    from fsarm_sim.sim import simulation

    calls = {"n": 0}
    real_step = mujoco.mj_step

    def step(m, d, nstep=1):  # type: ignore[no-untyped-def]
        calls["n"] += 1
        if calls["n"] == 3:  # the run steps in chunks, recording in compiled code
            raise KeyboardInterrupt
        real_step(m, d, nstep=nstep)

    monkeypatch.setattr(simulation.mujoco, "mj_step", step)
    r = run_scenario("fig14-sine", duration_s=5.0)
    assert r.interrupted
    assert 0.1 < r.duration_s < 5.0
    # every finished step's row, none lost or repeated
    assert len(r.columns["t"]) == round(r.duration_s / 1e-3)
    assert np.allclose(r.columns["t"], np.arange(len(r.columns["t"])) * 1e-3, rtol=0, atol=1e-12)
    assert np.all(np.isfinite(r.columns["q3"]))
