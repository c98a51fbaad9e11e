"""Scenarios and the runner: every registered scenario runs; fig14-sine meets its target."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from fsarm_sim.engine import model as model_mod
from fsarm_sim.engine.model import SimConfig, build_model
from fsarm_sim.errors import (
    InvalidParameterError,
    RunHealthError,
    ScenarioNotFoundError,
    SimulationWarningError,
)
from fsarm_sim.kernels import layout
from fsarm_sim.plant.shaft import load_catalogue
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
    r = run_scenario("fig14-sine", duration_s=5.0, keep_partial=True)
    assert r.interrupted
    assert 0.1 < r.duration_s < 5.0
    # every finished step's row, none lost or repeated
    assert len(r.columns["t"]) == round(r.duration_s / 1e-3)
    assert np.allclose(r.columns["t"], np.arange(len(r.columns["t"])) * 1e-3, rtol=0, atol=1e-12)
    assert np.all(np.isfinite(r.columns["q3"]))


def test_interrupted_run_raises_unless_partial_is_wanted(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C in a run a study, sweep point or fit makes: KeyboardInterrupt, never a cut run's
    numbers passed off as a whole run's (a sweep would store them as a finished point)."""
    import mujoco

    from fsarm_sim.sim import simulation
    from fsarm_sim.studies import arm_metrics

    calls = {"n": 0}
    real_step = mujoco.mj_step

    def step(m, d, nstep=1):  # type: ignore[no-untyped-def]
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        real_step(m, d, nstep=nstep)

    monkeypatch.setattr(simulation.mujoco, "mj_step", step)
    with pytest.raises(KeyboardInterrupt):
        run_scenario("fig14-sine", duration_s=5.0)
    calls["n"] = 0
    with pytest.raises(KeyboardInterrupt):
        arm_metrics.tracking(SimConfig(), "fig14-sine", duration_s=5.0)
    calls["n"] = 0
    sim = Simulation(SimConfig(), _fig14_table(5.0))
    with pytest.raises(KeyboardInterrupt):
        sim.run(5.0)
    assert sim.data.userdata[layout.U_REC_STRIDE] == 0.0  # the recorder was switched off on the way


def _fig14_table(seconds: float) -> np.ndarray:
    n = round(seconds / 0.001) + 1
    return scenarios.get("fig14-sine").reference(np.arange(n, dtype=np.float64) * 0.001)


def _record(cfg: SimConfig, table: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray]:
    sim = Simulation(cfg, table, "native")
    cols, _ = sim.run(0.6)
    return cols, sim.data.userdata[: layout.N_USERDATA].copy()


def test_runs_in_a_row_equal_fresh_runs() -> None:
    """Simulations built one after another with different shafts and payloads (build_model keeps
    the compiled structure, issue 15) record exactly what each records when built first."""
    cat = load_catalogue()
    cfgs = [
        SimConfig(shaft=cat.shaft(6, 335)),
        SimConfig(shaft=cat.shaft(12, 535, series_hysteresis=True)),
        SimConfig(shaft=cat.shaft(6, 335), payload_kg=3.0),
        SimConfig(shaft=cat.shaft(6, 335)),
    ]
    table = _fig14_table(0.6)
    fresh = []
    for cfg in cfgs:
        model_mod.clear_model_cache()
        fresh.append(_record(cfg, table))
    model_mod.clear_model_cache()
    for cfg, (want_cols, want_ud) in zip(cfgs, fresh, strict=True):
        cols, ud = _record(cfg, table)
        assert cols.keys() == want_cols.keys()
        for key in cols:
            np.testing.assert_array_equal(cols[key], want_cols[key], err_msg=key)
        np.testing.assert_array_equal(ud, want_ud)
    assert not np.array_equal(fresh[0][0]["twist"], fresh[1][0]["twist"])  # they differ


def test_live_simulations_share_no_model() -> None:
    """Two Simulations of one configuration alive at once: stepping or writing one leaves the
    other as a fresh one."""
    table = _fig14_table(0.6)
    a = Simulation(SimConfig(), table, "native")
    b = Simulation(SimConfig(), table, "native")
    assert a.model is not b.model and a.data is not b.data
    a.run(0.3)
    a.params[layout.P_WN3] = 1.0
    a.model.dof_damping[:] = 9.0
    cols, _ = b.run(0.6)
    want, _ = _record(SimConfig(), table)
    for key in cols:
        np.testing.assert_array_equal(cols[key], want[key], err_msg=key)


def test_health_sees_the_state_and_the_model_it_has_now() -> None:
    """health() keeps views of the parameters and reference per model: a model put in place
    afterwards is the one checked; a non-finite state and a joint far from its reference are
    caught."""
    table = _fig14_table(0.6)
    sim = Simulation(SimConfig(), table, "native")
    sim.run(0.5)
    sim.health()
    far = table.copy()
    far[:, 2] += math.radians(50.0)  # joint 3's reference 50 deg away: a diverged run
    sim.model = build_model(SimConfig(), far, lean=True)
    with pytest.raises(RunHealthError, match=r"joint q3 is -5\d\.\d deg from its reference"):
        sim.health()
    sim = Simulation(SimConfig(), table, "native")
    sim.run(0.5)
    sim.data.qpos[sim.structure.qadr[1]] = math.nan
    with pytest.raises(RunHealthError, match=r"state is not finite \(q2\)"):
        sim.health()
    sim.data.qpos[sim.structure.qadr[1]] = 0.0
    sim.data.qvel[0] = math.inf
    with pytest.raises(RunHealthError, match=r"state is not finite \(rotor\)"):
        sim.health()


@pytest.mark.parametrize("name", sorted(scenarios.REGISTRY))
def test_scenario_table_is_the_reference_and_the_callers_own(name: str) -> None:
    """Scenario.table (kept per process) equals the reference function at the tick times, and
    each call hands out a writable copy that later calls do not see."""
    sc = scenarios.get(name)
    want = sc.reference(np.arange(500, dtype=np.float64) * 0.002)
    a = sc.table(500, 0.002)
    np.testing.assert_array_equal(a, want)
    a[:] = 1e9
    np.testing.assert_array_equal(sc.table(500, 0.002), want)
    assert sc.table(500, 0.002) is not sc.table(500, 0.002)


def test_scenario_table_of_an_impure_reference_is_computed_every_time() -> None:
    """A scenario registered with ``pure_reference=False`` (its reference draws new numbers per
    call) gets a fresh table at every call: nothing is kept."""
    draws = iter(range(1, 100))

    def noisy(t: np.ndarray) -> np.ndarray:
        return np.full((t.size, 9), float(next(draws)))

    sc = scenarios.Scenario("noisy", "test", 1.0, 0.0, noisy, pure_reference=False)
    first, second = sc.table(10, 0.001), sc.table(10, 0.001)
    assert first[0, 0] == 1.0 and second[0, 0] == 2.0
    pure = scenarios.Scenario("kept", "test", 1.0, 0.0, noisy)
    assert pure.table(10, 0.001)[0, 0] == pure.table(10, 0.001)[0, 0]


def _populate_works() -> bool:
    """Whether this machine maps pages in with madvise(MADV_POPULATE_WRITE) (Linux >= 5.14)."""
    from fsarm_sim.sim import run_memory as sim_mod

    madvise = sim_mod._madvise()
    if madvise is None:
        return False
    probe = np.empty(4 * sim_mod.PAGE_BYTES)
    start = -(-int(probe.ctypes.data) // sim_mod.PAGE_BYTES) * sim_mod.PAGE_BYTES
    return madvise(start, sim_mod.PAGE_BYTES, sim_mod.MADV_POPULATE_WRITE) == 0


def test_the_record_array_is_resident_before_the_run_writes_it() -> None:
    """resident_empty maps the array's whole pages in before anything writes them (mincore)."""
    import ctypes

    from fsarm_sim.sim import run_memory as sim_mod

    if not _populate_works():
        pytest.skip("no madvise(MADV_POPULATE_WRITE) here: the record stays lazily mapped")
    page = sim_mod.PAGE_BYTES
    # 40 MiB: above malloc's largest mmap threshold (32 MiB), so always freshly mapped memory
    a = sim_mod.resident_empty((146_000, 36))
    assert a.shape == (146_000, 36) and a.dtype == np.float64 and a.flags.writeable
    start = -(-int(a.ctypes.data) // page) * page
    n = (int(a.ctypes.data) + a.nbytes) // page * page - start
    vec = (ctypes.c_ubyte * (n // page))()
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mincore.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p)
    assert libc.mincore(start, n, vec) == 0, ctypes.get_errno()
    assert all(b & 1 for b in vec)


def test_the_resident_record_logs_the_same_values(monkeypatch: pytest.MonkeyPatch) -> None:
    """The record array only changes when its pages are mapped: the logged columns are the same
    to the last bit as with a plain np.empty record."""
    from fsarm_sim.sim import simulation as sim_mod

    a = run_scenario("fig14-sine", duration_s=3.0).columns
    monkeypatch.setattr(sim_mod, "resident_empty", np.empty)
    b = run_scenario("fig14-sine", duration_s=3.0).columns
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def test_tracking_at_the_scenarios_own_bend_matches_the_scenario_run() -> None:
    """A sweep point that sets the bend (joint 2 held there) and one that keeps the scenario's
    pose run the same motion, so their metrics must agree to the last bit: both from the
    control kernel's per-step accumulators (the bend path once sampled the recorded rows)."""
    from fsarm_sim.studies import arm_metrics

    q2 = float(_fig14_table(0.01)[0, 1])
    own = arm_metrics.tracking(SimConfig(), "fig14-sine", duration_s=2.0)
    held = arm_metrics.tracking(SimConfig(), "fig14-sine", duration_s=2.0, bend_rad=q2)
    assert held == own


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"duration_s": True}, "duration must be a finite number"),  # used to run 1 s
        ({"duration_s": 0.1, "payload_kg": True}, "payload_kg (--payload-kg) must be a number"),
        ({"duration_s": 0.1, "log_every_ticks": True}, "whole number"),
        ({"duration_s": 0.1, "log_every_ticks": 10**20}, "<= 360000000"),  # was OverflowError
        ({"duration_s": 0.1, "log_every_ticks": 0}, ">= 1"),
        ({"duration_s": "0.1"}, "duration must be a finite number"),
    ],
)
def test_booleans_and_huge_sizes_are_not_numbers_of_a_run(
    kwargs: dict[str, object], words: str
) -> None:
    """Issue 33: refused before the model is built."""
    with pytest.raises(InvalidParameterError) as info:
        run_scenario("fig14-sine", **kwargs)  # type: ignore[arg-type]
    assert words in str(info.value)


def test_booleans_are_not_numbers_of_a_config() -> None:
    from fsarm_sim.engine.model import Effects, Gains

    for cfg, words in (
        (SimConfig(payload_kg=True), "payload_kg must be a number"),  # type: ignore[arg-type]
        (SimConfig(timestep_s=True), "timestep_s must be a number"),  # type: ignore[arg-type]
        (SimConfig(gains=Gains(ctrl_dt_s=True)), "gain ctrl_dt_s must be a number"),  # type: ignore[arg-type]
        (
            SimConfig(effects=Effects(laws=(("coulomb_friction", (("f_c_nm", True),)),))),
            "coulomb_friction.f_c_nm must be a number",
        ),
    ):
        with pytest.raises(InvalidParameterError, match=re.escape(words)):
            cfg.validate()


def test_log_every_beyond_the_run_records_the_first_row_only() -> None:
    """The cap is the most steps a run may take: anything up to it is a correct run."""
    from fsarm_sim.sim.simulation import MAX_LOG_EVERY

    res = run_scenario("fig14-sine", duration_s=0.05, log_every_ticks=MAX_LOG_EVERY)
    assert len(res.columns["t"]) == 1
