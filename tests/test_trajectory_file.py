from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.records import measured
from fsarm_sim.sim import scenarios
from fsarm_sim.studies import arm_metrics
from fsarm_sim.studies import trajectory_file as tf

from conftest import run_fsarm

REF = ("q1_ref", "q2_ref", "q3_ref", "qd1_ref", "qd2_ref", "qd3_ref", "qdd1_ref", "qdd2_ref")
NAMES = (*REF, "qdd3_ref")
N = 301  # 0.3 s at the 1 kHz control rate


def write_fig14(path: Path, columns: tuple[str, ...] = NAMES, n: int = N) -> pd.DataFrame:
    """fig14-sine's own reference table as a trajectory file (CSV or Parquet by suffix)."""
    table = scenarios.get("fig14-sine").table(n, 0.001)
    frame = pd.DataFrame({"t": np.arange(n) * 0.001})
    for k, name in enumerate(NAMES):
        if name in columns:
            frame[name] = table[:, k]
    if path.suffix == ".parquet":
        frame.to_parquet(path)
    else:
        frame.to_csv(path, index=False)
    return frame


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_scenarios_table_as_a_file_tracks_as_the_scenario(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"fig14{suffix}"
    write_fig14(path)
    name = tf.scenario_name(path)
    sc = scenarios.get(name)
    assert sc.duration_s == pytest.approx(0.3) and sc.payload_kg == 0.0
    assert arm_metrics.scenario_holds_joint2(name, 0.3)  # q2 constant: the bends apply
    cfg = SimConfig(shaft=load_catalogue().shaft(9.0, 450.0))
    got = arm_metrics.tracking(cfg, name, bend_rad=0.6)
    want = arm_metrics.tracking(cfg, "fig14-sine", duration_s=0.3, bend_rad=0.6)
    assert got["q3_rmse_deg"] > 0.0
    for key, value in want.items():
        assert got[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key


def test_positions_only_get_finite_difference_rates_and_rest_after_the_end(
    tmp_path: Path,
) -> None:
    path = tmp_path / "pos.csv"
    write_fig14(path, ("q1_ref", "q2_ref", "q3_ref"))
    sc = scenarios.get(tf.scenario_name(path))
    want = scenarios.get("fig14-sine").table(N, 0.001)
    got = sc.table(N, 0.001)
    np.testing.assert_allclose(got[:, :3], want[:, :3], atol=1e-12)
    # central differences: O(dt^2) inside, one-sided (O(dt)) at the two ends
    q3d_scale = np.abs(want[:, 5]).max()
    np.testing.assert_allclose(got[1:-1, 5], want[1:-1, 5], atol=1e-4 * q3d_scale)
    later = sc.reference(np.array([0.25, 0.5]))
    assert later[1, 2] == pytest.approx(want[-1, 2]) and np.all(later[1, 3:] == 0.0)


def _frame() -> pd.DataFrame:
    t = np.arange(5) * 0.01
    return pd.DataFrame({"t": t, "q1_ref": 0.0, "q2_ref": 0.7, "q3_ref": 0.1 * t})


@pytest.mark.parametrize(
    ("change", "error", "words"),
    [
        (
            lambda f: f.drop(columns="q3_ref"),
            measured.MissingColumnError,
            "needs column(s) 'q3_ref'",
        ),
        (lambda f: f.assign(qd1_ref=0.0), measured.MissingColumnError, "all of qd1_ref"),
        (lambda f: f.assign(t=f["t"] + 1.0), measured.TimeAxisError, "must be at t = 0"),
        (lambda f: f.assign(t=[0, 0.2, 0.1, 0.3, 0.4]), measured.TimeAxisError, "increasing"),
        (lambda f: f.assign(t=f["t"] * 1e6), measured.TimeAxisError, "milliseconds"),
        (lambda f: f.assign(q2_ref=45.0), tf.TrajectoryFileError, "in radians"),
        (lambda f: f.assign(q3_ref=np.nan), measured.NonFiniteError, "finite"),
        (lambda f: f.astype({"q1_ref": str}).assign(q1_ref="x"), measured.NonNumericError, "'x'"),
        (lambda f: f.head(1), measured.TooFewSamplesError, "at least 2"),
    ],
)
def test_bad_files_are_named_errors(
    tmp_path: Path,
    change: Callable[[pd.DataFrame], pd.DataFrame],
    error: type[Exception],
    words: str,
) -> None:
    path = tmp_path / "bad.csv"
    change(_frame()).to_csv(path, index=False)
    with pytest.raises(error, match=r"bad\.csv") as info:
        tf.scenario_name(path)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_wrong_suffix_missing_and_changed_files(tmp_path: Path) -> None:
    with pytest.raises(tf.TrajectoryFileError, match=r"\.csv or \.parquet"):
        tf.scenario_name(tmp_path / "traj.txt")
    with pytest.raises(measured.MeasuredDataError, match="not found"):
        tf.scenario_name(tmp_path / "absent.csv")
    path = tmp_path / "t.csv"
    _frame().to_csv(path, index=False)
    name = tf.scenario_name(path)
    _frame().assign(q3_ref=0.2).to_csv(path, index=False)
    assert tf.scenario_name(path) != name  # a changed file is a new task (a new store key)
    with pytest.raises(tf.TrajectoryFileError, match="changed since"):
        scenarios.get(name)


def test_select_on_a_trajectory_file(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "mine.parquet"
    write_fig14(path)
    store = ["--store", str(tmp_path / "s.sqlite"), "--out", str(tmp_path)]
    args = ["select", "--trajectory-file", str(path), "--budget", "16", *store]
    assert run_fsarm(monkeypatch, *args) == 0
    assert "optimum: D =" in capsys.readouterr().out
    data = json.loads((tmp_path / "select.json").read_text())
    assert data["task"]["scenario"].startswith(f"file:{path.resolve()}#sha256=")
    assert 4.0 <= data["best"]["diameter_mm"] <= 13.0
    bad = tmp_path / "bad.csv"
    _frame().drop(columns="q2_ref").to_csv(bad, index=False)
    for wrong in (
        ["select", "--trajectory-file", str(bad)],
        ["select", "fig14-sine", "--trajectory-file", str(path)],
        ["select"],
    ):
        assert run_fsarm(monkeypatch, *wrong) == 2
        err = capsys.readouterr().err
        assert "Traceback" not in err and ("q2_ref" in err or "one of the two" in err)
