"""The loop panels of a recording: shaft torque vs twist (seed 000 Fig. 6/7) and bending moment vs
bend (Fig. 9), each with the catalogue's model curve (eq. 8 / eq. 4) beside the plant's loop.

Entity layout of one loop ``loops/<loop>`` (timeline ``sim_time``):

* ``loops/<loop>/plot``                 - static image: the whole loop (faint), the model curve,
  axes through zero with ticks and numbers, title and legend (:mod:`.loop_plot`);
* ``loops/<loop>/<tag>/trace``          - LineStrips2D, the loop from the start up to each time
  (latest-at: the view shows the loop up to the time cursor);
* ``loops/<loop>/<tag>/now``            - Points2D, the current point, labelled with its values.

``trace`` and ``now`` are in the image's pixel coordinates (:meth:`LoopImage.to_pixels`): the
values logged there are the plotted values, mapped by an affine map whose coefficients are in
``loops/<loop>/plot``'s sibling text ``loops/<loop>/map`` (JSON), so that a reader can map them
back. ``<tag>`` names one configuration (``run`` for a single run; a comparison recording logs
one tag per configuration into the same panel).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from fsarm_sim.review.loop_plot import LegendEntry, LoopCurve, LoopImage, render_loop

if TYPE_CHECKING:
    import rerun as rr

    from fsarm_sim.plant.shaft import ShaftParams

Array = npt.NDArray[np.float64]
Columns = Mapping[str, Array]

TIMELINE = "sim_time"
RAD2DEG = 180.0 / math.pi
HELD_BEND_DEG = 0.5  # a bend spanning less than this is held: no bending loop (figures.py's rule)
MAX_TRACE_FRAMES = 200  # growing-loop snapshots per run (file size grows with frames x points)
MAX_TRACE_POINTS = 400  # points per snapshot at most
MODEL_POINTS = 60  # points of a drawn model curve (visual only)
MAX_MODEL_ROWS = 2000  # rows of a run a model curve along the run is evaluated at (visual only)
NOW_COLOR = (214, 39, 40)


@dataclass(frozen=True)
class Trace:
    """One configuration's plant curve in a loop panel: y column vs the loop's x column."""

    tag: str  # entity name under the loop (``run``, or a configuration's name)
    label: str  # legend text
    color: tuple[int, int, int]
    y: str  # y column (the loop's x column is shared)


@dataclass(frozen=True)
class Loop:
    """An x-y panel traced over time. ``x``/``y`` column values times ``x_scale``/``y_scale``
    are the plotted values; ``now_format`` formats the current point's label from them."""

    name: str
    title: str
    x: str
    x_label: str
    x_scale: float
    y: str
    y_label: str
    y_scale: float = 1.0
    now_format: str = "x = {x:.3g}, y = {y:.3g}"
    # does a run carry information for this panel? (None: whenever x varies)
    informative: Callable[[Columns], bool] | None = None

    @property
    def entity(self) -> str:
        return f"loops/{self.name}"


def bend_moves(cols: Columns, bend: str = "phi_b") -> bool:
    """Does joint 2 bend the shaft in this run (span of φ_B at least :data:`HELD_BEND_DEG`)?"""
    return bend in cols and float(np.ptp(np.asarray(cols[bend]))) * RAD2DEG >= HELD_BEND_DEG


def bending_shown(cols: Columns) -> bool:
    """The bending panels carry information: the bend moves and the transmission puts a moment
    on joint 2 (a transmission not routed over joint 2 logs a constant zero)."""
    return bend_moves(cols) and "tau_bend" in cols and varies(cols["tau_bend"])


def varies(values: Array, rel: float = 1e-9) -> bool:
    """Not constant (span above ``rel`` of the magnitude; NaN-free)."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return len(v) > 1 and float(np.ptp(v)) > rel * (1.0 + float(np.max(np.abs(v))))


def loop_is_informative(loop: Loop, cols: Columns) -> bool:
    if loop.x not in cols or loop.y not in cols:
        return False
    if loop.informative is not None:
        return loop.informative(cols)
    return varies(cols[loop.x]) and varies(cols[loop.y])


ARM_LOOPS: tuple[Loop, ...] = (
    Loop(
        "torque_twist",
        "shaft torque vs twist (cf. seed 000 Fig. 6/7)",
        x="twist",
        x_label="twist Δθ [deg]",
        x_scale=RAD2DEG,
        y="tau_shaft",
        y_label="shaft torque τ [N·m]",
        now_format="Δθ {x:.2f}°  τ {y:.3f} N·m",
    ),
    Loop(
        "bending",
        "bending moment vs bend (cf. seed 000 Fig. 9)",
        x="phi_b",
        x_label="bend φ_B [deg]",
        x_scale=RAD2DEG,
        y="moment_bend",
        y_label="bending moment M [N·m]",
        now_format="φ_B {x:.1f}°  M {y:.2f} N·m",
        informative=bending_shown,
    ),
)


def _hex(color: tuple[int, int, int]) -> str:
    return "#{:02x}{:02x}{:02x}".format(*color)


def shaft_model_curves(
    loop: Loop, cols: Columns, shaft: ShaftParams, *, tag: str = "catalogue"
) -> list[LoopCurve]:
    """The catalogue's curve for ``loop``: eq. 8 (τ = K(φ_B, side) Δθ) at each row's twist and
    bend for torque vs twist; eq. 2/4 (M = K_b (φ + β φ³)) over the run's bend range for moment
    vs bend. Empty for other loops."""
    x = np.asarray(cols[loop.x], dtype=np.float64)
    lo, hi = float(np.min(x)), float(np.max(x))
    if loop.x == "twist":
        # eq. 8 at each row's own twist and bend: the loop the catalogue model predicts for this
        # very motion (a line when the bend is held), beside the plant's
        bend = np.asarray(cols.get("phi_b", np.zeros_like(x)), dtype=np.float64)
        step = max(1, math.ceil(len(x) / MAX_MODEL_ROWS))
        xs, bs = x[::step], bend[::step]
        tau = np.array(
            [shaft.k_series(b, 1 if v >= 0.0 else -1) * v for v, b in zip(xs, bs, strict=True)]
        )
        b_deg = np.abs(bs) * RAD2DEG
        where = (
            f"φ_B = {float(np.median(b_deg)):.0f}°"
            if float(np.ptp(b_deg)) < HELD_BEND_DEG
            else f"φ_B {float(b_deg.min()):.0f}…{float(b_deg.max()):.0f}° as run"
        )
        return [
            LoopCurve(
                xs * loop.x_scale,
                tau * loop.y_scale,
                f"{tag}: eq. 8, {where}",
                "#ff7f0e",
                "--",
                1.8,
            )
        ]
    if loop.x == "phi_b":
        xs = np.linspace(lo, hi, MODEL_POINTS)
        m = np.array([shaft.static_relief_nm(v) for v in xs])
        return [
            LoopCurve(
                xs * loop.x_scale, m * loop.y_scale, f"{tag}: eq. 4 elastic M", "#ff7f0e", "--", 1.8
            )
        ]
    return []


def loop_image(
    loop: Loop,
    runs: Sequence[tuple[Trace, Columns]],
    model_curves: Sequence[LoopCurve] = (),
    *,
    subtitle: str | None = None,
    y_range: tuple[float, float] | None = None,
) -> LoopImage:
    """Render the panel's frame: each run's whole loop (faint), the model curves, the legend
    (each run's colour, the model curves, the current point; faint = the whole run)."""
    curves = [
        LoopCurve(
            np.asarray(c[loop.x]) * loop.x_scale,
            np.asarray(c[tr.y]) * loop.y_scale,
            f"{tr.label} (whole run)",
            _hex(tr.color),
            "-",
            1.6,
            0.4,
            in_legend=False,
        )
        for tr, c in runs
    ]
    overlay = [LegendEntry(f"{tr.label} (faint: whole run)", _hex(tr.color)) for tr, _ in runs]
    overlay.append(LegendEntry("now (time cursor)", _hex(NOW_COLOR), "none", 0.0, "o"))
    title = loop.title if subtitle is None else f"{loop.title}\n{subtitle}"
    return render_loop(
        [*curves, *model_curves],
        title=title,
        xlabel=loop.x_label,
        ylabel=loop.y_label,
        overlay=overlay,
        y_range=y_range,
    )


def _snapshots(n: int) -> tuple[npt.NDArray[np.intp], int]:
    """Row indices at which the growing loop is snapshotted, and the point stride inside one."""
    frames = np.unique(np.linspace(1, n - 1, min(n - 1, MAX_TRACE_FRAMES)).round().astype(np.intp))
    return frames, max(1, math.ceil(n / MAX_TRACE_POINTS))


def log_loop_panel(
    rec: rr.RecordingStream,
    loop: Loop,
    runs: Sequence[tuple[Trace, Columns, npt.NDArray[np.intp]]],
    image: LoopImage,
    *,
    time_column: str = "t",
) -> list[str]:
    """Log the panel's image, its data map and, per run, the growing loop and the current point.

    ``runs``: (trace, columns, row indices to log) per configuration; return the entity paths."""
    import rerun as rr

    rec.log(
        f"{loop.entity}/plot",
        rr.EncodedImage(contents=image.png, media_type="image/png"),
        static=True,
    )
    rec.log(
        f"{loop.entity}/map",
        rr.TextDocument(
            json.dumps(
                {
                    "u": [image.ax, image.bx],
                    "v": [image.ay, image.by],
                    "x": [loop.x, loop.x_scale],
                    "y_scale": loop.y_scale,
                    "x_range": image.x_range,
                    "y_range": image.y_range,
                }
            ),
            media_type="text/plain",
        ),
        static=True,
    )
    paths = [f"{loop.entity}/plot"]
    for tr, cols, rows in runs:
        if len(rows) < 2:
            continue
        t = np.asarray(cols[time_column], dtype=np.float64)[rows]
        x = np.asarray(cols[loop.x], dtype=np.float64)[rows] * loop.x_scale
        y = np.asarray(cols[tr.y], dtype=np.float64)[rows] * loop.y_scale
        px = image.to_pixels(x, y)
        base = f"{loop.entity}/{tr.tag}"
        # the current point, with its values
        rec.log(
            f"{base}/now",
            rr.Points2D.from_fields(colors=[NOW_COLOR], radii=[-5.0], show_labels=True),
            static=True,
        )
        rec.send_columns(
            f"{base}/now",
            indexes=[rr.TimeColumn(TIMELINE, duration=t)],
            columns=rr.Points2D.columns(
                positions=px,
                labels=[loop.now_format.format(x=a, y=b) for a, b in zip(x, y, strict=True)],
            ),
        )
        # the loop from the start to each snapshot (latest-at shows it up to the cursor)
        frames, stride = _snapshots(len(rows))
        strips = [np.vstack([px[:f:stride], px[f : f + 1]]) for f in frames]
        rec.log(
            f"{base}/trace",
            rr.LineStrips2D.from_fields(colors=[tr.color], radii=[-1.5]),
            static=True,
        )
        rec.send_columns(
            f"{base}/trace",
            indexes=[rr.TimeColumn(TIMELINE, duration=t[frames])],
            columns=rr.LineStrips2D.columns(strips=cast(Any, strips)).partition(
                np.ones(len(strips), dtype=int)
            ),
        )
        paths += [f"{base}/now", f"{base}/trace"]
    return paths
