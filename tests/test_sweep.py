"""Sweep specs (parsing, validation before any work), points, per-point metrics, resume, analysis."""

from __future__ import annotations

import math
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.executors import ExecutorError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.records.store import ResultStore, point_key
from fsarm_sim.studies import arm_metrics, sweep_analysis
from fsarm_sim.studies import sweep as sw

from conftest import run_fsarm

# ---------------------------------------------------------------------------------------------
# parsing


def test_value_syntaxes() -> None:
    info = sw.fields()["diameter_mm"]
    assert sw.parse_values(info, "4:13:4") == (4.0, 7.0, 10.0, 13.0)
    assert sw.parse_values(info, "235, 335,535") == (235.0, 335.0, 535.0)
    assert sw.parse_values(info, "9") == (9.0,)
    assert sw.parse_values(info, [4, 6.5]) == (4.0, 6.5)
    assert sw.parse_values(info, {"start": 4, "stop": 13, "num": 4}) == (4.0, 7.0, 10.0, 13.0)
    assert sw.parse_values(sw.fields()["scenario"], "fig14-sine,step-q3") == (
        "fig14-sine",
        "step-q3",
    )
    assert sw.parse_values(sw.fields()["gains.speed_ff"], "true,false") == (True, False)


@pytest.mark.parametrize(
    ("grid", "match"),
    [
        ("diameter_mm=", "no values"),
        ("diameter_mm=4:13:0", "whole number >= 1"),
        ("diameter_mm=13:4:3", "reversed range"),
        ("diameter_mm=4:4:3", "empty range"),
        ("diameter_mm=4:13:2.5", "whole number"),
        ("diameter_mm=4:13", "start:stop:count"),
        ("diameter_mm=nan", "not a finite number"),
        ("diameter_mm=4:nan:3", "not a finite number"),
        ("diameter_mm=4,,5", "empty item"),
        ("diameter_mm=4,4", "repeated"),
        ("diameter_mm=3,9", "outside the validity range"),
        ("length_mm=100", "outside the validity range"),
        ("stiffness=1,2", "unknown sweep field"),
        ("bend_deg=0,130", "outside the validity range"),
        ("payload_kg=0,20", "above its maximum"),
        ("scenario=fig14-sine,moonwalk", "unknown scenario"),
        ("gains.wn3=-1,5", "below its minimum"),
        ("duration_s=0,1", "below its minimum|must be > 0"),
        ("diameter_mm", "FIELD=VALUES"),
    ],
)
def test_bad_specs_are_named_errors(grid: str, match: str) -> None:
    with pytest.raises(sw.SweepSpecError, match=match):
        sw.build_spec(grid=[grid])


def test_cross_field_checks() -> None:
    # bend_deg cannot be imposed on a scenario that moves joint 2 (when the arm is run) ...
    with pytest.raises(sw.SweepSpecError, match="moves joint 2"):
        sw.build_spec(grid=["bend_deg=0,45"], fixed=["scenario=p2p-payload"])
    # ... but it can when only bench/relief outputs are wanted
    sw.build_spec(grid=["bend_deg=0,45"], fixed=["scenario=p2p-payload"], outputs=["relief"])
    with pytest.raises(sw.SweepSpecError, match="twice"):
        sw.build_spec(grid=["diameter_mm=4,5"], fixed=["diameter_mm=6"])
    with pytest.raises(sw.SweepSpecError, match="outputs"):
        sw.build_spec(outputs=["tracking", "fun"])
    with pytest.raises(sw.SweepSpecError, match="more than"):
        sw.build_spec(grid=["diameter_mm=4:13:100", "length_mm=235:535:100", "bend_deg=0:90:11"])
    with pytest.raises(sw.SweepSpecError, match=r"\[bench\]"):
        sw.build_spec(bench={"chirp_s": -1.0})
    with pytest.raises(sw.SweepSpecError, match=r"\[bandwidth\]"):
        sw.build_spec(bandwidth={"speed": 3.0})


def test_toml_spec(tmp_path: Path) -> None:
    f = tmp_path / "s.toml"
    f.write_text(
        'name = "t"\noutputs = ["relief"]\n[grid]\ndiameter_mm = "4:13:4"\n'
        "length_mm = [235, 535]\n[fixed]\npayload_kg = 5\n"
    )
    spec = sw.build_spec(sw.load_spec_file(f), grid=["length_mm=335"])  # CLI replaces the file's
    assert spec.name == "t" and spec.n_points == 4
    assert spec.grid["length_mm"] == (335.0,)
    assert spec.fixed == {"payload_kg": 5.0}
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\ncolour = "red"\n')
    with pytest.raises(sw.SweepSpecError, match="unknown keys"):
        sw.load_spec_file(bad)
    bad.write_text("[grid\n")
    with pytest.raises(sw.SweepSpecError, match="TOML"):
        sw.load_spec_file(bad)


def test_every_example_spec_is_valid() -> None:
    examples = Path(__file__).resolve().parent.parent / "examples" / "sweeps"
    files = sorted(examples.glob("*.toml"))
    assert files, "examples/sweeps/*.toml missing"
    for f in files:
        spec = sw.build_spec(sw.load_spec_file(f))
        assert spec.n_points >= 1


def test_points_are_complete_canonical_and_unique() -> None:
    spec = sw.build_spec(grid=["diameter_mm=4,9", "gains.wn3=10,25"], outputs=["tracking"])
    pts = sw.points(spec)
    assert len(pts) == 4 == spec.n_points
    assert len({point_key(p) for p in pts}) == 4
    p = pts[0]
    assert p["duration_s"] == 10.0  # the scenario's (fig14-sine)
    assert (
        p["scenario"] == "fig14-sine" and p["bend_deg"] == 45.0 and p["schema"] == sw.POINT_SCHEMA
    )
    assert len(p["catalogue_sha256"]) == 64
    assert sw._gains({**p, "gains.wn3": 10.0}).wn_rad_s == (20.0, 20.0, 10.0)
    assert sw._gains({"gains.torque_bandwidth_rad_s": 80.0}) == Gains(torque_bandwidth_rad_s=80.0)


def test_cli_rejects_bad_spec_before_any_work(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = tmp_path / "r.sqlite"
    code = run_fsarm(monkeypatch, "sweep", "--store", str(store), "--grid", "diameter_mm=13:4:3")
    assert code == 2
    assert "reversed range" in capsys.readouterr().err
    assert not store.exists()


# ---------------------------------------------------------------------------------------------
# per-point metrics


def test_bandwidth_estimator_on_a_known_first_order_lowpass() -> None:
    from scipy import signal as sig

    fs, fc = 1000.0, 8.0
    t = np.arange(0, 6.0, 1 / fs)
    u = arm_metrics.log_chirp(t, 0.5, 80.0, 6.0)
    b, a = sig.bilinear([2 * math.pi * fc], [1.0, 2 * math.pi * fc], fs)
    y = sig.lfilter(b, a, u)
    f, H = arm_metrics.frequency_response(u, y, fs, 0.75, 53.0)
    assert arm_metrics.minus_3db(f, np.abs(H)) == pytest.approx(fc, rel=0.05)
    assert math.isnan(arm_metrics.minus_3db(f, np.abs(H / H)))  # flat: no crossing


def test_torque_bandwidth_follows_the_loop_gain() -> None:
    shaft = load_catalogue().shaft(series_hysteresis=False)  # the loop around eq. 8 alone
    bws = []
    for wt in (60.0, 120.0):
        cfg = SimConfig(shaft=shaft, gains=Gains(torque_bandwidth_rad_s=wt))
        bw = arm_metrics.torque_bandwidth(cfg, chirp_s=2.0, f_stop_hz=80.0)
        assert 0.7 * wt / (2 * math.pi) < bw.bandwidth_hz < 2.5 * wt / (2 * math.pi)
        bws.append(bw.bandwidth_hz)
    assert bws[1] > 1.5 * bws[0]


def test_bend_cannot_be_imposed_on_a_moving_joint2() -> None:
    with pytest.raises(InvalidParameterError, match="moves joint 2"):
        arm_metrics.tracking(SimConfig(), "p2p-payload", duration_s=3.0, bend_rad=0.3)


def test_evaluate_point_outputs_and_labels() -> None:
    spec = sw.build_spec(
        fixed=["duration_s=0.3", "diameter_mm=6", "length_mm=435", "bend_deg=30"],
        bench={"chirp_s": 1.0, "bend_period_s": 1.0, "bend_cycles": 1, "series_hysteresis": False},
        bandwidth={"chirp_s": 1.0, "f_stop_hz": 60.0},
    )
    (p,) = sw.points(spec)
    out = sw.evaluate_point({"point": p, "catalogue_toml": None})
    assert out["stiffness_source"].startswith("simulated bench")
    # series hysteresis off: the bench fit is eq. 3 itself
    assert out["k_sp"] == pytest.approx(out["k_sp_catalogue"], rel=1e-6)
    assert out["k_sn"] == pytest.approx(out["k_sn_catalogue"], rel=1e-6)
    assert out["k_sn"] < out["k_sp"]
    assert out["kb"] > out["kb_catalogue"]  # linear fit absorbs stiffening and the conduit
    for key in (
        "q3_rmse_deg",
        "peak_motor_torque_nm",
        "peak_motor_speed_rad_s",
        "static_relief_nm",
    ):
        assert math.isfinite(out[key]) and out[key] > 0.0
    assert "torque_bandwidth_hz" in out
    only = sw.build_spec(fixed=["diameter_mm=6", "length_mm=435"], outputs=["relief"])
    (q,) = sw.points(only)
    cat_out = sw.evaluate_point({"point": q, "catalogue_toml": None})
    assert cat_out["stiffness_source"] == "catalogue eq. 3/4"
    assert cat_out["kb"] == cat_out["kb_catalogue"]


def test_a_point_after_other_points_equals_a_fresh_one() -> None:
    """What one process keeps between points (compiled models, reference tables, issue 15)
    changes no output: each point evaluated after the others, in either order, equals the point
    evaluated first in an emptied process cache."""
    from fsarm_sim.engine import model as model_mod
    from fsarm_sim.sim import scenarios

    spec = sw.build_spec(
        grid=["diameter_mm=6,12", "length_mm=335,535", "scenario=fig14-sine,p2p-payload"],
        fixed=["duration_s=0.4"],
        outputs=["tracking"],
    )
    tasks = [{"point": p, "catalogue_toml": None, "backend": "native"} for p in sw.points(spec)]

    def clear() -> None:
        model_mod.clear_model_cache()
        scenarios._cached_table.cache_clear()

    fresh = []
    for t in tasks:
        clear()
        fresh.append(sw.evaluate_point(t))
    clear()
    for t, want in [
        *zip(tasks, fresh, strict=True),
        *reversed(list(zip(tasks, fresh, strict=True))),
    ]:
        assert sw.evaluate_point(t) == want
    assert fresh[0] != fresh[1]


# ---------------------------------------------------------------------------------------------
# resume after kill -9, and the analysis


def _count(store: Path) -> int:
    if not store.exists():
        return 0
    try:
        db = sqlite3.connect(f"file:{store}?mode=ro", uri=True, timeout=1.0)
        try:
            return int(db.execute("SELECT COUNT(*) FROM points").fetchone()[0])
        finally:
            db.close()
    except sqlite3.OperationalError:
        return 0


def test_killed_sweep_resumes_without_recomputing_or_duplicating(tmp_path: Path) -> None:
    store = tmp_path / "r.sqlite"
    n = 16
    cmd = [
        sys.executable,
        "-c",
        "from fsarm_sim.cli import main; main()",
        "sweep",
        "--store",
        str(store),
        "--grid",
        f"payload_kg=0:15:{n}",
        "--set",
        "duration_s=0.5",
        "--outputs",
        "tracking",
        "--workers",
        "1",
        "--no-progress",
    ]
    env = {**os.environ, "MUJOCO_GL": "disable"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60.0
    while _count(store) < 3 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    killed_at = _count(store)
    assert 3 <= killed_at < n, "the sweep finished before it could be killed"
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"{killed_at} already stored, {n - killed_at} computed, 0 failed" in " ".join(
        done.stdout.split()
    )
    with ResultStore(store) as st:
        rows = list(st.rows())
    assert len(rows) == n
    assert len({r.key for r in rows}) == n
    assert sorted(r.inputs["payload_kg"] for r in rows) == pytest.approx(
        list(np.linspace(0, 15, n))
    )


def test_analysis_recovers_the_catalogue_surfaces(tmp_path: Path) -> None:
    spec = sw.build_spec(
        grid=["diameter_mm=4,6,9,13", "length_mm=235,535", "bend_deg=0,90"], outputs=["relief"]
    )
    store = tmp_path / "r.sqlite"
    report = sw.run_sweep(spec, store, workers=1)
    assert report.computed == 16 and report.failed == 0
    again = sw.run_sweep(spec, store, workers=1)
    assert again.already == 16 and again.computed == 0
    res = sweep_analysis.analyze(store, tmp_path / "out")
    for eq in ("eq3 positive", "eq3 negative", "eq4"):
        assert res.comparisons[eq].surface_max_rel_error < 1e-9
    names = {p.name for p in res.files}
    assert {
        "points.csv",
        "analysis.json",
        "fig8_eq3_surfaces.png",
        "fig10_eq4_surface.png",
    } <= names
    assert "map_static_relief_nm.png" in names
    # the tidy table beside the store: one row per point, a column per field, units in the schema
    import pyarrow.parquet as pq

    assert report.table == store.with_suffix(".parquet")
    table = pq.read_table(report.table)
    assert table.num_rows == 16
    assert {"diameter_mm", "length_mm", "bend_deg", "static_relief_nm", "kb"} <= set(
        table.column_names
    )
    assert table.schema.field("diameter_mm").metadata[b"unit"] == b"mm"
    assert table.schema.field("static_relief_nm").metadata[b"unit"] == b"N*m"
    assert table.schema.field("kb").metadata[b"unit"] == b"N*m/rad"
    assert sorted(set(table.column("diameter_mm").to_pylist())) == [4.0, 6.0, 9.0, 13.0]


def test_ctrl_c_in_a_point_stores_no_cut_point(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while a point's run steps (one worker, in this process): the sweep stops with
    KeyboardInterrupt and stores only the points that finished - never the cut run's metrics as
    if it were a finished point (0.5.0 stored it and went on)."""
    import mujoco

    from fsarm_sim.sim import simulation

    seen: list[object] = []  # the MjData of each point's run, in order
    real_step = mujoco.mj_step

    def step(m, d, nstep=1):  # type: ignore[no-untyped-def]
        if d not in seen:
            seen.append(d)
        if len(seen) == 2:  # the second point's run, whatever its chunks
            raise KeyboardInterrupt
        real_step(m, d, nstep=nstep)

    monkeypatch.setattr(simulation.mujoco, "mj_step", step)
    spec = sw.build_spec(
        grid=["payload_kg=0,1,2"], fixed=["duration_s=1"], outputs=["tracking"], name="cut"
    )
    store = tmp_path / "r.sqlite"
    with pytest.raises(KeyboardInterrupt):
        sw.run_sweep(spec, store, workers=1)
    with ResultStore(store) as st:
        rows = list(st.rows())
    assert [r.inputs["payload_kg"] for r in rows] == [0.0]


def test_auto_executor_threads_native_simulations_and_pools_python_fits(tmp_path: Path) -> None:
    """The default executor: threads where every point is a native simulation, the process pool
    where points fit benches in Python or step the Python callbacks, inline for one worker."""
    tracking = sw.build_spec(grid=["diameter_mm=8,9"], outputs=["tracking"], name="t")
    assert sw.pick_executor(tracking) == "threads"
    assert sw.pick_executor(tracking, workers=2) == "threads"
    assert sw.pick_executor(tracking, workers=1) == "local"
    assert sw.pick_executor(tracking, "dask") == "dask"  # a named executor is kept
    # the report names the executor the points ran on
    store = tmp_path / "s.sqlite"
    short = sw.build_spec(
        grid=["diameter_mm=8,9"], fixed=["duration_s=0.2"], outputs=["tracking"], name="s"
    )
    assert sw.run_sweep(short, store, workers=2).executor == "threads"
    with pytest.raises(ExecutorError, match="auto, local, threads or dask"):
        sw.pick_executor(tracking, "foo")
    bench = sw.build_spec(grid=["diameter_mm=8,9"], outputs=["bench", "tracking"], name="b")
    assert sw.pick_executor(bench) == "local"
    python = sw.build_spec(
        grid=["diameter_mm=8,9"], backend="python", outputs=["tracking"], name="p"
    )
    assert python.backend == "python" and sw.pick_executor(python) == "local"


def test_a_huge_range_is_refused_before_numpy_makes_it() -> None:
    """Issue 33: 4:13:100000000 used to build 1e8 values (and hang) before the points cap."""
    import time

    start = time.perf_counter()
    with pytest.raises(sw.SweepSpecError, match="at most 100000 points"):
        sw.build_spec(grid=["diameter_mm=4:13:100000000"])
    with pytest.raises(sw.SweepSpecError, match="at most 100000 points"):
        sw.build_spec({"grid": {"diameter_mm": {"start": 4, "stop": 13, "num": 1e300}}})
    assert time.perf_counter() - start < 5.0  # at once (a hang is minutes), not a speed goal


def test_workers_are_capped_before_any_work(tmp_path: Path) -> None:
    from fsarm_sim.executors import MAX_WORKERS, ExecutorError

    spec = sw.build_spec(grid=["diameter_mm=9"], outputs=["relief"])
    for bad in (0, MAX_WORKERS + 1, True):
        with pytest.raises(ExecutorError, match="workers"):
            sw.run_sweep(spec, tmp_path / "r.sqlite", workers=bad)  # type: ignore[arg-type]
    assert not (tmp_path / "r.sqlite").exists()
