"""Comparison recordings: two or more configurations of the same scenario in one Rerun recording.

Each configuration gets a tag (``with-slip``, ``D7``, ...): its time series are logged under
``signals/<panel>/<tag>/<column>`` (so every panel shows the configurations over each other, the
legend naming them; a signal keeps its colour in every configuration, which differ by shade and
line width), its loop as ``loops/<loop>/<tag>/...`` in the shared loop panel, each with
its own colour, beside the catalogue's model curve of each distinct shaft. The 3-D view shows the
first configuration's arm; the metadata page lists every configuration.

Also generic :func:`record_series_comparison` for records that are not arm runs (e.g. a
diagnosis: measured vs nominal vs final model per channel, and the residuals).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.review import recording
from fsarm_sim.review.loop_panels import (
    ARM_LOOPS,
    Loop,
    LoopCurve,
    Trace,
    log_loop_panel,
    loop_image,
    loop_is_informative,
    shaft_model_curves,
)

if TYPE_CHECKING:
    import rerun as rr
    import rerun.blueprint as rrb

    from fsarm_sim.sim.simulation import RunResult

Array = npt.NDArray[np.float64]

# one colour per configuration (loops, and series that have a single colour per panel)
CONFIG_COLORS: tuple[tuple[int, int, int], ...] = (
    recording.BLUE,
    recording.RED,
    recording.GREEN,
    recording.PURPLE,
)
TAG_RE = re.compile(r"^[^\x00-\x1f/]{1,80}$")  # a configuration's name (shown in legends)


def entity_name(tag: str) -> str:
    """The entity-path part of a configuration's name (letters, digits, ``_.-``; the rest ``_``)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", tag)


def check_tags(tags: Sequence[str]) -> None:
    """Configuration names: 1-80 characters without control characters or ``/``, distinct also
    as entity names; 2..4 configurations."""
    if not 2 <= len(tags) <= len(CONFIG_COLORS):
        raise InvalidParameterError(
            f"a comparison needs 2 to {len(CONFIG_COLORS)} configurations, got {len(tags)}"
        )
    for t in tags:
        if not TAG_RE.match(t) or not t.strip():
            raise InvalidParameterError(
                f"configuration name {t!r} must be 1-80 characters, no '/' or control characters"
            )
    names = [entity_name(t) for t in tags]
    if len(set(names)) != len(names):
        raise InvalidParameterError(f"configuration names must differ, got {list(tags)}")


# the k-th configuration's style of a series: its colour mixed with white (> 0) or black (< 0)
# by this share, and its line width (UI points); visual only
RUN_STYLES: tuple[tuple[float, float], ...] = ((0.0, 1.5), (0.55, 3.0), (-0.4, 1.5), (0.8, 4.0))


def _shade(color: tuple[int, int, int], k: int) -> tuple[int, int, int]:
    """The k-th configuration's shade of a series colour: every signal keeps its own colour in
    every configuration (q1 is blue in each), the configurations differ by shade and width
    (:data:`RUN_STYLES`)."""
    mix = RUN_STYLES[k][0]
    target = 255.0 if mix > 0 else 0.0
    a = abs(mix)
    return tuple(round((1.0 - a) * c + a * target) for c in color)  # type: ignore[return-value]


@dataclass(frozen=True)
class Tagged:
    tag: str
    result: RunResult


def _tagged_panels(tag: str, k: int) -> list[recording.Panel]:
    """The arm panels of configuration ``k`` (tagged ``tag``): its own entities, labels and
    shade; references and limits are the same for every configuration, shown with the first."""
    return [
        recording.Panel(
            f"{p.name}/{entity_name(tag)}",
            p.title,
            tuple(
                replace(
                    s,
                    label=f"{s.label} · {tag}",
                    color=_shade(s.color, k),
                    width=RUN_STYLES[k][1],
                )
                for s in p.series
                if k == 0 or not (s.column.endswith("_ref") or "limit" in s.column)
            ),
        )
        for p in recording.ARM_PANELS
    ]


def _loop_views(
    rec: rr.RecordingStream,
    all_cols: Sequence[tuple[Tagged, recording.Columns, Any]],
    scenario: str,
) -> list[recording.LoopView]:
    """Log each informative loop plot of the configurations (with the catalogue's law where it
    is the flexible shaft's); return their views."""
    views = []
    for lp in ARM_LOOPS:
        members = [(r, c, rows) for r, c, rows in all_cols if loop_is_informative(lp, c)]
        if not members:
            continue
        traces = [
            (Trace(entity_name(r.tag), r.tag, CONFIG_COLORS[k], lp.y), c, rows)
            for k, (r, c, rows) in enumerate(members)
        ]
        model: list[LoopCurve] = []
        seen: list[Any] = []
        for r, c, _ in members:
            sh = r.result.config.shaft
            law = (sh.k_pos, sh.s_pos, sh.k_neg, sh.s_neg, sh.kb, sh.beta)  # eq. 8 / eq. 4
            if r.result.config.transmission == "flexible-shaft" and law not in seen:
                seen.append(law)
                model += shaft_model_curves(
                    lp, c, sh, tag="catalogue" if len(members) == 1 else f"{r.tag} catalogue"
                )
        if len(seen) == 1:  # one law for all: one curve, named plainly
            model = shaft_model_curves(lp, members[0][1], members[0][0].result.config.shaft)
        image = loop_image(
            lp,
            [(tr, c) for tr, c, _ in traces],
            model,
            subtitle=f"{scenario}: {' vs '.join(r.tag for r, _, _ in members)}",
        )
        log_loop_panel(rec, lp, traces, image)
        views.append(recording.LoopView(lp.entity, lp.title, image.width, image.height))
    return views


def log_runs(
    rec: rr.RecordingStream,
    runs: Sequence[Tagged],
    rate_hz: float | None = recording.DEFAULT_RATE_HZ,
) -> rrb.Blueprint:
    """Log the configurations into ``rec``; return the blueprint."""
    import rerun as rr

    from fsarm_sim.records.timeseries import run_metadata

    check_tags([r.tag for r in runs])
    scen = {r.result.scenario for r in runs}
    if len(scen) != 1:
        raise InvalidParameterError(f"compare runs of one scenario, got {sorted(scen)}")
    first = runs[0].result
    # the 3-D view shows the first configuration (its columns carry the motor-limit lines)
    first_cols, _ = recording.log_arm_world(rec, first, rate_hz)
    pages = [
        f"## {r.tag}\n\n" + recording.metadata_markdown(run_metadata(r.result), r.result.metrics)
        for r in runs
    ]
    rec.log(
        "run/metadata",
        rr.TextDocument(
            f"# {first.scenario}: {' vs '.join(r.tag for r in runs)}\n\n" + "\n\n".join(pages),
            media_type="text/markdown",
        ),
        static=True,
    )
    all_cols = []
    panels_shown: dict[str, recording.Panel] = {}
    curves: dict[str, list[recording.Curve]] = {}
    for k, r in enumerate(runs):
        cols = first_cols if k == 0 else recording.with_derived(r.result.columns)
        rows = recording.decimate(cols["t"], rate_hz)
        all_cols.append((r, cols, rows))
        # references and limits are the same for every configuration: shown once
        panels = _tagged_panels(r.tag, k)
        recording.log_scalar_panels(rec, cols, panels, rows)
        for base, tagged in zip(recording.ARM_PANELS, panels, strict=True):
            curves.setdefault(base.name, []).extend(recording.panel_curves(tagged, cols))
        for p in recording.informative_panels(cols, recording.ARM_PANELS):
            panels_shown.setdefault(p.name, p)
    views = _loop_views(rec, all_cols, first.scenario)
    ordered = [p for p in recording.ARM_PANELS if p.name in panels_shown]
    return recording.blueprint(ordered, views, curves=curves)


def record_runs(
    runs: Sequence[tuple[str, RunResult]],
    path: Path,
    rate_hz: float | None = recording.DEFAULT_RATE_HZ,
) -> Path:
    """Write the configurations ``(tag, result)`` as one Rerun recording; return the path."""
    import rerun as rr

    tagged = [Tagged(t, r) for t, r in runs]
    check_tags([t.tag for t in tagged])
    rec = rr.RecordingStream(
        recording.APPLICATION_ID,
        recording_id=f"{tagged[0].result.scenario}:" + " vs ".join(t.tag for t in tagged),
    )
    return recording.save_recording(rec, path, lambda r: log_runs(r, tagged, rate_hz))


# --------------------------------------------------------------------------- any series


@dataclass(frozen=True)
class SeriesPanel:
    """A time-series panel of :func:`record_series_comparison`: legend name -> values on the
    shared time axis, drawn in the given order with :data:`SERIES_COLORS`."""

    name: str
    title: str
    curves: Mapping[str, Array]
    colors: Mapping[str, tuple[int, int, int]] = field(default_factory=dict)  # else SERIES_COLORS


@dataclass(frozen=True)
class XYPanel:
    """A loop panel of :func:`record_series_comparison`: legend name -> (x, y) on the shared time
    axis (already in the axes' units); each is traced up to the time cursor."""

    name: str
    title: str
    x_label: str
    y_label: str
    curves: Mapping[str, tuple[Array, Array]]
    colors: Mapping[str, tuple[int, int, int]] = field(default_factory=dict)  # else SERIES_COLORS
    y_range: tuple[float, float] | None = None  # fixed y frame (e.g. before/after on one scale)


SERIES_COLORS: tuple[tuple[int, int, int], ...] = (
    (20, 20, 20),  # the first curve (e.g. measured): black
    recording.GREY,
    recording.RED,
    recording.BLUE,
    recording.ORANGE,
    recording.GREEN,
    recording.PURPLE,
)
MAX_SERIES_ROWS = 4000  # logged rows per series at most (a long record is decimated)


def _slug(name: str) -> str:
    s = re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_")
    return s or "series"


def record_series_comparison(
    path: Path,
    *,
    t: Array,
    panels: Sequence[SeriesPanel],
    loops: Sequence[XYPanel] = (),
    markdown: str = "",
    recording_id: str = "comparison",
) -> Path:
    """One recording of time series and x-y loops that compare models with a record: each panel
    is a TimeSeriesView (``signals/<panel>/<curve>``), each loop a loop panel
    (``loops/<loop>/<curve>/...``, :mod:`.loop_panels`), the markdown a page. Returns the path."""
    import rerun as rr

    t = np.asarray(t, dtype=np.float64)
    n = len(t)
    if n < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0.0):
        raise InvalidParameterError("a comparison recording needs >= 2 finite, sorted times")
    for p in panels:
        for k, v in p.curves.items():
            if len(v) != n:
                raise InvalidParameterError(f"panel {p.name}: {k} has {len(v)} values, t has {n}")
    step = max(1, math.ceil(n / MAX_SERIES_ROWS))
    rows = np.arange(0, n, step)
    rec = rr.RecordingStream(recording.APPLICATION_ID, recording_id=recording_id)

    def log(rec: rr.RecordingStream) -> Any:
        rec.log("run/metadata", rr.TextDocument(markdown, media_type="text/markdown"), static=True)
        shown = []
        curves: dict[str, list[recording.Curve]] = {}
        for p in panels:
            series = tuple(
                recording.Series(
                    _slug(k), k, 1.0, p.colors.get(k, SERIES_COLORS[i % len(SERIES_COLORS)])
                )
                for i, k in enumerate(p.curves)
            )
            cols = {
                "t": t,
                **{_slug(k): np.asarray(v, dtype=np.float64) for k, v in p.curves.items()},
            }
            panel = recording.Panel(p.name, p.title, series)
            recording.log_scalar_panels(rec, cols, [panel], rows)
            shown.append(panel)
            curves[panel.name] = recording.panel_curves(panel, cols)
        views = []
        for lp in loops:
            loop = Loop(lp.name, lp.title, "x", lp.x_label, 1.0, "y", lp.y_label)
            runs = []
            for i, (k, (x, y)) in enumerate(lp.curves.items()):
                if len(x) != n or len(y) != n:
                    raise InvalidParameterError(f"loop {lp.name}: {k} does not match t")
                cols = {
                    "t": t,
                    "x": np.asarray(x, dtype=np.float64),
                    "y": np.asarray(y, dtype=np.float64),
                }
                color = lp.colors.get(k, SERIES_COLORS[i % len(SERIES_COLORS)])
                runs.append((Trace(_slug(k), k, color, "y"), cols, rows))
            image = loop_image(loop, [(tr, c) for tr, c, _ in runs], y_range=lp.y_range)
            log_loop_panel(rec, loop, runs, image)
            views.append(recording.LoopView(loop.entity, loop.title, image.width, image.height))
        return recording.blueprint(shown, views, with_3d=False, curves=curves)

    return recording.save_recording(rec, path, log)
