"""Comparison recordings: two shafts of one scenario in one recording, read back with Rerun's
reader; each configuration's series and loop are its own run's values."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.review import comparison, recording
from fsarm_sim.sim.simulation import RunResult, run_scenario

from conftest import run_fsarm

RrdReader = pytest.importorskip("rerun.chunk").RrdReader
RATE_HZ = 50.0


@pytest.fixture(scope="module")
def runs() -> list[tuple[str, RunResult]]:
    cat = load_catalogue()
    out = []
    for tag, d in (("D9", 9.0), ("D7", 7.0)):
        cfg = SimConfig(shaft=cat.shaft(d, 450.0))
        out.append((tag, run_scenario("step-q3", cfg, duration_s=0.4, backend="native")))
    return out


@pytest.fixture(scope="module")
def chunks(
    runs: list[tuple[str, RunResult]], tmp_path_factory: pytest.TempPathFactory
) -> dict[str, list[dict[str, Any]]]:
    path = tmp_path_factory.mktemp("cmp") / "cmp.rrd"
    comparison.record_runs(runs, path, rate_hz=RATE_HZ)
    reader = RrdReader(path)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    out: dict[str, list[dict[str, Any]]] = {}
    for c in reader.stream().collect().stream():
        out.setdefault(c.entity_path, []).append(c.to_record_batch().to_pydict())
    return out


def _temporal(chunks: dict[str, list[dict[str, Any]]], path: str, column: str) -> list[Any]:
    t: list[float] = []
    vals: list[Any] = []
    for b in chunks[path]:
        if "sim_time" in b and column in b:
            t += [x.total_seconds() for x in b["sim_time"]]
            vals += b[column]
    return [vals[i] for i in np.argsort(t, kind="stable")]


def test_each_configuration_has_its_own_series(
    chunks: dict[str, list[dict[str, Any]]], runs: list[tuple[str, RunResult]]
) -> None:
    for tag, run in runs:
        rows = recording.decimate(run.columns["t"], RATE_HZ)
        got = np.ravel(
            _temporal(chunks, f"/signals/shaft_torque/{tag}/tau_shaft", "Scalars:scalars")
        )
        np.testing.assert_allclose(got, run.columns["tau_shaft"][rows], rtol=1e-12)
    a, b = (run.columns["tau_shaft"] for _, run in runs)
    assert not np.allclose(a, b)  # two shafts: the comparison shows a difference


def test_loop_panel_traces_both(
    chunks: dict[str, list[dict[str, Any]]], runs: list[tuple[str, RunResult]]
) -> None:
    stored = json.loads(
        next(b for b in chunks["/loops/torque_twist/map"] if "TextDocument:text" in b)[
            "TextDocument:text"
        ][0][0]
    )
    for tag, run in runs:
        rows = recording.decimate(run.columns["t"], RATE_HZ)
        now = _temporal(chunks, f"/loops/torque_twist/{tag}/now", "Points2D:positions")
        px = np.array([np.asarray(p, dtype=float).reshape(-1, 2)[0] for p in now])
        x = np.degrees(run.columns["twist"][rows])
        y = run.columns["tau_shaft"][rows]
        np.testing.assert_allclose(px[:, 0], stored["u"][0] + stored["u"][1] * x, atol=1e-3)
        np.testing.assert_allclose(px[:, 1], stored["v"][0] + stored["v"][1] * y, atol=1e-3)
    text = next(b for b in chunks["/run/metadata"] if "TextDocument:text" in b)
    assert "D9 vs D7" in text["TextDocument:text"][0][0]


def test_bad_configuration_names(runs: list[tuple[str, RunResult]], tmp_path: Path) -> None:
    (_, r1), (_, r2) = runs
    for tags, msg in ((("a=1", "a_1"), "differ"), (("a/b", "c"), "no '/'"), (("a",), "2 to")):
        pairs = list(zip(tags, (r1, r2), strict=False))
        with pytest.raises(InvalidParameterError, match=msg):
            comparison.record_runs(pairs, tmp_path / "x.rrd")
    assert not (tmp_path / "x.rrd").exists()


def test_cli_run_records_a_comparison(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rrd = tmp_path / "cmp.rrd"
    code = run_fsarm(
        monkeypatch,
        "run",
        "step-q3",
        "--duration",
        "0.2",
        "--out",
        str(tmp_path / "runs"),
        "--rrd",
        str(rrd),
        "--rrd-compare",
        "diameter-mm=7",
    )
    assert code == 0, capsys.readouterr().err
    paths = {c.entity_path for c in RrdReader(rrd).stream().collect().stream()}
    assert {
        "/signals/shaft_torque/diameter-mm_9/tau_shaft",
        "/signals/shaft_torque/diameter-mm_7/tau_shaft",
        "/loops/torque_twist/diameter-mm_7/now",
    } <= paths


@pytest.mark.parametrize(
    ("args", "msg"),
    [
        (["--rrd-compare", "diameter-mm=7"], "needs --rrd"),
        (["--rrd", "X", "--rrd-compare", "colour=red"], "KEY=VALUE with KEY among"),
        (["--rrd", "X", "--rrd-compare", "length-mm=-3"], "finite number > 0"),
        (["--rrd", "X", "--rrd-compare", "series-hysteresis=maybe"], "on|off"),
    ],
)
def test_cli_rejects_bad_comparisons_before_running(
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    msg: str,
) -> None:
    args = [str(tmp_path / "x.rrd") if a == "X" else a for a in args]
    code = run_fsarm(monkeypatch, "run", "step-q3", "--out", str(tmp_path / "runs"), *args)
    assert code == 2 and msg in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()


def test_series_comparison_recording(tmp_path: Path) -> None:
    """A record-vs-models recording (what `fsarm diagnose --rrd` writes): every curve under its
    panel with its values, the loops' current points on the stored pixel map."""
    t = np.linspace(0.0, 2.0, 201)
    y = np.sin(3 * t)
    panels = [
        comparison.SeriesPanel("out", "output", {"measured": y, "final model": 0.9 * y}),
        comparison.SeriesPanel("res", "residual", {"before": 0.1 * y, "after": 0.01 * y}),
    ]
    loops = [comparison.XYPanel("loop", "y vs t", "t [s]", "y", {"measured": (t, y)})]
    path = comparison.record_series_comparison(
        tmp_path / "d.rrd", t=t, panels=panels, loops=loops, markdown="# d"
    )
    chunks: dict[str, list[dict[str, Any]]] = {}
    for c in RrdReader(path).stream().collect().stream():
        chunks.setdefault(c.entity_path, []).append(c.to_record_batch().to_pydict())
    got = np.ravel(_temporal(chunks, "/signals/out/final_model", "Scalars:scalars"))
    np.testing.assert_allclose(got, 0.9 * y)
    assert "/signals/res/after" in chunks and "/loops/loop/measured/now" in chunks
    with pytest.raises(InvalidParameterError, match="has 3 values"):
        comparison.record_series_comparison(
            tmp_path / "e.rrd",
            t=t,
            panels=[comparison.SeriesPanel("x", "x", {"a": np.zeros(3)})],
        )


def test_cli_diagnose_writes_a_recording(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = tmp_path / "m.csv"
    assert (
        run_fsarm(
            monkeypatch, "synth", str(data), "--duration", "6", "--effect", "backlash=0.03,0.0"
        )
        == 0
    )
    rrd = tmp_path / "d.rrd"
    assert (
        run_fsarm(monkeypatch, "diagnose", str(data), "--max-effects", "1", "--rrd", str(rrd)) == 0
    )
    assert f"rerun recording: {rrd}" in capsys.readouterr().out
    paths = {c.entity_path for c in RrdReader(rrd).stream().collect().stream()}
    for p in (
        "/signals/output/measured",
        "/signals/output/final",
        "/signals/output/nominal",
        "/signals/residual/before_nominal",
        "/signals/residual/after_final",
        "/loops/residual_before/before_nominal/now",
        "/loops/residual_after/after_final/trace",
    ):
        assert p in paths, p


def test_a_signal_keeps_its_colour_in_every_configuration() -> None:
    """Configurations differ by shade and width; a signal's hue stays (q1 is blue in each)."""
    from fsarm_sim.review.comparison import RUN_STYLES, _shade

    blue = (31, 119, 180)
    shades = [_shade(blue, k) for k in range(len(RUN_STYLES))]
    assert shades[0] == blue and len(set(shades)) == len(shades)
    for c in shades:  # the same hue: blue stays the largest channel, red the smallest
        assert c[2] >= c[1] >= c[0]
