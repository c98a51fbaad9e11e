"""A recording's blueprint: which panels a run shows, their tabs, layout and legends, and the
metadata view.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fsarm_sim._version import __version__
from fsarm_sim.review.loop_panels import (
    varies,
)
from fsarm_sim.review.panels import CAMERA_EYE_M, CAMERA_TARGET_M, Array, Columns, Panel

if TYPE_CHECKING:
    import rerun.blueprint as rrb


# --------------------------------------------------------------------------- blueprint, metadata


def informative_panels(cols: Columns, panels: Sequence[Panel]) -> list[Panel]:
    """The panels that carry information for this run: their own test when they have one, else
    at least one series that exists and varies."""
    out = []
    for p in panels:
        present = [s for s in p.series if s.column in cols]
        if not present:
            continue
        ok = (
            p.informative(cols)
            if p.informative is not None
            else any(varies(cols[s.column]) for s in present)
        )
        if ok:
            out.append(p)
    return out


@dataclass(frozen=True)
class LoopView:
    """A loop panel in the blueprint: its entity, title and image size (its visual bounds)."""

    entity: str
    title: str
    width: int
    height: int


# --- time-series views: what each panel needs to be read at a glance. Rerun draws a plot's
# legend over the data and labels the time axis only where ticks have room (its time ticks step
# 1 s, 10 s, ...: a 7 s run in a quarter-width panel got "+0s" alone). So the panels stand in
# one full-width column, at most PANELS_PER_TAB per tab, each with a y range of its data and a
# legend in the corner the data leave free (room is made above or below the data where none is).
PANELS_PER_TAB = 4
COLUMN_PX = (560.0, 800.0)  # the panels' column in a 1600 x 1000 window (below its tabs)
PANEL_CHROME_PX = 50.0  # a panel's title bar and time axis; visual only
LEGEND_ROW_PX = 19.0  # one legend entry's height (Rerun's default font), visual only
LEGEND_CHAR_PX = 7.0  # one character's width in a legend entry, visual only
LEGEND_PAD_PX = 30.0  # a legend entry's colour mark and margins, visual only
Y_MARGIN = 0.06  # share of the data's span left free above and below it

Curve = tuple[Array, Array, str]  # (t, y as shown, legend name) of one series in a panel


def panel_curves(panel: Panel, cols: Columns, time_column: str = "t") -> list[Curve]:
    """The series of ``panel`` that ``cols`` holds, as shown (scaled), with their names."""
    t = np.asarray(cols[time_column], dtype=np.float64)
    return [
        (t, np.asarray(cols[s.column], dtype=np.float64) * s.scale, s.label)
        for s in panel.series
        if s.column in cols
    ]


@dataclass(frozen=True)
class SeriesLayout:
    """How a time-series view shows its curves: the y range, the legend's corner (``None``: no
    legend, one curve names itself by the title) and the share of the plot the legend covers."""

    y_range: tuple[float, float]
    corner: str | None
    legend_share: tuple[float, float]


CORNERS = ("RightTop", "LeftTop", "RightBottom", "LeftBottom")


def plot_px(panels_in_tab: int) -> tuple[float, float]:
    """The nominal plot area of one of ``panels_in_tab`` panels stacked in the column."""
    return COLUMN_PX[0], COLUMN_PX[1] / max(1, panels_in_tab) - PANEL_CHROME_PX


def series_layout(
    curves: Sequence[Curve], plot_px: tuple[float, float] = plot_px(PANELS_PER_TAB)
) -> SeriesLayout:
    """The y range and legend corner of a panel showing ``curves``: the corner whose legend box
    covers the fewest data points; where every corner covers some, the range grows on that side
    by the legend's height, so that the legend stands beside the data, never on it."""
    finite = [(t[m], y[m]) for t, y, _ in curves if (m := np.isfinite(y) & np.isfinite(t)).any()]
    if not finite:
        return SeriesLayout((-1.0, 1.0), None, (0.0, 0.0))
    ts = np.concatenate([t for t, _ in finite])
    ys = np.concatenate([y for _, y in finite])
    lo, hi = float(ys.min()), float(ys.max())
    span = hi - lo if hi > lo else max(abs(hi), 1.0) * 0.1
    lo, hi = lo - Y_MARGIN * span, hi + Y_MARGIN * span
    if len(curves) < 2:
        return SeriesLayout((lo, hi), None, (0.0, 0.0))
    longest = max(len(name) for _, _, name in curves)
    w = min(0.9, (LEGEND_PAD_PX + LEGEND_CHAR_PX * longest) / plot_px[0])
    h = min(0.6, (LEGEND_ROW_PX * len(curves) + 8.0) / plot_px[1])
    t0, t1 = float(ts.min()), float(ts.max())
    u = (ts - t0) / (t1 - t0) if t1 > t0 else np.zeros_like(ts)
    v = (ys - lo) / (hi - lo)

    def covered(corner: str) -> int:
        in_x = u >= 1.0 - w if corner.startswith("Right") else u <= w
        in_y = v >= 1.0 - h if corner.endswith("Top") else v <= h
        return int(np.count_nonzero(in_x & in_y))

    corner = min(CORNERS, key=covered)  # ties: the first (top right, where Rerun puts it)
    if covered(corner):
        grow = (hi - lo) * h / (1.0 - h)  # the legend's rows beyond the data
        lo, hi = (lo, hi + grow) if corner.endswith("Top") else (lo - grow, hi)
    return SeriesLayout((lo, hi), corner, (w, h))


def series_view(panel: Panel, curves: Sequence[Curve], panels_in_tab: int) -> rrb.TimeSeriesView:
    """The panel's TimeSeriesView laid out by :func:`series_layout`."""
    import rerun.blueprint as rrb

    lay = series_layout(curves, plot_px(panels_in_tab))
    legend = (
        rrb.PlotLegend(visible=False)
        if lay.corner is None
        else rrb.PlotLegend(corner=getattr(rrb.Corner2D, lay.corner), visible=True)
    )
    return rrb.TimeSeriesView(
        origin=panel.entity,
        name=panel.title,
        axis_y=rrb.ScalarAxis(range=lay.y_range, zoom_lock=False),
        plot_legend=legend,
    )


def panel_tabs(panels: Sequence[Panel]) -> list[tuple[str, list[Panel]]]:
    """The panels as tabs: consecutive panels of a group share one, at most
    :data:`PANELS_PER_TAB` each (a larger group is split: ``control 1``, ``control 2``)."""
    groups: list[tuple[str, list[Panel]]] = []
    for p in panels:
        if groups and groups[-1][0] == p.group:
            groups[-1][1].append(p)
        else:
            groups.append((p.group, [p]))
    tabs = []
    for name, members in groups:
        chunks = [members[i : i + PANELS_PER_TAB] for i in range(0, len(members), PANELS_PER_TAB)]
        for k, chunk in enumerate(chunks):
            tabs.append((f"{name} {k + 1}" if len(chunks) > 1 else name, chunk))
    return tabs


def shown_panels(panels: Sequence[Panel]) -> list[Panel]:
    """The panels a reader sees on opening the recording (the first tab's)."""
    tabs = panel_tabs(panels)
    return tabs[0][1] if tabs else []


def blueprint(
    panels: Sequence[Panel],
    loops: Sequence[LoopView],
    *,
    with_3d: bool = True,
    metadata: str | None = "run/metadata",
    curves: Mapping[str, Sequence[Curve]] | None = None,
) -> rrb.Blueprint:
    """The layout: 3-D arm and metadata, the loop panels (framed to their plot), the time-series
    panels in tabs of one column (:func:`panel_tabs`), each laid out from its ``curves`` (panel
    name -> curves; :func:`series_layout`); Rerun's side panels start collapsed (the views get
    the room)."""
    import rerun.blueprint as rrb

    loop_views = [
        rrb.Spatial2DView(
            origin=lp.entity,
            name=lp.title,
            visual_bounds=rrb.VisualBounds2D(x_range=(0.0, lp.width), y_range=(0.0, lp.height)),
            background=(255, 255, 255),
        )
        for lp in loops
    ]
    meta = [rrb.TextDocumentView(origin=metadata, name="run")] if metadata is not None else []
    arm = (
        [
            rrb.Spatial3DView(
                origin="world",
                name="arm (3-D)",
                # the whole arm in view at any pose (reach ~0.85 m from the base; visual only)
                eye_controls=rrb.EyeControls3D(
                    kind=rrb.Eye3DKind.Orbital,
                    position=CAMERA_EYE_M,
                    look_target=CAMERA_TARGET_M,
                    eye_up=(0.0, 0.0, 1.0),
                ),
            )
        ]
        if with_3d
        else []
    )
    # one loop: it shares its column with the metadata and the arm gets a full column
    left: list[Any] = arm + (meta if len(loop_views) != 1 else [])
    middle: list[Any] = loop_views + (meta if len(loop_views) == 1 else [])
    columns: list[Any] = []
    shares: list[float] = []
    for views, share in ((left, 2.0), (middle, 2.2)):
        if views:
            rows = [
                3.0 if isinstance(v, rrb.Spatial3DView | rrb.Spatial2DView) else 1.0 for v in views
            ]
            columns.append(rrb.Vertical(*views, row_shares=rows))
            shares.append(share)
    tabs = [
        rrb.Vertical(
            *(series_view(p, (curves or {}).get(p.name, ()), len(members)) for p in members),
            name=name,
        )
        for name, members in panel_tabs(panels)
    ]
    if tabs:
        columns.append(tabs[0] if len(tabs) == 1 else rrb.Tabs(*tabs, active_tab=0))
        shares.append(3.0)
    return rrb.Blueprint(
        rrb.Horizontal(*columns, column_shares=shares),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )


def metadata_markdown(meta: Mapping[str, Any], metrics: Mapping[str, Any] | None = None) -> str:
    """A readable markdown page of the run metadata (and metrics), with the full JSON below."""
    lines = [f"# {meta.get('scenario', 'run')}", ""]
    shaft = meta.get("shaft") or {}
    rows = [
        ("setup", meta.get("setup")),
        ("shaft D / L [mm]", f"{shaft.get('diameter_mm')} / {shaft.get('length_mm')}"),
        ("payload [kg]", meta.get("payload_kg")),
        ("duration [s]", meta.get("duration_s")),
        ("fsarm-sim", meta.get("fsarm_sim_version", __version__)),
    ]
    lines += ["| item | value |", "|---|---|", *(f"| {k} | {v} |" for k, v in rows), ""]
    if metrics:
        rmse = metrics.get("rmse_deg")
        if isinstance(rmse, Mapping):
            lines.append(
                "tracking RMSE [deg]: " + ", ".join(f"{k} {float(v):.4f}" for k, v in rmse.items())
            )
            lines.append("")
    payload = {"metadata": meta, "metrics": metrics or {}}
    lines += ["```json", json.dumps(payload, indent=2, default=str), "```"]
    return "\n".join(lines)
