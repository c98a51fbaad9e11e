"""``fsarm diagnose DATA --rrd FILE``: the discrepancy story as a Rerun recording.

Measured vs catalogue vs nominal (refit) vs final model per channel, the residuals before (nominal)
and after (final), and the loops before and after - from a finished diagnosis, through
:func:`fsarm_sim.review.comparison.record_series_comparison` (the review layer knows nothing of
the diagnosis; this module reads it). Bench records: the output torque and its loop against the
input; arm records: the report's channels (q3, theta_m, q2, twist) and the twist residual
against q3. The loops are residual vs input, before and after on one scale: the missing effect's
signature, then what is left.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.records.sidecar import UNITS
from fsarm_sim.review.comparison import SeriesPanel, XYPanel, record_series_comparison
from fsarm_sim.review.loop_plot import frame

MODELS = ("catalogue", "nominal", "final")
# one colour per role in every panel: the record black, the models grey / red / blue
COLORS = {
    "measured": (20, 20, 20),
    "catalogue": (150, 150, 150),
    "nominal": (214, 39, 40),
    "final": (31, 119, 180),
    "before (nominal)": (214, 39, 40),
    "after (final)": (31, 119, 180),
}


def label(column: str, what: str = "") -> str:
    """``column [unit]`` (``column what [unit]``) with the SI unit the project gives the column
    (:data:`fsarm_sim.records.sidecar.UNITS`); a column it does not name keeps its bare name."""
    text = f"{column} {what}" if what else column
    unit = UNITS.get(column)
    return f"{text} [{unit.replace('*', '·')}]" if unit else text


def _residual_loops(
    x: np.ndarray, before: np.ndarray, after: np.ndarray, x_label: str, y_label: str
) -> list[XYPanel]:
    """Residual vs input, before and after, on one y scale: the missing effect's signature
    (e.g. a friction box) before, noise after."""
    yr = frame([before, after])
    return [
        XYPanel(
            f"residual_{name}",
            f"residual vs {x_label.split(' [')[0]}: {name}",
            x_label,
            y_label,
            {key: (x, res)},
            COLORS,
            yr,
        )
        for name, key, res in (
            ("before", "before (nominal)", before),
            ("after", "after (final)", after),
        )
    ]


def _page(diag: Any) -> str:
    named = ", ".join(diag.named) or "none"
    lines = [
        f"# diagnosis: {diag.dataset.path.name}",
        "",
        f"named effects: **{named}**",
        "",
        f"held-out NRMSE of the main channel: nominal {100 * diag.gap_before:.4g} % -> "
        f"final {100 * diag.gap_after:.4g} %",
        "",
        str(diag.verdict),
        "",
        "Curves: measured (black), catalogue (the model as stated), nominal (its parameters "
        "refit), final (with the named effects). Residual = measured - model.",
    ]
    return "\n".join(lines)


def _bench(diag: Any) -> tuple[Any, list[SeriesPanel], list[XYPanel]]:
    inp = diag.ctx.inp
    ds = diag.dataset
    y = np.asarray(inp.y, dtype=np.float64)
    fits = {"measured": y, **{m: np.asarray(getattr(diag, m).yhat) for m in MODELS}}
    before, after = y - fits["nominal"], y - fits["final"]
    panels = [
        SeriesPanel("output", f"{label(ds.output_column)}: measured vs models", fits, COLORS),
        SeriesPanel(
            "residual",
            f"{label(ds.output_column, 'residual')} (measured - model)",
            {"before (nominal)": before, "after (final)": after},
            COLORS,
        ),
        SeriesPanel("input", label(ds.input_column), {ds.input_column: np.asarray(inp.u)}),
    ]
    u = np.asarray(inp.u, dtype=np.float64)
    loops = _residual_loops(
        u, before, after, label(ds.input_column), label(ds.output_column, "residual")
    )
    return inp.t, panels, loops


def _arm(diag: Any) -> tuple[Any, list[SeriesPanel], list[XYPanel]]:
    ctx = diag.ctx
    channels = [c for c in ("q3", "theta_m", "q2", "twist") if c in ctx.y]
    panels = []
    for ch in channels:
        y = np.asarray(ctx.y[ch], dtype=np.float64)
        fits = {m: np.asarray(getattr(diag, m).pred[ch], dtype=np.float64) for m in MODELS}
        panels.append(
            SeriesPanel(ch, f"{label(ch)}: measured vs models", {"measured": y, **fits}, COLORS)
        )
        panels.append(
            SeriesPanel(
                f"{ch}_residual",
                label(ch, "residual"),
                {"before (nominal)": y - fits["nominal"], "after (final)": y - fits["final"]},
                COLORS,
            )
        )
    loops = []
    if {"q3", "twist"} <= set(channels):
        mt = np.asarray(ctx.y["twist"], dtype=np.float64)
        loops = _residual_loops(
            np.asarray(ctx.y["q3"], dtype=np.float64),
            mt - np.asarray(diag.nominal.pred["twist"]),
            mt - np.asarray(diag.final.pred["twist"]),
            label("q3"),
            label("twist", "residual"),
        )
    return ctx.run.t, panels, loops


def diagnosis_recording(diag: Any, path: Path) -> Path:
    """Write the diagnosis as a Rerun recording at ``path``; return it."""
    ctx = diag.ctx
    if hasattr(ctx, "inp"):
        t, panels, loops = _bench(diag)
    elif hasattr(ctx, "run") and hasattr(ctx, "y"):
        t, panels, loops = _arm(diag)
    else:
        raise InvalidParameterError(
            f"--rrd does not know how to draw a {type(diag.setup).__name__} diagnosis"
        )
    return record_series_comparison(
        path,
        t=np.asarray(t, dtype=np.float64),
        panels=panels,
        loops=loops,
        markdown=_page(diag),
        recording_id=f"diagnose:{diag.dataset.path.name}",
    )
