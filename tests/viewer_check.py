"""Open a recording in Rerun's own web viewer, take a screenshot and check what a person would see.

The recording is served by the ``rerun`` binary that ships with the installed rerun-sdk
(``rerun --serve-web FILE --bind 127.0.0.1``; the real binary, not the Python wrapper, so that
stopping it stops the server) and opened in headless Chromium from the system packages (Debian:
``apt-get install chromium``), driven by Playwright with software WebGL2 (SwiftShader) and every
host but localhost blocked. :func:`screenshot` waits until the picture is complete (all views
drawn, two screenshots in a row the same) and returns it with its views found.

The views are found in the picture itself (:func:`find_views`): Rerun separates the tiles of a
blueprint by one-pixel lines of one grey, so the screenshot is split recursively at lines that
cross a whole tile, the way the blueprint's containers nest. :func:`check_views` then says, per
view, whether it is blank, and for a loop panel (a plot image with a black axes frame,
:mod:`fsarm_sim.review.loop_plot`) how much of the frame its data (blue) fill.

Nothing here changes a recording; it needs ``playwright`` (a dev dependency) and a Chromium
executable (``FSARM_CHROMIUM`` or ``/usr/bin/chromium``); without one it raises
:class:`ViewerCheckError` naming what is missing and how to install it.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError

Image = npt.NDArray[np.uint8]  # (h, w, 3) RGB

CHROMIUM_CANDIDATES = ("/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome")
CHROMIUM_FLAGS = (
    "--use-angle=swiftshader",  # software WebGL2 (--use-gl=swiftshader is refused by Chromium)
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1, EXCLUDE localhost",
    "--no-sandbox",  # CI runs as root
)
VIEWPORT = (1600, 1000)
SEPARATOR_RGB = (223, 223, 223)  # Rerun's light theme: the line between tiles
SEPARATOR_TOL = 6
TITLE_BAR_PX = 26  # a view's title bar (excluded from its content)
MIN_VIEW_PX = (120, 80)  # smaller tiles are the top bar, the time bar, ...
INK_DIFF = 40  # a pixel differs from the background by more than this in some channel
SATURATION = 60  # max - min channel above this: a coloured pixel (a curve, the arm)


class ViewerCheckError(FsarmError):
    """The viewer check cannot run (no browser, no rerun binary) or the viewer showed no data."""


# --------------------------------------------------------------------------- executables


def rerun_binary() -> Path:
    """The ``rerun`` executable shipped inside the installed rerun-sdk (``rerun_cli/rerun``)."""
    try:
        import rerun_cli
    except ImportError:
        raise ViewerCheckError(
            "rerun-sdk's command-line package (rerun_cli) is not installed"
        ) from None
    exe = Path(rerun_cli.__file__).with_name("rerun")
    if not exe.exists():
        raise ViewerCheckError(f"the rerun binary is missing from the installed rerun-sdk: {exe}")
    return exe


def chromium_executable() -> Path:
    """Chromium from the system packages (``FSARM_CHROMIUM`` overrides the path)."""
    env = os.environ.get("FSARM_CHROMIUM")
    candidates = [env] if env else [*CHROMIUM_CANDIDATES, shutil.which("chromium") or ""]
    for c in candidates:
        if c and Path(c).exists():
            return Path(c)
    raise ViewerCheckError(
        "no Chromium browser for the viewer check: install Debian's package "
        "(`apt-get install -y chromium`; scripts/setup_env.sh does it when run as root) or set "
        f"FSARM_CHROMIUM to a Chromium executable (looked for {', '.join(candidates)})"
    )


def _playwright() -> Any:
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        raise ViewerCheckError(
            "the viewer check needs playwright (a dev dependency): "
            "`.venv/bin/pip install -c requirements.lock -e .[dev]`"
        ) from None
    return sync_playwright


# --------------------------------------------------------------------------- serving


@contextmanager
def serve(rrd: Path, timeout_s: float = 20.0) -> Iterator[str]:
    """Serve ``rrd`` with Rerun's web viewer on 127.0.0.1; yield the URL that opens it."""
    rrd = Path(rrd)
    if not rrd.is_file():
        raise ViewerCheckError(f"no recording at {rrd}")
    cmd = [
        str(rerun_binary()),
        "--serve-web",
        str(rrd),
        "--bind",
        "127.0.0.1",
        "--web-viewer-port",
        "0",
        "--port",
        "0",
        "--threads",
        "1",
    ]
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "RUST_LOG": "info", "NO_COLOR": "1"},
    )
    lines: list[str] = []
    found = threading.Event()
    url: list[str] = []

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:  # keep draining: a full pipe would block the server
            lines.append(line)
            m = re.search(r"connect at (http://\S+)", line)
            if m and not found.is_set():
                url.append(m.group(1))
                found.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        if not found.wait(timeout_s):
            raise ViewerCheckError(
                f"`{' '.join(cmd)}` printed no web-viewer address in {timeout_s:g} s:\n"
                + "".join(lines[-20:])
            )
        yield url[0]
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


# --------------------------------------------------------------------------- finding the views


@dataclass(frozen=True)
class Box:
    """A rectangle of the screenshot, pixels: x0 <= x < x1, y0 <= y < y1."""

    x0: int
    y0: int
    x1: int
    y1: int

    @property
    def width(self) -> int:
        return self.x1 - self.x0

    @property
    def height(self) -> int:
        return self.y1 - self.y0

    def crop(self, img: Image) -> Image:
        return img[self.y0 : self.y1, self.x0 : self.x1]


def _separator_mask(img: Image) -> npt.NDArray[np.bool_]:
    diff = np.abs(img.astype(np.int16) - np.array(SEPARATOR_RGB, dtype=np.int16))
    return np.all(diff <= SEPARATOR_TOL, axis=-1)


def _runs(flags: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Runs of True as (start, stop)."""
    d = np.diff(np.concatenate([[0], np.asarray(flags, dtype=np.int8), [0]]))
    return list(zip(np.nonzero(d == 1)[0].tolist(), np.nonzero(d == -1)[0].tolist(), strict=True))


def _split(mask: npt.NDArray[np.bool_], box: Box, depth: int, out: list[Box]) -> None:
    sub = mask[box.y0 : box.y1, box.x0 : box.x1]
    if depth > 12 or sub.size == 0:
        out.append(box)
        return
    for axis in (1, 0):  # columns (vertical lines) first, then rows
        full = sub.mean(axis=0 if axis == 1 else 1) >= 0.97
        n = len(full)
        cuts = [(a, b) for a, b in _runs(full) if a > 2 and b < n - 2]
        if not cuts:
            continue
        edges = [0]
        for a, b in cuts:
            edges += [a, b]
        edges.append(n)
        pieces = []
        for lo, hi in zip(edges[::2], edges[1::2], strict=True):
            if hi - lo < 3:
                continue
            if axis == 1:
                pieces.append(Box(box.x0 + lo, box.y0, box.x0 + hi, box.y1))
            else:
                pieces.append(Box(box.x0, box.y0 + lo, box.x1, box.y0 + hi))
        if len(pieces) > 1:
            for p in pieces:
                _split(mask, p, depth + 1, out)
            return
    out.append(box)


def find_views(img: Image) -> list[Box]:
    """The tiles of the viewer's blueprint in a screenshot, top-left first (row-major by tile
    origin); the top bar, the time bar and slivers are left out."""
    tiles: list[Box] = []
    _split(_separator_mask(img), Box(0, 0, img.shape[1], img.shape[0]), 0, tiles)
    views = [
        b
        for b in tiles
        if b.width >= MIN_VIEW_PX[0]
        and b.height >= MIN_VIEW_PX[1]
        and np.ptp(b.crop(img).reshape(-1, 3), axis=0).max() > 0  # an empty grid cell is uniform
    ]
    return sorted(views, key=lambda b: (b.x0, b.y0))


# --------------------------------------------------------------------------- judging a view


@dataclass(frozen=True)
class ViewReport:
    """What one view shows: ink (anything unlike the background) and colour, as shares of its
    content area; for a loop panel the axes frame and the share of it the data span."""

    box: Box
    ink: float
    colour: float
    axes: Box | None = None
    data_share: tuple[float, float] | None = None  # (x, y) span of the data / span of the axes

    @property
    def blank(self) -> bool:
        """Nothing drawn in the content area (a text view has ink but no colour)."""
        return self.ink < 0.002

    @property
    def coloured(self) -> bool:
        """Curves, the arm or a plot drawn (text alone is black on white)."""
        return self.colour >= 0.0005

    @property
    def is_loop(self) -> bool:
        return self.axes is not None


def _content(img: Image, box: Box) -> Image:
    return img[box.y0 + TITLE_BAR_PX : box.y1 - 2, box.x0 + 2 : box.x1 - 2]


def _axes_frame(content: Image) -> Box | None:
    """A matplotlib axes frame in the view: its top and bottom spines, the outermost dark
    horizontal lines at least 35 % of the view wide that start and end at the same columns
    (vertical spines may be covered by a label); None when there is none."""
    dark = np.all(content < 180, axis=-1)
    h, w = dark.shape
    lines = []
    for y in range(h):
        runs = [(s, e) for s, e in _runs(dark[y]) if e - s >= 0.35 * w]
        if runs:
            lines.append((y, *max(runs, key=lambda r: r[1] - r[0])))
    if len(lines) < 2:
        return None
    (y0, s0, e0), (y1, s1, e1) = lines[0], lines[-1]
    if abs(s0 - s1) > 3 or abs(e0 - e1) > 3 or y1 - y0 < 0.1 * h:
        return None
    return Box(min(s0, s1), y0, max(e0, e1), y1 + 1)


def _bluish(px: Image) -> npt.NDArray[np.bool_]:
    p = px.astype(np.int16)
    r, g, b = p[..., 0], p[..., 1], p[..., 2]
    return (b - r > 35) & (b > g) & (b > 120)


def judge_view(img: Image, box: Box) -> ViewReport:
    """Ink and colour shares of a view's content; for a loop panel also its data share."""
    c = _content(img, box)
    if c.size == 0:
        return ViewReport(box, 0.0, 0.0)
    flat = c.reshape(-1, 3).astype(np.int32)
    code = (flat[:, 0] << 16) | (flat[:, 1] << 8) | flat[:, 2]
    values, counts = np.unique(code, return_counts=True)
    mode = int(values[int(np.argmax(counts))])
    bg = np.array([mode >> 16, (mode >> 8) & 255, mode & 255], dtype=np.int32)
    ink = float(np.mean(np.any(np.abs(flat - bg) > INK_DIFF, axis=-1)))
    colour = float(np.mean((flat.max(axis=-1) - flat.min(axis=-1)) > SATURATION))
    frame = _axes_frame(c)
    if frame is None:
        return ViewReport(box, ink, colour)
    inner = c[frame.y0 + 2 : frame.y1 - 2, frame.x0 + 2 : frame.x1 - 2]
    ys, xs = np.nonzero(_bluish(inner))
    share = (
        (float(np.ptp(xs)) / inner.shape[1], float(np.ptp(ys)) / inner.shape[0])
        if len(xs) > 1
        else (0.0, 0.0)
    )
    ax_box = Box(
        box.x0 + 2 + frame.x0,
        box.y0 + TITLE_BAR_PX + frame.y0,
        box.x0 + 2 + frame.x1,
        box.y0 + TITLE_BAR_PX + frame.y1,
    )
    return ViewReport(box, ink, colour, ax_box, share)


@dataclass
class Shot:
    """A screenshot of the viewer and what was found in it."""

    png: bytes
    image: Image
    views: list[ViewReport] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def loops(self) -> list[ViewReport]:
        return [v for v in self.views if v.is_loop]

    @property
    def blank(self) -> list[ViewReport]:
        return [v for v in self.views if v.blank]

    @property
    def colourless(self) -> list[ViewReport]:
        return [v for v in self.views if not v.coloured]


def _decode(png: bytes) -> Image:
    import io

    from PIL import Image as PILImage

    with PILImage.open(io.BytesIO(png)) as im:
        return np.asarray(im.convert("RGB"), dtype=np.uint8)


def analyse(png: bytes) -> Shot:
    img = _decode(png)
    return Shot(png, img, [judge_view(img, b) for b in find_views(img)])


def screenshot(
    rrd: Path,
    *,
    expected_views: int | None = None,
    text_views: int = 1,
    viewport: tuple[int, int] = VIEWPORT,
    timeout_s: float = 60.0,
    settle_s: float = 1.5,
) -> Shot:
    """Open ``rrd`` in Rerun's web viewer (headless Chromium) and return the first screenshot
    that is complete: ``expected_views`` views found (when given), none blank, no more than
    ``text_views`` without colour (data not loaded yet shows as empty plots), and the picture
    unchanged over ``settle_s``. On timeout, the last screenshot is returned as it is (the caller
    judges it; :attr:`Shot.blank` says what is missing)."""
    chromium = chromium_executable()
    sync_playwright = _playwright()
    t0 = time.monotonic()
    with serve(rrd) as url, sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=str(chromium), headless=True, args=list(CHROMIUM_FLAGS)
        )
        try:
            page = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
            # one render of the software-WebGL viewer can take longer than Playwright's 30 s
            # default on a loaded machine: each page action gets the caller's whole budget
            page.set_default_timeout(timeout_s * 1000.0)
            page.goto(url)
            last: bytes | None = None
            shot = analyse(page.screenshot())
            while time.monotonic() - t0 < timeout_s:
                time.sleep(settle_s)
                png = page.screenshot()
                shot = analyse(png)
                complete = (
                    not shot.blank
                    and len(shot.colourless) <= text_views
                    and (expected_views is None or len(shot.views) == expected_views)
                )
                if complete and last is not None and _same(last, png):
                    break
                last = png if complete else None
        finally:
            browser.close()
    shot.seconds = time.monotonic() - t0
    return shot


def _same(a: bytes, b: bytes) -> bool:
    if a == b:
        return True
    ia, ib = _decode(a), _decode(b)
    return ia.shape == ib.shape and float(np.mean(np.any(ia != ib, axis=-1))) < 0.001
