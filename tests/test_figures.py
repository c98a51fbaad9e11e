"""Static figures: generated small, real PNG/SVG files, drawing exactly the run's data."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from fsarm_sim import cli
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.review import figures
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import RunResult, run_scenario

SMALL = (3.2, 2.2)  # inches
DPI = 50


@pytest.fixture(scope="module")
def p2p() -> RunResult:
    """The whole p2p-payload run: joint 2 bends the shaft 15 -> 60 -> 15 deg (a closed cycle)."""
    return run_scenario("p2p-payload")


def _png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    w, h = struct.unpack(">II", head[16:24])
    return int(w), int(h)


def _assert_nontrivial_png(path: Path) -> None:
    assert path.stat().st_size > 3000, f"{path} is suspiciously small"
    assert _png_size(path) == (round(SMALL[0] * DPI), round(SMALL[1] * DPI))
    img = matplotlib.image.imread(path)
    assert float(img[..., :3].std()) > 0.05  # not a blank canvas


def test_run_figures_are_small_nontrivial_pngs(p2p: RunResult, tmp_path: Path) -> None:
    paths = figures.run_figures(p2p, tmp_path, dpi=DPI, size_in=SMALL)
    assert [p.name for p in paths] == [f"p2p-payload_{k}.png" for k in figures.FIGURE_KINDS]
    for p in paths:
        _assert_nontrivial_png(p)


def test_svg_output(p2p: RunResult, tmp_path: Path) -> None:
    fig = figures.tracking_figure(p2p.columns, size_in=SMALL)
    (svg,) = figures.save_figure(fig, tmp_path / "t", formats=("svg",))
    text = svg.read_text("utf-8")
    assert text.lstrip().startswith("<?xml") and "<svg" in text


def test_tracking_draws_the_columns_in_degrees(p2p: RunResult) -> None:
    cols = p2p.columns
    fig = figures.tracking_figure(cols, joints=[3], size_in=SMALL)
    top, bottom = fig.axes
    actual, desired = top.lines[0], top.lines[1]
    np.testing.assert_allclose(actual.get_ydata(), np.degrees(cols["q3"]))
    np.testing.assert_allclose(desired.get_ydata(), np.degrees(cols["q3_ref"]))
    np.testing.assert_allclose(bottom.lines[0].get_ydata(), np.degrees(cols["q3"] - cols["q3_ref"]))


def test_moving_joints_picks_what_moves(p2p: RunResult) -> None:
    assert figures.moving_joints(p2p.columns) == [1, 2, 3]
    fig14 = run_scenario("fig14-sine", duration_s=0.2).columns
    assert figures.moving_joints(fig14) == [3]
    # default joints: the moving ones (one solid + one dashed line each)
    assert len(figures.tracking_figure(p2p.columns, size_in=SMALL).axes[0].lines) == 6


def test_bending_loop_is_fig9_sign_and_dissipates(p2p: RunResult) -> None:
    """M = -tau_bend rises with the bend (Fig. 9's slope), and the closed 15 -> 60 -> 15 deg
    cycle encloses positive area: the conduit's visco-elastic hysteresis absorbs energy."""
    cols = p2p.columns
    ax = figures.bending_figure(cols, size_in=SMALL).axes[0]
    x = np.asarray(ax.lines[0].get_xdata(), dtype=float)
    m = np.asarray(ax.lines[0].get_ydata(), dtype=float)
    np.testing.assert_allclose(m, -cols["tau_bend"])
    np.testing.assert_allclose(x, np.degrees(cols["phi_b"]))
    slope = np.polyfit(x, m, 1)[0]
    assert slope > 0.0
    work_in = float(np.sum(0.5 * (m[1:] + m[:-1]) * np.diff(np.radians(x))))  # closed-cycle ∮M dφ
    assert abs(x[-1] - x[0]) < 0.5  # the cycle is closed (back to 15 deg)
    assert work_in > 0.0
    # without the conduit (dashed curve) the elastic moment is conservative: ~no area
    e = np.asarray(ax.lines[1].get_ydata(), dtype=float)
    work_elastic = float(np.sum(0.5 * (e[1:] + e[:-1]) * np.diff(np.radians(x))))
    assert abs(work_elastic) < 0.1 * work_in


def test_torque_twist_reuses_generic_columns() -> None:
    """Bench-style column names: the function takes them as parameters."""
    twist = np.radians(np.concatenate([np.linspace(-2, 2, 50), np.linspace(2, -2, 50)]))
    torque = 20.0 * twist + np.concatenate([np.full(50, -0.1), np.full(50, 0.1)])
    ax = figures.torque_twist_figure(
        {"dtheta": twist, "tau_out": torque},
        twist="dtheta",
        torque="tau_out",
        model_torque=None,
        bend=None,
        size_in=SMALL,
    ).axes[0]
    assert len(ax.lines) >= 1
    np.testing.assert_allclose(ax.lines[0].get_xdata(), np.degrees(twist))


def test_named_errors() -> None:
    with pytest.raises(InvalidParameterError, match="column 'q3'"):
        figures.tracking_figure({"t": np.zeros(3)}, joints=[3])
    with pytest.raises(InvalidParameterError, match="at least one curve"):
        figures.loops_figure([], xlabel="x", ylabel="y", title="t")
    with pytest.raises(InvalidParameterError, match="formats"):
        figures.check_output(["jpg"], 100)
    with pytest.raises(InvalidParameterError, match="dpi"):
        figures.check_output(["png"], 0)


def test_figures_command_covers_every_scenario(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every scenario's every figure is written, or left out with its reason printed."""
    monkeypatch.setattr(
        sys,
        "argv",
        [
            "fsarm",
            "figures",
            "--out",
            str(tmp_path),
            "--duration",
            "0.3",
            "--dpi",
            str(DPI),
            "--width",
            str(SMALL[0]),
            "--height",
            str(SMALL[1]),
        ],
    )
    try:
        cli.main()
    except SystemExit as exc:
        assert not exc.code
    every = {f"{s}_{k}" for s in scenarios.REGISTRY for k in figures.FIGURE_KINDS}
    written = {p.stem for p in tmp_path.iterdir()}
    out = capsys.readouterr().out
    left_out = {line.split()[1] for line in out.splitlines() if line.startswith("no ")}
    assert written | left_out == every and not written & left_out
    assert "fig14-sine_bending" in left_out and "fig14-sine_tracking" in written
    for name in (f"{w}.png" for w in written):
        assert _png_size(tmp_path / name) == (round(SMALL[0] * DPI), round(SMALL[1] * DPI))


def test_figures_without_information_are_left_out_with_a_reason(tmp_path: Path) -> None:
    """fig14-sine holds the bend at 45°: its bending 'loop' would be a dot, so no file, and the
    reason says so; p2p-payload moves joint 2, so its bending figure is written."""
    fig14 = run_scenario("fig14-sine", duration_s=0.5)
    skipped: dict[str, str] = {}
    paths = figures.run_figures(fig14, tmp_path, dpi=DPI, size_in=SMALL, skipped=skipped)
    assert [p.name for p in paths] == ["fig14-sine_tracking.png", "fig14-sine_torque_twist.png"]
    assert set(skipped) == {"bending"} and "held at 45.0°" in skipped["bending"]
    assert figures.skip_reason("bending", {"phi_b": np.linspace(0.0, 0.5, 20)}) == ""
