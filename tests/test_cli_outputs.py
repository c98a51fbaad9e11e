"""Bad-input battery of the ``fsarm`` commands (issue 17): output paths checked before the run,
no output over an input or over another output, foreign result stores left untouched, bad numbers
refused up front, exit codes that tell the truth, and results kept when a write fails.

Every refused case: exit code 2, one line ``error: ...`` naming the problem, no traceback, and the
files that were there before are byte-identical afterwards.
"""

from __future__ import annotations

import errno
import io
import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import FailingStdout, run_fsarm

DATA = Path(__file__).resolve().parents[1] / "examples" / "data"
SHORT = ["--duration", "0.2"]


def _setup(tmp: Path) -> None:
    """The files every case may refer to (each case gets a fresh copy)."""
    shutil.copy(DATA / "series_null.csv", tmp / "m.csv")
    shutil.copy(DATA / "series_null.json", tmp / "m.json")
    ms = pd.read_csv(DATA / "series_null.csv")
    ms["t"] = ms["t"] * 1000.0  # time in milliseconds
    ms.to_csv(tmp / "ms.csv", index=False)
    shutil.copy(DATA / "series_null.json", tmp / "ms.json")
    (tmp / "afile").write_text("a file, not a folder\n")
    (tmp / "adir").mkdir()
    (tmp / "tab.csv").mkdir()
    (tmp / "D").mkdir()
    (tmp / "D" / "fig14-sine.csv").write_text("t,q1\n0,0\n")  # an earlier run's time series
    (tmp / "D" / "fig14-sine.json").write_text('{"setup": "arm"}\n')
    (tmp / "coeff.toml").write_text("# someone's coefficient file\n")
    (tmp / "spec.toml").write_text("[grid]\ndiameter_mm = [9]\n")
    (tmp / "x.json").write_text('{"format": "fsarm-bench-model"}\n')
    db = sqlite3.connect(tmp / "foreign.db")
    db.execute("CREATE TABLE customers (name TEXT)")
    db.execute("INSERT INTO customers VALUES ('ada')")
    db.commit()
    db.close()
    (tmp / "notsql.db").write_bytes(b"not a database at all\n" * 40)


def _snapshot(tmp: Path) -> dict[str, bytes]:
    return {str(p.relative_to(tmp)): p.read_bytes() for p in sorted(tmp.rglob("*")) if p.is_file()}


# (id, arguments with {t} = the case's folder, text the one error line must contain)
REFUSED: list[tuple[str, list[str], str]] = [
    # fsarm run: outputs over outputs, files vs folders, unwritable places
    (
        "run-json-over-timeseries",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/D", "--json", "{t}/D/fig14-sine.csv"],
        "--json {t}/D/fig14-sine.csv is the same file as the time series that --out writes",
    ),
    (
        "run-json-over-sidecar",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/D", "--json", "{t}/D/fig14-sine.json"],
        "same file as the time series' sidecar that --out writes",
    ),
    (
        "run-json-over-timeseries-unresolved",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/D", "--json", "{t}/adir/../D/fig14-sine.csv"],
        "same file as the time series that --out writes",
    ),
    (
        "run-parquet-sidecar",
        [
            "run",
            "step-q3",
            *SHORT,
            "--format",
            "parquet",
            "--out",
            "{t}/D",
            "--rrd",
            "{t}/D/step-q3.parquet",
        ],
        "--rrd {t}/D/step-q3.parquet is the same file as the time series",
    ),
    (
        "run-json-is-folder",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--json", "{t}/adir"],
        "--json points to the folder {t}/adir; give a file path",
    ),
    (
        "run-out-is-file",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/afile"],
        "--out points to the file {t}/afile; give a folder",
    ),
    (
        "run-rrd-is-folder",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--rrd", "{t}/adir"],
        "--rrd points to the folder",
    ),
    (
        "run-figures-is-file",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--figures", "{t}/afile"],
        "--figures points to the file",
    ),
    (
        "run-json-under-a-file",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--json", "{t}/afile/s.json"],
        "{t}/afile is a file, not a folder",
    ),
    (
        "run-json-is-out-folder",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--json", "{t}/o"],
        "--json {t}/o is also the folder of --out",
    ),
    (
        "run-json-and-rrd-same",
        ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--json", "{t}/s", "--rrd", "{t}/s"],
        "the same file as the file of --json",
    ),
    (
        "run-json-over-shaft-file",
        [
            "run",
            "fig14-sine",
            *SHORT,
            "--out",
            "{t}/o",
            "--shaft-file",
            "{t}/coeff.toml",
            "--json",
            "{t}/coeff.toml",
        ],
        "is the coefficient file of --shaft-file (an input)",
    ),
    ("run-format", ["run", "fig14-sine", *SHORT, "--out", "{t}/o", "--format", "xlsx"], "format"),
    ("run-unknown-scenario", ["run", "nope", "--out", "{t}/o"], "'nope' is not one of"),
    ("run-duration-nan", ["run", "fig14-sine", "--duration", "nan", "--out", "{t}/o"], "duration"),
    # fsarm diagnose: outputs over the dataset, files vs folders, time in milliseconds
    (
        "diagnose-json-over-sidecar",
        ["diagnose", "{t}/m.csv", "--json", "{t}/m.json"],
        "--json {t}/m.json is the sidecar of the dataset {t}/m.csv (an input)",
    ),
    (
        "diagnose-json-over-table",
        ["diagnose", "{t}/m.csv", "--json", "{t}/m.csv"],
        "is the dataset {t}/m.csv (an input)",
    ),
    (
        "diagnose-model-over-sidecar",
        ["diagnose", "{t}/m", "--model", "{t}/m.json"],
        "--model {t}/m.json is the sidecar of the dataset",
    ),
    (
        "diagnose-report-is-file",
        ["diagnose", "{t}/m.csv", "--report", "{t}/afile"],
        "--report points to the file {t}/afile; give a folder",
    ),
    (
        "diagnose-model-is-folder",
        ["diagnose", "{t}/m.csv", "--model", "{t}/adir"],
        "--model points to the folder {t}/adir; give a file path",
    ),
    (
        "diagnose-json-is-folder",
        ["diagnose", "{t}/m.csv", "--json", "{t}/adir"],
        "--json points to the folder",
    ),
    (
        "diagnose-json-in-report",
        ["diagnose", "{t}/m.csv", "--report", "{t}/R", "--json", "{t}/R/result.json"],
        "--json {t}/R/result.json is the same file as the result that --report writes",
    ),
    (
        "diagnose-model-in-report",
        ["diagnose", "{t}/m.csv", "--report", "{t}/R", "--model", "{t}/R/model.json"],
        "is the same file as the final model that --report writes",
    ),
    ("diagnose-time-in-ms", ["diagnose", "{t}/ms.csv"], "if it is in milliseconds"),
    ("diagnose-no-table", ["diagnose", "{t}/none.csv"], "not found"),
    # fsarm synth: numbers refused at synth time, memory cap, outputs over inputs
    ("synth-inertia", ["synth", "{t}/s.csv", "--inertia", "-1"], "--inertia must be"),
    (
        "synth-inertia-load",
        ["synth", "{t}/s.csv", "--load", "inertia", "--inertia", "0"],
        "--inertia must be",
    ),
    (
        "synth-true-inertia",
        ["synth", "{t}/s.csv", "--load", "inertia", "--true-inertia", "-1"],
        "--true-inertia must be",
    ),
    ("synth-stiffness", ["synth", "{t}/s.csv", "--stiffness-scale", "nan"], "--stiffness-scale"),
    ("synth-amplitude", ["synth", "{t}/s.csv", "--amplitude", "-1"], "--amplitude must be"),
    ("synth-noise", ["synth", "{t}/s.csv", "--noise", "nan"], "--noise must be"),
    ("synth-rate-huge", ["synth", "{t}/s.csv", "--rate", "1e9"], "samples are allowed"),
    (
        "synth-long",
        ["synth", "{t}/s.csv", "--duration", "1e7"],
        "lower --rate or --duration",
    ),
    ("synth-rate-slow", ["synth", "{t}/s.csv", "--rate", "1"], "--rate"),
    ("synth-setup", ["synth", "{t}/s.csv", "--setup", "bogus"], "'--setup': 'bogus' is not one of"),
    (
        "synth-sidecar-over-model",
        ["synth", "{t}/x.csv", "--model", "{t}/x.json"],
        "the sidecar of OUT {t}/x.json is the truth model of --model (an input)",
    ),
    ("synth-out-is-folder", ["synth", "{t}/tab.csv"], "OUT points to the folder"),
    # fsarm check-dynamics, compare-transmissions, transparency, collision, bench-speed
    ("dynamics-duration-nan", ["check-dynamics", "--duration", "nan"], "duration must be"),
    ("dynamics-duration-long", ["check-dynamics", "--duration", "1e5"], "duration must be"),
    ("dynamics-inertia", ["check-dynamics", "--shaft-inertia", "-1"], "shaft inertia must be"),
    ("dynamics-json-folder", ["check-dynamics", "--json", "{t}/adir"], "--json points to"),
    ("compare-duration-nan", ["compare-transmissions", "--duration", "nan"], "duration must be"),
    ("compare-payload-nan", ["compare-transmissions", "--payload-kg", "nan"], "--payload-kg"),
    ("compare-json-folder", ["compare-transmissions", "--json", "{t}/adir"], "--json points to"),
    ("transparency-json-folder", ["transparency", "--json", "{t}/adir"], "--json points to"),
    ("collision-json-folder", ["collision", "--json", "{t}/adir"], "--json points to"),
    ("collision-json-under-file", ["collision", "--json", "{t}/afile/c.json"], "not a folder"),
    ("bench-speed-json-folder", ["bench-speed", "--quick", "--json", "{t}/adir"], "--json"),
    # sweeps, stores, campaigns, figures
    (
        "sweep-foreign-sqlite",
        ["sweep", "--store", "{t}/foreign.db", "--grid", "diameter_mm=9", "--no-progress"],
        "foreign.db is an SQLite database that fsarm did not create",
    ),
    (
        "sweep-not-sqlite",
        ["sweep", "--store", "{t}/notsql.db", "--grid", "diameter_mm=9", "--no-progress"],
        "it is not an SQLite file",
    ),
    (
        "sweep-dry-run-foreign",
        ["sweep", "--store", "{t}/foreign.db", "--grid", "diameter_mm=9", "--dry-run"],
        "did not create",
    ),
    (
        "sweep-report-foreign",
        ["sweep-report", "--store", "{t}/foreign.db", "--out", "{t}/rep"],
        "did not create",
    ),
    (
        "sweep-store-is-folder",
        ["sweep", "--store", "{t}/adir", "--grid", "diameter_mm=9"],
        "--store points to the folder",
    ),
    (
        "sweep-store-is-spec",
        ["sweep", "--store", "{t}/spec.toml", "--spec", "{t}/spec.toml"],
        "--store {t}/spec.toml is the sweep spec of --spec (an input)",
    ),
    (
        "sweep-out-is-file",
        ["sweep", "--store", "{t}/r.sqlite", "--grid", "diameter_mm=9", "--out", "{t}/afile"],
        "--out points to the file",
    ),
    ("sweep-no-store", ["sweep", "--grid", "diameter_mm=9"], "--store FILE is required"),
    (
        "sweep-report-no-store",
        ["sweep-report", "--store", "{t}/no.db", "--out", "{t}/r"],
        "results store not found",
    ),
    ("campaign-out-is-file", ["campaign", "--out", "{t}/afile"], "--out points to the file"),
    ("bench-series-out-is-file", ["bench", "series", "--out", "{t}/afile"], "--out points to"),
    ("bench-parallel-out-is-file", ["bench", "parallel", "--out", "{t}/afile"], "--out points"),
    ("figures-out-is-file", ["figures", "--out", "{t}/afile"], "--out points to the file"),
    ("select-shaft-nan", ["select-shaft", "--k-des", "nan"], "K_des"),
    ("diagnose-max-effects", ["diagnose", "{t}/m.csv", "--max-effects", "-1"], "--max-effects"),
    (
        "collision-series-hysteresis",
        ["collision", "--transmission", "qa-joint", "--no-series-hysteresis"],
        "--[no-]series-hysteresis would change nothing with transmission 'qa-joint'",
    ),
    # qa-throws: every input checked before the table's header is printed
    (
        "qa-throws-speed-zero",
        ["qa-throws", "--speeds", "0"],
        "--speeds must be finite and > 0 deg/s",
    ),
    ("qa-throws-preset", ["qa-throws", "--presets", "4"], "Table IV of seed 002 has rows"),
    (
        "qa-throws-adjust",
        ["qa-throws", "--adjust", "x"],
        "'--adjust': 'x' is not one of 'none', 'drive', 'ideal'",
    ),
    ("qa-throws-arm", ["qa-throws", "--lever-arms", "9"], "--lever-arms must be within"),
    # shaft options a transmission would ignore (they used to change nothing, silently)
    (
        "run-qa-joint-diameter",
        ["run", "fig14-sine", "--out", "{t}/o", "--transmission", "qa-joint", "--diameter-mm", "6"],
        "--diameter-mm would change nothing with transmission 'qa-joint': it reads no catalogue",
    ),
    (
        "run-magnetic-spring-shaft-file",
        [
            "run",
            "fig14-sine",
            "--out",
            "{t}/o",
            "--transmission",
            "magnetic-spring",
            "--extrapolate",
        ],
        "--extrapolate would change nothing with transmission 'magnetic-spring'",
    ),
    (
        "run-rtca-series-hysteresis",
        ["run", "fig14-sine", "--out", "{t}/o", "--transmission", "rtca", "--no-series-hysteresis"],
        "--[no-]series-hysteresis would change nothing with transmission 'rtca': it keeps the "
        "catalogue shaft only for the bending moment on joint 2",
    ),
    (
        "run-tendon-sheath-compare-hysteresis",
        [
            "run",
            "fig14-sine",
            "--out",
            "{t}/o",
            "--transmission",
            "tendon-sheath",
            "--rrd",
            "{t}/x.rrd",
            "--rrd-compare",
            "series-hysteresis=off",
        ],
        "--rrd-compare series-hysteresis would change nothing with transmission 'tendon-sheath'",
    ),
]


@pytest.mark.parametrize(("args", "message"), [c[1:] for c in REFUSED], ids=[c[0] for c in REFUSED])
def test_refused_with_one_named_line(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    args: list[str],
    message: str,
) -> None:
    _setup(tmp_path)
    before = _snapshot(tmp_path)
    code = run_fsarm(monkeypatch, *(a.replace("{t}", str(tmp_path)) for a in args))
    cap = capsys.readouterr()
    assert "Traceback" not in cap.out + cap.err
    lines = cap.err.strip().splitlines()
    assert code == 2, cap.err
    assert len(lines) == 1 and lines[0].startswith("error: "), cap.err
    assert message.replace("{t}", str(tmp_path)) in lines[0]
    assert _snapshot(tmp_path) == before  # nothing written, nothing overwritten
    assert not list(tmp_path.glob("*-wal")) and not (tmp_path / "rep").exists()


# ---------------------------------------------------------------------------------------------
# a write that fails after the run keeps the results


def test_run_summary_to_a_full_disk_is_rescued(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    code = run_fsarm(
        monkeypatch, "run", "step-q3", *SHORT, "--out", str(tmp_path), "--json", "/dev/full"
    )
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert (tmp_path / "step-q3.csv").is_file()  # the other output is where it was asked
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: 1 output(s) not written where asked") and "saved to" in last
    rescued = Path(last.split("saved to ")[1].split(" instead")[0])
    assert "fsarm-rescue-" in str(rescued)
    assert set(json.loads(rescued.read_text())["rmse_rad"]) == {"q1", "q2", "q3"}
    shutil.rmtree(rescued.parent)


def test_run_timeseries_write_failure_is_rescued(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from fsarm_sim.records import timeseries

    original = timeseries.write_timeseries
    target = tmp_path / "o"

    def failing(result: object, out_dir: Path, fmt: str = "csv") -> Path:
        if out_dir == target:
            raise OSError(28, "No space left on device")
        return original(result, out_dir, fmt)

    monkeypatch.setattr(timeseries, "write_timeseries", failing)
    code = run_fsarm(monkeypatch, "run", "step-q3", *SHORT, "--out", str(target))
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and "No space left on device" in err
    rescued = Path(err.strip().splitlines()[-1].split("saved to ")[1].split(" instead")[0])
    assert rescued.name.startswith("fsarm-rescue-")
    assert len(pd.read_csv(rescued / "step-q3.csv")) == 200
    assert json.loads((rescued / "step-q3.json").read_text())["setup"] == "arm"
    shutil.rmtree(rescued)


def test_diagnose_result_to_a_full_disk_is_rescued(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    code = run_fsarm(
        monkeypatch,
        "diagnose",
        str(DATA / "series_null.csv"),
        "--json",
        "/dev/full",
        "--model",
        str(tmp_path / "model.json"),
    )
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert (tmp_path / "model.json").is_file()
    last = err.strip().splitlines()[-1]
    rescued = Path(last.split("saved to ")[1].split(" instead")[0])
    assert json.loads(rescued.read_text())["setup"] == "series_bench"
    shutil.rmtree(rescued.parent)


# ---------------------------------------------------------------------------------------------
# exit codes that tell the truth


def test_ctrl_c_during_run_keeps_the_finished_part_and_exits_130(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from fsarm_sim.sim.simulation import Simulation

    loop = Simulation._loop

    def half_then_ctrl_c(self: Simulation, n_steps: int, *args: object) -> None:
        loop(self, n_steps // 2, *args)
        raise KeyboardInterrupt

    monkeypatch.setattr(Simulation, "_loop", half_then_ctrl_c)
    summary = tmp_path / "s.json"
    code = run_fsarm(
        monkeypatch,
        "run",
        "step-q3",
        "--duration",
        "0.4",
        "--out",
        str(tmp_path),
        "--json",
        str(summary),
    )
    err = capsys.readouterr().err
    assert code == 130 and "Traceback" not in err and "interrupted" in err
    side = json.loads((tmp_path / "step-q3.json").read_text())
    assert side["interrupted"] is True and 0.15 < side["duration_s"] < 0.25
    assert 150 < len(pd.read_csv(tmp_path / "step-q3.csv")) < 250
    assert json.loads(summary.read_text())["setup"]["interrupted"] is True


def test_compare_transmissions_exits_1_when_a_row_failed(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from fsarm_sim.errors import RunFailedError
    from fsarm_sim.studies import comparison

    original = comparison.run_scenario

    def run(name: str, cfg: comparison.SimConfig, **kw: object) -> object:
        if cfg.transmission == "rtca":
            raise RunFailedError("run diverged (test)")
        return original(name, cfg, **kw)

    monkeypatch.setattr(comparison, "run_scenario", run)
    rows = tmp_path / "rows.json"
    code = run_fsarm(
        monkeypatch,
        "compare-transmissions",
        "--quick",
        *SHORT,
        "--only",
        "flexible-shaft",
        "--only",
        "rtca",
        "--json",
        str(rows),
    )
    cap = capsys.readouterr()
    assert code == 1 and "Traceback" not in cap.out + cap.err
    assert "failed rtca: run diverged (test)" in cap.out
    assert "1 of 2 transmission(s) failed" in cap.err
    assert [r["transmission"] for r in json.loads(rows.read_text())] == ["flexible-shaft", "rtca"]


def test_compare_transmissions_all_ok_exits_0(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code = run_fsarm(
        monkeypatch, "compare-transmissions", "--quick", *SHORT, "--only", "tendon-sheath"
    )
    assert code == 0 and "failed" not in capsys.readouterr().out


def test_sweep_rerun_reports_failed_points_already_stored(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from fsarm_sim.records.store import ResultStore
    from fsarm_sim.studies import sweep as sw

    store = tmp_path / "r.sqlite"
    grid = "diameter_mm=9"
    spec = sw.build_spec(None, grid=[grid], fixed=[], name=None, outputs=["bench"])
    (point,) = sw.points(spec)
    with ResultStore(store) as st:
        st.put(point, None, sweep=spec.name, error="diverged at t = 1 s (earlier run)")
    code = run_fsarm(
        monkeypatch,
        "sweep",
        "--store",
        str(store),
        "--grid",
        grid,
        "--outputs",
        "bench",
        "--no-progress",
    )
    cap = capsys.readouterr()
    assert code == 2 and "Traceback" not in cap.out + cap.err
    assert "1 of the 1 stored point(s) had failed in an earlier run" in cap.out
    assert "diverged at t = 1 s (earlier run) (stored by an earlier run)" in cap.out
    (line,) = cap.err.strip().splitlines()
    assert "1 point(s) of sweep failed (0 in this run, 1 stored by an earlier run)" in line


def test_store_accepts_its_own_files_and_empty_ones(tmp_path: Path) -> None:
    from fsarm_sim.records.store import ResultStore

    (tmp_path / "empty.sqlite").touch()
    sqlite3.connect(tmp_path / "blank.sqlite").close()  # SQLite file with no tables
    for name in ("new.sqlite", "empty.sqlite", "blank.sqlite"):
        with ResultStore(tmp_path / name) as st:
            st.set_meta("x", "1")
        with ResultStore(tmp_path / name) as st:  # reopened: recognised as fsarm's
            assert st.meta("x") == "1" and st.meta("schema_version") == "1"


def test_run_outputs_that_do_not_collide_pass(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The checks refuse only what is wrong: an existing output folder, a summary beside the
    time series, and a folder still to be made are fine."""
    (tmp_path / "D").mkdir()
    code = run_fsarm(
        monkeypatch,
        "run",
        "step-q3",
        *SHORT,
        "--out",
        str(tmp_path / "D"),
        "--json",
        str(tmp_path / "D" / "summary.json"),
        "--figures",
        str(tmp_path / "new" / "figs"),
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert (tmp_path / "D" / "step-q3.csv").is_file()
    assert (tmp_path / "D" / "summary.json").is_file()
    # every figure is written, or left out with its reason (a short run's bend is held)
    written = len(list((tmp_path / "new" / "figs").glob("*.png")))
    left_out = sum(
        line.startswith("no ") and "figure" in line for line in captured.out.splitlines()
    )
    assert written >= 1 and written + left_out == 3


def test_module_names_every_command_that_writes() -> None:
    """Each command module that writes files goes through fsarm_sim.outputs."""
    src = Path(__file__).resolve().parents[1] / "src" / "fsarm_sim" / "cli"
    for name in (
        "__init__.py",
        "review.py",
        "discrepancy.py",
        "dynamics.py",
        "speed.py",
        "sweep.py",
        "transmissions.py",
        "collision.py",
    ):
        text = (src / name).read_text()
        assert "OutputPlan" in text or "run_output_plan" in text, name


def test_unwritable_places_are_refused_before_the_run(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """No write permission (simulated: the tests may run as root, who may write anywhere)."""
    import os

    real_access = os.access
    locked = tmp_path / "locked"
    locked.mkdir()
    (locked / "old.json").write_text("{}")

    def access(path: object, mode: int) -> bool:
        p = Path(str(path))
        denied = mode & os.W_OK and (p == locked or locked in p.parents)
        return not denied and real_access(path, mode)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "access", access)
    for args, message in (
        (["--json", str(locked / "s.json")], f"no permission to write in {locked}"),
        (["--json", str(locked / "new" / "s.json")], f"no permission to write in {locked}"),
        (["--json", str(locked / "old.json")], "exists and is not writable"),
        (["--out", str(locked)], "no permission to write in this folder"),
        (["--figures", str(locked / "f")], f"no permission to write in {locked}"),
    ):
        code = run_fsarm(monkeypatch, "run", "step-q3", *SHORT, "--out", str(tmp_path), *args)
        err = capsys.readouterr().err
        (line,) = err.strip().splitlines()
        assert code == 2 and message in line, err
    assert not (tmp_path / "step-q3.csv").exists()  # refused before the run


def test_safe_writer_reports_a_result_it_could_not_keep(tmp_path: Path) -> None:
    from fsarm_sim.errors import OutputWriteError
    from fsarm_sim.outputs import SafeWriter

    notes: list[str] = []
    writes = SafeWriter(notes.append)

    def never(path: Path) -> Path:
        raise OSError(5, "Input/output error")

    assert writes.write(tmp_path / "a.json", never, "the thing (--json)") is None
    assert len(notes) == 1 and "it is lost" in notes[0] and "Input/output error" in notes[0]
    assert writes.write(tmp_path / "b.json", lambda p: p, "ok") == tmp_path / "b.json"
    with pytest.raises(OutputWriteError, match="1 output"):
        writes.finish()


def test_sweep_dry_run_counts_failed_points_in_the_store(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from fsarm_sim.records.store import ResultStore
    from fsarm_sim.studies import sweep as sw

    store = tmp_path / "r.sqlite"
    spec = sw.build_spec(None, grid=["diameter_mm=9,10"], outputs=["bench"])
    with ResultStore(store) as st:
        st.put(sw.points(spec)[0], None, sweep=spec.name, error="boom")
    code = run_fsarm(
        monkeypatch,
        "sweep",
        "--store",
        str(store),
        "--grid",
        "diameter_mm=9,10",
        "--outputs",
        "bench",
        "--dry-run",
    )
    assert code == 0
    assert "2 points valid, 1 already in" in capsys.readouterr().out


# ---------------------------------------------------------------------------------------------
# a print that fails never loses the work (issue 33): files first, then the printout; a full or
# closed standard output is one named line at the end, a reader that left (| head) no error


def test_run_with_stdout_on_a_full_device_keeps_every_file(tmp_path: Path) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    fsarm = Path(sys.executable).with_name("fsarm")
    out, summary = str(tmp_path / "D"), str(tmp_path / "S")
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [str(fsarm), "run", "fig14-sine", *SHORT, "--out", out, "--json", summary],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, "MUJOCO_GL": "disable"},
            timeout=120,
        )
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert done.returncode == 2
    assert line.startswith("error: standard output could not be written (no space left")
    assert len(pd.read_csv(tmp_path / "D" / "fig14-sine.csv")) == 200
    assert json.loads((tmp_path / "D" / "fig14-sine.json").read_text())["setup"] == "arm"
    assert set(json.loads((tmp_path / "S").read_text())["rmse_rad"]) == {"q1", "q2", "q3"}


@pytest.mark.parametrize(
    ("code", "exit_code", "message"),
    [
        (errno.ENOSPC, 2, "error: standard output could not be written (no space left"),
        (errno.EIO, 2, "error: standard output could not be written (input/output error"),
        (errno.EPIPE, 0, None),  # the reader left (| head): nothing is wrong
    ],
)
def test_a_failing_stdout_is_named_once_and_stops_nothing(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    code: int,
    exit_code: int,
    message: str | None,
) -> None:
    monkeypatch.setattr(sys, "stdout", FailingStdout(code))
    assert run_fsarm(monkeypatch, "scenarios") == exit_code
    assert run_fsarm(monkeypatch, "run", "step-q3", *SHORT, "--out", str(tmp_path)) == exit_code
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert (tmp_path / "step-q3.csv").is_file() and (tmp_path / "step-q3.json").is_file()
    lines = err.strip().splitlines()
    if message is not None:
        assert len(lines) == 2 and all(ln.startswith(message) for ln in lines)
    else:
        assert lines == []


def test_guarded_stream_keeps_the_first_error_and_drops_the_rest() -> None:
    from fsarm_sim.outputs import GuardedStream

    g = GuardedStream(FailingStdout(errno.ENOSPC))
    assert g.write("abc") == 3 and g.write("de") == 2
    g.flush()
    assert g.error is not None and g.error.errno == errno.ENOSPC
    ok = GuardedStream(io.StringIO())
    ok.write("fine")
    ok.flush()
    assert ok.error is None and ok.stream.getvalue() == "fine"


# ---------------------------------------------------------------------------------------------
# outputs over inputs and sizes that scale work (issue 33)


def test_design_experiment_saves_before_it_prints(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Both files of design-experiment exist although standard output is full."""
    from fsarm_sim.discrepancy import design

    def quick(ds: object, **_: object) -> dict[str, object]:  # the design: tested elsewhere
        t = np.linspace(0.0, 1.0, 20)
        best = {"design": "sine", "expected_margin": 1.0}
        best |= {"expected_margin_if_A": 1.0, "expected_margin_if_B": 1.0}
        return {  # the keys the command reads
            "t": t,
            "u": 0.1 * t,
            "best": best,
            "own_input_expected_margin": 0.5,
            "step": 1,
            "A": "a",
            "B": "b",
            "record_margin": 0.2,
            "input_column": "theta_m",
        }

    monkeypatch.setattr(design, "design", quick)
    monkeypatch.setattr(sys, "stdout", FailingStdout(errno.ENOSPC))
    code = run_fsarm(
        monkeypatch,
        "design-experiment",
        str(DATA / "series_null.csv"),
        "--out",
        str(tmp_path / "in.csv"),
        "--json",
        str(tmp_path / "d.json"),
    )
    err = capsys.readouterr().err
    assert "Traceback" not in err and code == 2, err
    assert (tmp_path / "in.csv").is_file() and json.loads((tmp_path / "d.json").read_text())
