"""Static figures (matplotlib's object API on Agg canvases: headless, no pyplot state) in the style of seed 000's figures.

* :func:`tracking_figure`      - Fig. 14: desired vs actual joint position, and the error;
* :func:`torque_twist_figure`  - Fig. 6/7: shaft torque vs twist (true loop and the eq. 8 model);
* :func:`bending_figure`       - Fig. 9: bending moment M vs bend φ_B.

All take plain column dicts (``{"t": ..., "q3": ..., ...}``) and column names as parameters, so
bench runs and sweeps reuse them with their own columns; :func:`loops_figure` draws any set of
x-y curves (e.g. one torque-twist loop per bending angle, Fig. 6). Angles are stored in radians
and drawn in degrees.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from fsarm_sim.errors import InvalidParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim.simulation import RunResult

Array = npt.NDArray[np.float64]
Columns = Mapping[str, Array]
RAD2DEG = 180.0 / math.pi
FORMATS = ("png", "svg", "pdf")
DEFAULT_SIZE_IN = (6.4, 4.0)
DEFAULT_DPI = 110
MOVING_REF_RAD = 1e-6  # a joint whose reference spans less than this is "holding"
STILL_SPAN = 1e-3  # relative x span below which a curve is drawn with markers


@dataclass(frozen=True)
class Curve:
    """One x-y curve of :func:`loops_figure` (values already in the units of the axes)."""

    x: Array
    y: Array
    label: str
    style: str = "-"
    color: str | None = None


def _col(cols: Columns, name: str) -> Array:
    try:
        return np.asarray(cols[name], dtype=np.float64)
    except KeyError:
        raise InvalidParameterError(
            f"figure needs column '{name}'; the columns are: {', '.join(sorted(cols))}"
        ) from None


def _new(size_in: tuple[float, float], nrows: int = 1, **kw: Any) -> tuple[Figure, list[Axes]]:
    """A figure on its own Agg canvas: no pyplot, no global figure registry, nothing to close."""
    fig = Figure(figsize=size_in)
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, 1, squeeze=False, **kw)
    return fig, list(axes[:, 0])


def moving_joints(cols: Columns, joints: Iterable[int] = (1, 2, 3)) -> list[int]:
    """Joints whose reference moves (spans more than 1e-6 rad) in ``cols``."""
    out = []
    for j in joints:
        key = f"q{j}_ref"
        if key in cols and np.ptp(np.asarray(cols[key])) > MOVING_REF_RAD:
            out.append(j)
    return out


def tracking_figure(
    cols: Columns,
    joints: Sequence[int] | None = None,
    *,
    time: str = "t",
    title: str | None = None,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
) -> Figure:
    """Seed 000 Fig. 14 style: desired (dashed) vs actual joint position, and the error below.

    ``joints``: which joints (1-3); default the joints whose reference moves, else joint 3.
    Reads ``q<j>``, ``q<j>_ref`` and ``time``."""
    if joints is None:
        joints = moving_joints(cols) or [3]
    t = _col(cols, time)
    fig, (ax, ax_e) = _new(size_in, 2, sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    colors = {1: "tab:blue", 2: "tab:orange", 3: "tab:green"}
    for i, j in enumerate(joints):
        q, q_ref = _col(cols, f"q{j}") * RAD2DEG, _col(cols, f"q{j}_ref") * RAD2DEG
        c = colors.get(j)
        ax.plot(t, q, "-", color=c, lw=1.6, label=f"actual q{j}")
        ax.plot(t, q_ref, "--", color="k", lw=0.9, label="desired" if i == 0 else None)
        ax_e.plot(t, q - q_ref, "-", color=c, lw=1.0, label=f"e{j}")
    ax.set_ylabel("joint angle [deg]")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    ax_e.set_ylabel("error [deg]")
    ax_e.set_xlabel("time [s]")
    ax_e.grid(True, alpha=0.3)
    ax_e.axhline(0.0, color="k", lw=0.5)
    ax.set_title(title or "position tracking: desired vs actual (cf. seed 000 Fig. 14)")
    fig.tight_layout()
    return fig


def _zero_lines(ax: Axes) -> None:
    """Axes lines through the origin where it lies in view, without widening the view to it
    (an arm's loop can sit far from the origin)."""
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    if y0 < 0.0 < y1:
        ax.axhline(0.0, color="k", lw=0.5)
    if x0 < 0.0 < x1:
        ax.axvline(0.0, color="k", lw=0.5)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)


def loops_figure(
    curves: Sequence[Curve],
    *,
    xlabel: str,
    ylabel: str,
    title: str,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
) -> Figure:
    """Any set of x-y curves on one axes, with axes through the origin (Fig. 6/7/9 layout)."""
    if not curves:
        raise InvalidParameterError("loops_figure needs at least one curve")
    fig, (ax,) = _new(size_in)
    for c in curves:
        # a curve that does not move in x (e.g. a held bend) would be an invisible dot
        still = len(c.x) > 0 and float(np.ptp(c.x)) < STILL_SPAN * (
            1.0 + float(np.max(np.abs(c.x)))
        )
        ax.plot(
            c.x, c.y, c.style, color=c.color, lw=1.2, label=c.label, marker="o" if still else None
        )
    _zero_lines(ax)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    fig.tight_layout()
    return fig


def _bend_note(cols: Columns, bend: str | None = "phi_b") -> str:
    if bend is None or bend not in cols:
        return ""
    b = _col(cols, bend) * RAD2DEG
    return f", φ_B = {b.mean():.0f}°" if np.ptp(b) < 0.5 else f", φ_B {b.min():.0f}…{b.max():.0f}°"


def torque_twist_figure(
    cols: Columns,
    *,
    twist: str = "twist",
    torque: str = "tau_shaft",
    model_torque: str | None = "tau_model",
    bend: str | None = "phi_b",
    title: str | None = None,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
) -> Figure:
    """Seed 000 Fig. 6/7 style: shaft torque vs twist Δθ; the true (plant) loop solid, the
    controller's eq. 8 model (virtual torque sensor) dashed when ``model_torque`` is given."""
    x = _col(cols, twist) * RAD2DEG
    curves = [Curve(x, _col(cols, torque), "shaft torque τ (plant)", "-", "tab:blue")]
    if model_torque is not None and model_torque in cols:
        curves.append(Curve(x, _col(cols, model_torque), "model τ_m (eq. 8)", "--", "tab:orange"))
    if title is None:
        title = "shaft torque vs twist (cf. seed 000 Fig. 6/7)" + _bend_note(cols, bend)
    return loops_figure(
        curves, xlabel="twist Δθ [deg]", ylabel="torque [N·m]", title=title, size_in=size_in
    )


def bending_figure(
    cols: Columns,
    *,
    bend: str = "phi_b",
    bend_torque: str = "tau_bend",
    conduit_torque: str | None = "tau_conduit",
    title: str | None = None,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
) -> Figure:
    """Seed 000 Fig. 9 style: bending moment M vs bend φ_B. ``bend_torque`` is the torque the
    shaft puts on the bend joint, so M = -bend_torque (positive M resists positive bend). The
    part without the visco-elastic conduit (whose hysteresis opens the loop) is drawn dashed."""
    x = _col(cols, bend) * RAD2DEG
    m = -_col(cols, bend_torque)
    curves = [Curve(x, m, "moment M (total)", "-", "tab:blue")]
    if conduit_torque is not None and conduit_torque in cols:
        curves.append(
            Curve(x, m + _col(cols, conduit_torque), "without conduit (elastic)", "--", "tab:gray")
        )
    fig = loops_figure(
        curves,
        xlabel="bend φ_B [deg]",
        ylabel="bending moment M [N·m]",
        title=title or "bending moment vs bend (cf. seed 000 Fig. 9)",
        size_in=size_in,
    )
    if len(x) and np.ptp(x) < 0.5:
        fig.axes[0].text(
            0.02,
            0.95,
            f"the bend is held near {x.mean():.1f}° in this run: no bending loop",
            transform=fig.axes[0].transAxes,
            va="top",
            fontsize="small",
        )
    return fig


def check_output(formats: Sequence[str], dpi: int) -> None:
    """Named errors for unknown formats or a non-positive dpi (checked before any run)."""
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise InvalidParameterError(f"figure formats must be among {FORMATS}, got {list(formats)}")
    if dpi <= 0 or dpi > 1200:
        raise InvalidParameterError(f"dpi must be between 1 and 1200, got {dpi}")


def save_figure(
    fig: Figure, stem: Path, formats: Sequence[str] = ("png",), dpi: int = DEFAULT_DPI
) -> list[Path]:
    """Write ``stem.<fmt>`` for each format; return the paths."""
    check_output(formats, dpi)
    stem.parent.mkdir(parents=True, exist_ok=True)
    paths = []
    for f in formats:
        p = stem.with_name(f"{stem.name}.{f}")
        fig.savefig(p, dpi=dpi)
        paths.append(p)
    return paths


FIGURE_KINDS = ("tracking", "torque_twist", "bending")
# below these ranges a loop figure is a dot: nothing to read from it (the bend held, or a twist
# of a few encoder counts)
MIN_BEND_RANGE_DEG = 0.5
MIN_TWIST_RANGE_DEG = 0.01


def skip_reason(kind: str, cols: Columns) -> str:
    """Why the ``kind`` figure of a run would carry no information ("" when it would)."""
    if kind == "bending" and "phi_b" in cols:
        b = _col(cols, "phi_b") * RAD2DEG
        if len(b) == 0 or np.ptp(b) < MIN_BEND_RANGE_DEG:
            held = f" at {b.mean():.1f}°" if len(b) else ""
            return f"the bend is held{held} in this run: no bending loop to draw"
    if kind == "torque_twist" and "twist" in cols:
        x = _col(cols, "twist") * RAD2DEG
        if len(x) == 0 or np.ptp(x) < MIN_TWIST_RANGE_DEG:
            return "the shaft barely twists in this run: no torque-twist loop to draw"
    return ""


def run_figures(
    result: RunResult,
    out_dir: Path,
    *,
    formats: Sequence[str] = ("png",),
    dpi: int = DEFAULT_DPI,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
    skipped: dict[str, str] | None = None,
) -> list[Path]:
    """The figures of one arm run that carry information: ``<out_dir>/<scenario>_<kind>.<fmt>``
    for each of :data:`FIGURE_KINDS` whose :func:`skip_reason` is empty; ``skipped`` (if given)
    receives the reasons of the others by kind."""
    cols, name = result.columns, result.scenario
    sh = result.config.shaft
    tag = (
        f"{name} (D={sh.diameter_mm:g} mm, L={sh.length_mm:g} mm, {result.config.payload_kg:g} kg)"
    )
    makers: dict[str, Callable[[], Figure]] = {
        "tracking": lambda: tracking_figure(
            cols, size_in=size_in, title=f"position tracking (cf. Fig. 14)\n{tag}"
        ),
        "torque_twist": lambda: torque_twist_figure(
            cols,
            size_in=size_in,
            title=f"shaft torque vs twist (cf. Fig. 6/7){_bend_note(cols)}\n{tag}",
        ),
        "bending": lambda: bending_figure(
            cols, size_in=size_in, title=f"bending moment vs bend (cf. Fig. 9)\n{tag}"
        ),
    }
    paths: list[Path] = []
    for kind in FIGURE_KINDS:
        reason = skip_reason(kind, cols)
        if reason:
            if skipped is not None:
                skipped[kind] = reason
            continue
        paths += save_figure(makers[kind](), Path(out_dir) / f"{name}_{kind}", formats, dpi)
    return paths


def all_scenario_figures(
    out_dir: Path,
    config: SimConfig | None = None,
    *,
    scenarios: Sequence[str] | None = None,
    duration_s: float | None = None,
    formats: Sequence[str] = ("png",),
    dpi: int = DEFAULT_DPI,
    size_in: tuple[float, float] = DEFAULT_SIZE_IN,
    skipped: dict[str, str] | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> dict[str, list[Path]]:
    """Run every registered scenario (or ``scenarios``) and write its figures; ``skipped``
    receives ``{"<scenario>_<kind>": reason}`` for the figures left out (:func:`skip_reason`);
    ``progress(scenario, done, total)`` is called before each scenario."""
    from fsarm_sim.sim import scenarios as registry
    from fsarm_sim.sim.simulation import run_scenario

    check_output(formats, dpi)
    names = list(scenarios) if scenarios is not None else list(registry.REGISTRY)
    out: dict[str, list[Path]] = {}
    for i, name in enumerate(names):
        if progress is not None:
            progress(name, i, len(names))
        result = run_scenario(name, config, duration_s=duration_s)
        notes: dict[str, str] = {}
        out[name] = run_figures(
            result, out_dir, formats=formats, dpi=dpi, size_in=size_in, skipped=notes
        )
        if skipped is not None:
            skipped.update({f"{name}_{kind}": why for kind, why in notes.items()})
    return out
