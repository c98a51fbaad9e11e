"""Loop panels for the Rerun viewer: an x-y plot (torque vs twist, moment vs bend) rendered once as
an image with real axes, plus the map from data units to the image's pixels.

Rerun's 2-D spatial view has no axes, ticks or numbers, and it keeps x and y at the same scale
(a loop of ±20° against ±0.5 N·m would be a flat line). So the loop's frame - axes through zero,
ticks and numbers in the panel's units, grid, title, a legend kept outside the axes - is drawn by
matplotlib (:func:`render_loop`) and logged as a static image; what changes with time (the loop
up to the cursor, the current point) is logged natively on top of the image, in its pixel
coordinates (:meth:`LoopImage.to_pixels`), so it stays crisp and follows the time cursor.

The frame is fitted to the data and holds the origin where that keeps the data over at least
half of it (:func:`frame`); the axes through zero are drawn wherever zero is in view.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from fsarm_sim.errors import InvalidParameterError

Array = npt.NDArray[np.float64]

MARGIN = 0.06  # share of the data span left free on each side of the frame
MIN_SPAN = 1e-9  # a frame is never narrower than this (data units)
DEFAULT_SIZE_PX = (620, 460)  # rendered size; the viewer scales it to the panel
DPI = 100.0


@dataclass(frozen=True)
class LoopCurve:
    """A curve drawn into the image (values in the axes' units; matplotlib colour and style)."""

    x: Array
    y: Array
    label: str
    color: str
    style: str = "-"
    width: float = 1.4
    alpha: float = 1.0
    in_legend: bool = True


@dataclass(frozen=True)
class LegendEntry:
    """A legend line for something drawn natively over the image (the growing loop, the marker)."""

    label: str
    color: str
    style: str = "-"
    width: float = 2.5
    marker: str | None = None


@dataclass(frozen=True)
class LoopImage:
    """The rendered plot: PNG bytes, its size in pixels and the affine map data -> pixel."""

    png: bytes
    width: int
    height: int
    x_range: tuple[float, float]
    y_range: tuple[float, float]
    # pixel (u, v) = (ax + bx * x, ay + by * y); v grows downwards as in the image
    ax: float
    bx: float
    ay: float
    by: float

    def to_pixels(self, x: Array, y: Array) -> Array:
        """Data -> image pixel coordinates, shape (n, 2) (u to the right, v down)."""
        xs = np.asarray(x, dtype=np.float64)
        ys = np.asarray(y, dtype=np.float64)
        return np.stack([self.ax + self.bx * xs, self.ay + self.by * ys], axis=-1)


def _finite(values: Sequence[Array]) -> Array:
    if not values:
        return np.zeros(0)
    v = np.concatenate([np.ravel(np.asarray(a, dtype=np.float64)) for a in values])
    return v[np.isfinite(v)]


def frame(values: Sequence[Array], margin: float = MARGIN) -> tuple[float, float]:
    """The axis range of ``values``: their span, widened by ``margin`` of the span on each side.

    Zero is brought into view (so the axes through zero show) when that at most doubles the
    span; a loop far from the origin (a preloaded shaft, a bent arm) is framed to itself and keeps
    the data over at least half the frame."""
    v = _finite(values)
    if not len(v):
        return -1.0, 1.0
    lo, hi = float(v.min()), float(v.max())
    span = hi - lo
    if lo > 0.0 and lo <= span:
        lo = 0.0
    elif hi < 0.0 and -hi <= span:
        hi = 0.0
    span = max(hi - lo, MIN_SPAN, 1e-6 * max(abs(lo), abs(hi)))
    return lo - margin * span, hi + margin * span


def _legend_handles(drawn: list[Line2D], overlay: Sequence[LegendEntry]) -> list[Line2D]:
    """The legend's entries: the overlay's traces first, then the drawn curves, then markers."""
    handles: list[Line2D] = []
    for e in sorted(overlay, key=lambda e: e.marker is not None):
        handles.append(
            Line2D(
                [],
                [],
                linestyle=cast(Any, e.style),
                color=e.color,
                lw=e.width,
                marker=e.marker,
                markersize=8,
                label=e.label,
            )
        )
    n_lines = sum(e.marker is None for e in overlay)
    handles[n_lines:n_lines] = drawn
    return handles


def _image(
    fig: Figure,
    canvas: FigureCanvasAgg,
    ax: Any,
    xr: tuple[float, float],
    yr: tuple[float, float],
    title: str,
) -> LoopImage:
    """The drawn figure as PNG bytes with its affine map data -> pixel."""
    canvas.draw()
    # data -> display (pixels from the bottom-left corner), then flip to image rows
    (u0, d0), (u1, d1) = ax.transData.transform([(xr[0], yr[0]), (xr[1], yr[1])])
    height = int(canvas.get_width_height()[1])
    width = int(canvas.get_width_height()[0])
    bx = (u1 - u0) / (xr[1] - xr[0])
    by = -(d1 - d0) / (yr[1] - yr[0])
    ax_ = u0 - bx * xr[0]
    ay_ = (height - d0) - by * yr[0]
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    if not all(math.isfinite(v) for v in (bx, by, ax_, ay_)):
        raise InvalidParameterError(f"loop '{title}': the data map is not finite")
    return LoopImage(
        png=buf.getvalue(),
        width=width,
        height=height,
        x_range=xr,
        y_range=yr,
        ax=float(ax_),
        bx=float(bx),
        ay=float(ay_),
        by=float(by),
    )


def render_loop(
    curves: Sequence[LoopCurve],
    *,
    title: str,
    xlabel: str,
    ylabel: str,
    overlay: Sequence[LegendEntry] = (),
    note: str | None = None,
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    x_range: tuple[float, float] | None = None,
    y_range: tuple[float, float] | None = None,
) -> LoopImage:
    """Draw ``curves`` on axes framed to them (and to zero), axes through zero, numbers on both
    axes, the legend above the axes (never over the data); return the image and its data map.

    ``overlay`` adds legend entries for what the caller draws natively over the image;
    ``x_range`` / ``y_range`` fix the frame (e.g. two panels compared on one scale)."""
    if not curves:
        raise InvalidParameterError("a loop panel needs at least one curve")
    w, h = size_px
    if not (100 <= w <= 4000 and 100 <= h <= 4000):
        raise InvalidParameterError(f"loop image size must be 100..4000 px, got {size_px!r}")
    xr = x_range if x_range is not None else frame([c.x for c in curves])
    yr = y_range if y_range is not None else frame([c.y for c in curves])
    if not (xr[1] > xr[0] and yr[1] > yr[0]) or not all(math.isfinite(v) for v in (*xr, *yr)):
        raise InvalidParameterError(f"loop frame must be finite, low < high: {xr}, {yr}")
    fig = Figure(figsize=(w / DPI, h / DPI), dpi=DPI)
    canvas = FigureCanvasAgg(fig)
    n_entries = sum(c.in_legend for c in curves) + len(overlay)
    long = max([len(c.label) for c in curves if c.in_legend] + [len(e.label) for e in overlay])
    ncol = 1 if long > 30 else 2
    rows = -(-n_entries // ncol)
    top = 0.68 - 0.045 * max(0, rows - 3)  # the legend sits between the title and the axes
    ax = fig.add_axes((0.15, 0.12, 0.81, top - 0.12))
    ax.set_xlim(*xr)
    ax.set_ylim(*yr)
    ax.axhline(0.0, color="0.15", lw=1.0, zorder=1)
    ax.axvline(0.0, color="0.15", lw=1.0, zorder=1)
    ax.grid(True, alpha=0.35)
    drawn: list[Line2D] = []
    for c in curves:
        (line,) = ax.plot(
            c.x, c.y, c.style, color=c.color, lw=c.width, alpha=c.alpha, label=c.label, zorder=2
        )
        if c.in_legend:
            drawn.append(line)
    handles = _legend_handles(drawn, overlay)
    ax.tick_params(labelsize=12)
    ax.set_xlabel(xlabel, fontsize=13)
    ax.set_ylabel(ylabel, fontsize=13)
    head, _, sub = title.partition("\n")
    fig.text(0.5, 0.985, head, ha="center", va="top", fontsize=14, weight="bold")
    if sub:
        fig.text(0.5, 0.935, sub, ha="center", va="top", fontsize=12)
    fig.legend(
        handles=handles,
        loc="upper center",
        bbox_to_anchor=(0.55, 0.885),
        ncol=ncol,
        fontsize=11 if len(handles) <= 4 else 10,
        frameon=False,
        handlelength=2.2,
        columnspacing=1.2,
    )
    if note:
        ax.text(
            0.02,
            0.97,
            note,
            transform=ax.transAxes,
            va="top",
            fontsize=11,
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"},
        )
    return _image(fig, canvas, ax, xr, yr, title)
