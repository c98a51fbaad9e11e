"""The recording as a person sees it: fig14-sine opened in Rerun's own web viewer (served by the
``rerun`` binary on localhost) in headless Chromium; the screenshot is split into the blueprint's
views and each is judged (not blank; the loop panel's data fill its axes).

A missing browser is a failure with the install command, not a skip: ``scripts/setup_env.sh``
installs Debian's ``chromium`` when run as root (CI), or set ``FSARM_CHROMIUM``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import viewer_check
from fsarm_sim.review import recording
from fsarm_sim.sim.simulation import run_scenario
from viewer_check import Box, ViewerCheckError

SEP = viewer_check.SEPARATOR_RGB


def _synthetic() -> np.ndarray:
    """A 400 x 300 'viewer': top bar, a left view, a right column split into a loop-like view
    (black axes frame, blue data over 60 % x 50 % of it) and an empty grid cell."""
    img = np.full((300, 400, 3), 255, dtype=np.uint8)
    img[35, :] = SEP  # under the top bar
    img[36:, 150] = SEP  # left | right
    img[160, 151:] = SEP  # right: top | bottom
    img[45:50, 10:60] = 40  # left view: a title
    img[100:200, 20:120] = (31, 119, 180)  # ... and a coloured plot
    img[45:50, 160:220] = 40  # loop view: a title
    x0, y0, x1, y1 = 180, 70, 380, 150  # its axes frame
    img[y0, x0:x1] = 0
    img[y1, x0:x1] = 0
    img[y0:y1, x0] = 0
    img[y0:y1, x1 - 1] = 0
    img[100:140, 220:340] = (31, 119, 180)  # data: 120 of 196 px wide, 40 of 76 px high
    img[36:, 151:][125:] = 255  # bottom right: an empty cell
    img[160, 151:] = SEP
    return img


def test_find_views_splits_at_separator_lines() -> None:
    img = _synthetic()
    views = viewer_check.find_views(img)
    assert views == [Box(0, 36, 150, 300), Box(151, 36, 400, 160)]  # the empty cell is left out
    left, loop = (viewer_check.judge_view(img, b) for b in views)
    assert not left.blank and left.coloured and not left.is_loop
    assert loop.is_loop and loop.axes == Box(180, 70, 380, 151)
    assert loop.data_share is not None
    assert loop.data_share[0] == pytest.approx(119 / 196) and loop.data_share[1] == pytest.approx(
        39 / 77
    )


def test_blank_view_is_reported() -> None:
    img = _synthetic()
    img[70:160, 152:400] = 255  # the loop view loses its plot, keeps its title bar
    views = viewer_check.find_views(img)
    report = viewer_check.judge_view(img, views[1])
    assert report.blank and not report.is_loop


def test_missing_browser_is_a_named_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("FSARM_CHROMIUM", str(tmp_path / "no-such-chromium"))
    with pytest.raises(ViewerCheckError, match="apt-get install -y chromium"):
        viewer_check.chromium_executable()


def test_rerun_binary_is_the_real_one() -> None:
    exe = viewer_check.rerun_binary()
    assert exe.name == "rerun" and exe.parent.name == "rerun_cli"
    assert exe.read_bytes()[:4] == b"\x7fELF" or exe.stat().st_size > 1_000_000


@pytest.fixture(scope="module")
def fig14_shot(tmp_path_factory: pytest.TempPathFactory) -> tuple[viewer_check.Shot, int]:
    viewer_check.chromium_executable()  # fail here, with the install command, when missing
    result = run_scenario("fig14-sine", duration_s=2.0, backend="native")
    path = tmp_path_factory.mktemp("viewer") / "fig14-sine.rrd"
    recording.record_run(result, path, rate_hz=50.0)
    cols = recording.with_derived(result.columns)
    n_loops = sum(recording.loop_is_informative(lp, cols) for lp in recording.ARM_LOOPS)
    # 3-D arm + metadata + loops + time series
    expected = 2 + n_loops + len(recording.shown_panels(recording.run_panels(result)))
    shot = viewer_check.screenshot(path, expected_views=expected, timeout_s=150.0)
    (path.parent / "fig14-sine.png").write_bytes(shot.png)
    keep = os.environ.get("FSARM_VIEWER_SHOTS")
    if keep:
        Path(keep).mkdir(parents=True, exist_ok=True)
        shutil.copy(path.parent / "fig14-sine.png", Path(keep) / "test_viewer_fig14-sine.png")
    return shot, expected


def test_viewer_shows_every_view_of_the_blueprint(
    fig14_shot: tuple[viewer_check.Shot, int],
) -> None:
    shot, expected = fig14_shot
    where = "; ".join(f"{v.box} ink {v.ink:.4f} colour {v.colour:.4f}" for v in shot.views)
    assert len(shot.views) == expected, f"{len(shot.views)} views found ({where})"
    assert not shot.blank, f"blank views: {[v.box for v in shot.blank]}"
    # only the metadata page is text without colour; every plot, the arm and the loop have data
    assert len(shot.colourless) == 1, where


def test_viewer_loop_panel_is_framed_to_its_data(
    fig14_shot: tuple[viewer_check.Shot, int],
) -> None:
    shot, _ = fig14_shot
    loops = shot.loops
    assert len(loops) == 1, "fig14-sine holds the bend: only the torque-twist loop is shown"
    share = loops[0].data_share
    assert share is not None
    assert share[0] >= 0.6 and share[1] >= 0.6, f"the loop fills {share} of its axes"
    ax = loops[0].axes
    assert ax is not None
    assert ax.width >= 0.5 * loops[0].box.width  # the plot, not a corner of the panel
