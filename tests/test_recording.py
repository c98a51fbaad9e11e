"""Rerun recordings: written headless, read back with Rerun's own reader (rerun.chunk.RrdReader),
entities, time range and values checked against the run and against independent kinematics."""

from __future__ import annotations

import io
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from PIL import Image as PILImage

from fsarm_sim.engine.model import SimConfig, model_path
from fsarm_sim.errors import FsarmError, InvalidParameterError
from fsarm_sim.review import recording
from fsarm_sim.sim.simulation import RunResult, run_scenario

from conftest import run_fsarm

RrdReader = pytest.importorskip("rerun.chunk").RrdReader

DURATION_S = 1.5
RATE_HZ = 50.0


@pytest.fixture(scope="module")
def run() -> RunResult:
    # p2p-payload: all three joints move (from 0.5 s) and the payload is drawn
    return run_scenario("p2p-payload", duration_s=DURATION_S)


@pytest.fixture(scope="module")
def rrd(run: RunResult, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("rrd") / "p2p.rrd"
    before = {k: v.copy() for k, v in run.columns.items()}
    recording.record_run(run, path, rate_hz=RATE_HZ)
    for k, v in before.items():  # recording reads the columns, never writes them
        np.testing.assert_array_equal(run.columns[k], v, err_msg=k)
    return path


@pytest.fixture(scope="module")
def chunks(rrd: Path) -> dict[str, list[dict[str, Any]]]:
    """entity path -> the record batches (as python dicts) of its chunks."""
    out: dict[str, list[dict[str, Any]]] = {}
    for c in RrdReader(rrd).stream().collect().stream():
        out.setdefault(c.entity_path, []).append(c.to_record_batch().to_pydict())
    return out


def _temporal(
    chunks: dict[str, list[dict[str, Any]]], path: str, column: str
) -> tuple[np.ndarray, list[Any]]:
    """(sim_time in s, values) of a temporal component, concatenated over chunks, sorted."""
    t: list[float] = []
    vals: list[Any] = []
    for b in chunks[path]:
        if "sim_time" in b and column in b:
            t += [
                x.total_seconds() if hasattr(x, "total_seconds") else x * 1e-9
                for x in b["sim_time"]
            ]
            vals += b[column]
    order = np.argsort(t, kind="stable")
    return np.asarray(t)[order], [vals[i] for i in order]


def _static(chunks: dict[str, list[dict[str, Any]]], path: str, column: str) -> Any:
    for b in chunks[path]:
        if "sim_time" not in b and column in b:
            return b[column][0]
    raise AssertionError(f"{path} has no static {column}")


def test_file_holds_one_recording_and_its_blueprint(rrd: Path) -> None:
    reader = RrdReader(rrd)
    recs = reader.recordings()
    assert len(recs) == 1 and recs[0].application_id == recording.APPLICATION_ID
    assert len(reader.blueprints()) == 1


def test_rerun_tool_verifies_the_file(rrd: Path) -> None:
    """Rerun's own command-line tool loads and interprets every chunk (archetypes well-formed)."""
    exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    if not Path(exe).exists():
        pytest.skip("the rerun executable is not installed next to this Python")
    proc = subprocess.run(
        [exe, "rrd", "verify", str(rrd)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_expected_entities(chunks: dict[str, list[dict[str, Any]]]) -> None:
    expected = {
        "/run/metadata",
        "/world/arm/link1",
        "/world/arm/link2",
        "/world/arm/link3",
        "/world/arm/payload",
        "/world/arm/link2/link2_tube",
        "/world/arm/link3/link3_tube",
        "/world/arm/payload/payload_geom",
        "/world/shaft",
        "/loops/torque_twist/plot",
        "/loops/torque_twist/map",
        "/loops/torque_twist/run/now",
        "/loops/torque_twist/run/trace",
        "/loops/bending/plot",
        "/loops/bending/run/now",
        "/loops/bending/run/trace",
    }
    for panel in recording.ARM_PANELS:
        expected |= {f"/{panel.entity}/{s.column}" for s in panel.series}
    missing = expected - set(chunks)
    assert not missing, f"missing entities: {sorted(missing)}"
    text = _static(chunks, "/run/metadata", "TextDocument:text")[0]
    assert "p2p-payload" in text and "fsarm_sim_version" in text and '"payload_kg": 15.0' in text


def test_time_range_and_rate(chunks: dict[str, list[dict[str, Any]]], run: RunResult) -> None:
    t, _ = _temporal(chunks, "/signals/joint3/q3", "Scalars:scalars")
    assert t[0] == 0.0
    assert t[-1] == pytest.approx(run.columns["t"][-1], abs=1e-9)
    assert len(t) == round(DURATION_S * RATE_HZ) + 1
    tb, _ = _temporal(chunks, "/world/arm/link3", "Transform3D:translation")
    np.testing.assert_allclose(tb, t, atol=1e-9)


def test_series_values_match_the_run(
    chunks: dict[str, list[dict[str, Any]]], run: RunResult
) -> None:
    cols = run.columns
    rows = recording.decimate(cols["t"], RATE_HZ)
    cases = {
        "/signals/joint3/q3": np.degrees(cols["q3"][rows]),
        "/signals/joint2/q2_ref": np.degrees(cols["q2_ref"][rows]),
        "/signals/errors/e3": np.degrees(cols["q3"][rows] - cols["q3_ref"][rows]),
        "/signals/shaft_torque/tau_shaft": cols["tau_shaft"][rows],
        "/signals/shaft_torque/tau_model": cols["tau_model"][rows],
        "/signals/speed/omega_d": cols["omega_d"][rows],
        "/signals/pid/pid_i": cols["pid_i"][rows],
    }
    for path, want in cases.items():
        _, vals = _temporal(chunks, path, "Scalars:scalars")
        np.testing.assert_allclose(np.ravel(vals), want, rtol=1e-12, atol=1e-12, err_msg=path)
    _, lim = _temporal(chunks, "/signals/motor_torque/tau_motor_limit_pos", "Scalars:scalars")
    assert np.all(np.ravel(lim) > 0.0) and np.ptp(np.ravel(lim)) == 0.0


def _rot_z(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def _rot_y(a: float) -> np.ndarray:
    return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])


def test_3d_arm_follows_independent_kinematics(
    chunks: dict[str, list[dict[str, Any]]], run: RunResult
) -> None:
    """Flange (payload body) and shaft-route ends from hand-written forward kinematics with the
    MJCF's offsets: q1 about z, q2 and q3 about y."""
    model = mujoco.MjModel.from_xml_path(str(model_path()))
    bpos = {
        n: model.body_pos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n)]
        for n in ("link2", "link3", "payload")
    }
    spos = {
        n: model.site_pos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n)]
        for n in ("shaft_in", "shaft_out")
    }
    hyp = model.body_pos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hypoid_housing")]
    cols = run.columns
    rows = recording.decimate(cols["t"], RATE_HZ)
    _, flange = _temporal(chunks, "/world/arm/payload", "Transform3D:translation")
    _, strips = _temporal(chunks, "/world/shaft", "LineStrips3D:strips")
    assert len(flange) == len(rows) == len(strips)
    moved = 0.0
    for i, r in enumerate(rows):
        q1, q2, q3 = cols["q1"][r], cols["q2"][r], cols["q3"][r]
        rz, r2, r23 = _rot_z(q1), _rot_z(q1) @ _rot_y(q2), _rot_z(q1) @ _rot_y(q2 + q3)
        p2 = rz @ bpos["link2"]
        want_flange = p2 + r2 @ bpos["link3"] + r23 @ bpos["payload"]
        np.testing.assert_allclose(np.ravel(flange[i]), want_flange, atol=1e-9)
        route = np.asarray(strips[i][0], dtype=float).reshape(-1, 3)
        np.testing.assert_allclose(route[0], rz @ spos["shaft_in"], atol=1e-6)
        np.testing.assert_allclose(route[-1], p2 + r2 @ (hyp + spos["shaft_out"]), atol=1e-6)
        # the route arrives along link 2's axis: it bends with q2
        tangent = route[-1] - route[-2]
        axis2 = r2 @ np.array([0.0, 0.0, 1.0])
        assert float(tangent @ axis2) / np.linalg.norm(tangent) > 0.95
        moved = max(
            moved,
            float(
                np.linalg.norm(
                    route[len(route) // 2]
                    - np.asarray(strips[0][0]).reshape(-1, 3)[len(route) // 2]
                )
            ),
        )
    assert moved > 0.01  # joint 2 moves 45 deg in this run: the drawn shaft visibly bends


def test_loops_are_the_recorded_pairs(
    chunks: dict[str, list[dict[str, Any]]], run: RunResult
) -> None:
    """The current point of the bending loop is (φ_B in deg, M = -tau_bend) of every logged row,
    in the plot image's pixels: one affine map per axis (x to the right, y up = pixel v down),
    the one stored beside the image, and every point inside the image."""
    cols = run.columns
    rows = recording.decimate(cols["t"], RATE_HZ)
    _, now = _temporal(chunks, "/loops/bending/run/now", "Points2D:positions")
    px = np.array([np.asarray(p, dtype=float).reshape(-1, 2)[0] for p in now])
    x, m = np.degrees(cols["phi_b"][rows]), -cols["tau_bend"][rows]
    assert len(px) == len(rows)
    for values, pixels in ((x, px[:, 0]), (m, px[:, 1])):
        slope, icpt = np.polyfit(values, pixels, 1)
        np.testing.assert_allclose(pixels, icpt + slope * values, atol=1e-3)
    assert np.polyfit(x, px[:, 0], 1)[0] > 0.0 and np.polyfit(m, px[:, 1], 1)[0] < 0.0
    stored = json.loads(_static(chunks, "/loops/bending/map", "TextDocument:text")[0])
    np.testing.assert_allclose(px[:, 0], stored["u"][0] + stored["u"][1] * x, atol=1e-3)
    np.testing.assert_allclose(px[:, 1], stored["v"][0] + stored["v"][1] * m, atol=1e-3)
    blob = _static(chunks, "/loops/bending/plot", "EncodedImage:blob")
    with PILImage.open(io.BytesIO(bytes(np.asarray(blob[0], dtype=np.uint8)))) as im:
        w, h = im.size
    assert np.all((px >= 0.0) & (px <= [w, h]))
    labels = _temporal(chunks, "/loops/bending/run/now", "Points2D:labels")[1]
    assert f"{x[-1]:.1f}°" in labels[-1][0] and f"{m[-1]:.2f} N·m" in labels[-1][0]
    _, strips = _temporal(chunks, "/loops/bending/run/trace", "LineStrips2D:strips")
    grown = [len(np.asarray(s[0], dtype=float).reshape(-1, 2)) for s in strips]
    assert grown == sorted(grown) and grown[-1] > 10  # the loop grows up to the cursor


def test_blueprint_leaves_out_panels_without_information() -> None:
    """fig14-sine holds joints 1 and 2: no joint-1/2 angle panels, no bending loop or bending
    time series; p2p-payload moves every joint: all of them."""
    held = run_scenario("fig14-sine", duration_s=0.3, backend="native")
    cols = recording.with_derived(held.columns)
    names = {p.name for p in recording.informative_panels(cols, recording.ARM_PANELS)}
    assert {"joint1", "joint2", "bending"}.isdisjoint(names)
    assert {"joint3", "errors", "shaft_torque", "twist_bend"} <= names
    loops = [lp.name for lp in recording.ARM_LOOPS if recording.loop_is_informative(lp, cols)]
    assert loops == ["torque_twist"]


def test_moving_run_keeps_every_panel(run: RunResult) -> None:
    cols = recording.with_derived(run.columns, tau_motor_limit_nm=1.0)
    names = [p.name for p in recording.informative_panels(cols, recording.ARM_PANELS)]
    assert names == [p.name for p in recording.ARM_PANELS]
    assert all(recording.loop_is_informative(lp, cols) for lp in recording.ARM_LOOPS)


def test_decimate() -> None:
    t = np.arange(0.0, 1.0005, 0.001)
    rows = recording.decimate(t, 100.0)
    assert rows[0] == 0 and rows[-1] == len(t) - 1 and len(rows) == 101
    assert len(recording.decimate(t, None)) == len(t)
    np.testing.assert_array_equal(recording.decimate(t[:-3], 100.0)[-2:], [990, len(t) - 4])
    for bad in (0.0, -5.0, math.nan, math.inf):
        with pytest.raises(InvalidParameterError, match="recording rate"):
            recording.decimate(t, bad)


def test_spawn_without_display_reports_instead_of_raising(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    msg = recording.spawn_viewer(tmp_path / "x.rrd")
    assert msg.startswith("no viewer opened") and "x.rrd" in msg


def test_cli_run_writes_recording_and_figures(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    rrd = tmp_path / "r" / "step.rrd"
    code = run_fsarm(
        monkeypatch,
        "run",
        "step-q3",
        "--duration",
        "0.3",
        "--out",
        str(tmp_path / "runs"),
        "--rrd",
        str(rrd),
        "--rrd-rate",
        "20",
        "--spawn",
        "--figures",
        str(tmp_path / "figs"),
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "no viewer opened" in out or "viewer started" in out
    assert len(RrdReader(rrd).recordings()) == 1
    written = {p.stem.removeprefix("step-q3_") for p in (tmp_path / "figs").iterdir()}
    left_out = {
        line.split()[1] for line in out.splitlines() if line.startswith("no ") and "figure" in line
    }
    assert "tracking" in written  # the others only where the run moves the shaft enough
    assert written | left_out == {"bending", "torque_twist", "tracking"}


def test_cli_rejects_bad_rate_before_running(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = run_fsarm(monkeypatch, "run", "step-q3", "--out", str(tmp_path), "--rrd-rate", "0")
    assert code == 2
    assert "--rrd-rate" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())  # failed before the run wrote anything
    assert issubclass(InvalidParameterError, FsarmError)


def test_the_transmissions_own_states_get_their_panel(
    chunks: dict[str, list[dict[str, Any]]], run: RunResult
) -> None:
    """The shaft's slip elements (its STATES) and the conduit branches, at the recorded rows."""
    assert set(run.states) == {"slip1", "slip2", "slip3", "conduit_branch1", "conduit_branch2"}
    assert all(len(v) == len(run.columns["t"]) for v in run.states.values())
    assert any(np.ptp(run.states[f"slip{i}"]) > 0.0 for i in (1, 2, 3))  # they slip and stick
    panels = {p.name: p for p in recording.state_panels(run)}
    assert set(panels) == {"transmission_states", "conduit_states"}
    t, values = _temporal(chunks, "/signals/transmission_states/state_slip1", "Scalars:scalars")
    i = np.searchsorted(run.columns["t"], t[-1])
    assert float(np.ravel(values[-1])[0]) == pytest.approx(run.states["slip1"][i])
    qa = run_scenario("step-q3", SimConfig(transmission="qa-joint"), duration_s=0.2)
    assert set(qa.states) == {"sigma_rad", "z_friction", "conduit_branch1", "conduit_branch2"}
    assert next(p.name for p in recording.state_panels(qa)) == "transmission_states"


def _legend_box_points(lay: recording.SeriesLayout, curves: list[recording.Curve]) -> int:
    """Data points inside the legend's box (plot coordinates 0..1 on both axes)."""
    assert lay.corner is not None
    t = np.concatenate([c[0] for c in curves])
    y = np.concatenate([c[1] for c in curves])
    u = (t - t.min()) / (t.max() - t.min())
    v = (y - lay.y_range[0]) / (lay.y_range[1] - lay.y_range[0])
    w, h = lay.legend_share
    in_x = u >= 1 - w if lay.corner.startswith("Right") else u <= w
    in_y = v >= 1 - h if lay.corner.endswith("Top") else v <= h
    return int(np.count_nonzero(in_x & in_y))


def test_legend_stands_off_the_data() -> None:
    """A legend goes to a corner the data leave free; where none is free (a signal filling the
    whole plot), the y range grows so the legend has rows of its own. The range holds the data."""
    t = np.linspace(0.0, 7.0, 701)
    rising = [(t, t / 7.0, "ramp"), (t, t / 7.0 - 0.1, "ramp ref")]  # free: top left
    lay = recording.series_layout(rising)
    assert lay.corner == "LeftTop" and _legend_box_points(lay, rising) == 0
    assert lay.y_range[0] < -0.1 and lay.y_range[1] > 1.0
    noise = np.random.default_rng(0).uniform(-1.0, 1.0, (3, len(t)))
    full = [(t, noise[k], f"signal {k}") for k in range(3)]  # every corner has data
    lay = recording.series_layout(full)
    assert lay.corner is not None and _legend_box_points(lay, full) == 0
    assert lay.y_range[1] - lay.y_range[0] > 2.5  # grown beyond the data's 2.0 (+ margins)
    one = recording.series_layout([(t, np.sin(t), "q3")])
    assert one.corner is None  # one curve: the title names it, no legend over it


def test_panels_stand_in_tabs_of_a_group() -> None:
    tabs = recording.panel_tabs(recording.ARM_PANELS)
    assert [name for name, _ in tabs] == ["tracking", "shaft", "control"]
    assert all(1 <= len(ps) <= recording.PANELS_PER_TAB for _, ps in tabs)
    assert [p for _, ps in tabs for p in ps] == list(recording.ARM_PANELS)
    assert recording.shown_panels(recording.ARM_PANELS) == list(recording.ARM_PANELS[:4])
