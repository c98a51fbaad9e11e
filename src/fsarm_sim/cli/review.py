"""Review outputs of the CLI: Rerun recordings and static figures.

* ``fsarm run SCENARIO --rrd FILE [--rrd-rate HZ] [--spawn] [--figures DIR]`` (options of ``run``,
  handled by :func:`review_outputs` after the run, so they cannot change its results);
* ``fsarm figures --out DIR``: every scenario's static figures in one command.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console

from fsarm_sim.choices import FigureFormat, Scenario
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan, SafeWriter

if TYPE_CHECKING:
    from fsarm_sim.sim.simulation import RunResult


def review_outputs(
    result: RunResult,
    *,
    rrd: Path | None,
    rrd_rate: float | None,
    spawn: bool,
    figures_dir: Path | None,
    out: Path,
    console: Console,
    writes: SafeWriter | None = None,
    compare: tuple[str, str, RunResult] | None = None,
) -> None:
    """Write the recording / figures a ``run`` asked for and report where they are (through
    ``writes``: a failed write goes to a rescue folder instead of being lost). ``compare``:
    (this run's name, the other's name, the other run) - both go into one recording."""
    w = writes if writes is not None else SafeWriter()
    if rrd is not None or spawn:
        from fsarm_sim.review.recording import DEFAULT_RATE_HZ, record_run, spawn_viewer

        rate = DEFAULT_RATE_HZ if rrd_rate is None else rrd_rate

        def write(p: Path) -> Path:
            if compare is None:
                return record_run(result, p, rate)
            from fsarm_sim.review.comparison import record_runs

            return record_runs([(compare[0], result), (compare[1], compare[2])], p, rate)

        path = w.write(
            rrd if rrd is not None else out / f"{result.scenario}.rrd",
            write,
            "the Rerun recording (--rrd)",
        )
        if path is not None:
            console.print(f"rerun recording: {path}")
            if spawn:
                console.print(spawn_viewer(path), markup=False)
    if figures_dir is not None:
        _write_run_figures(result, figures_dir, console, w)
    if writes is None:
        w.finish()


def _write_run_figures(
    result: RunResult, figures_dir: Path, console: Console, writes: SafeWriter
) -> None:
    """The run's figures (--figures) and the kinds it could not draw, with why."""
    from fsarm_sim.review.figures import run_figures

    skipped: dict[str, str] = {}
    paths = writes.write(
        figures_dir,
        lambda d: run_figures(result, d, skipped=skipped),
        "the figures (--figures)",
        folder=True,
    )
    if paths is not None:
        console.print(f"figures: {', '.join(str(p) for p in paths)}", markup=False)
    for kind, why in skipped.items():
        console.print(f"no {kind} figure: {why}", markup=False)


# the options of `figures_cmd`
FiguresOut = Annotated[Path, typer.Option(help="folder for the figures")]
FiguresScenario = Annotated[
    list[Scenario] | None,
    typer.Option(
        help="scenario to draw (repeatable; default: every registered one)",
        case_sensitive=False,
    ),
]
FiguresFmt = Annotated[
    list[FigureFormat] | None,
    typer.Option(
        "--format", help="figure format (repeatable) [default: png]", case_sensitive=False
    ),
]
FiguresDpi = Annotated[int, typer.Option(help="resolution of raster formats")]
FiguresWidth = Annotated[float, typer.Option(help="figure width, inches")]
FiguresHeight = Annotated[float, typer.Option(help="figure height, inches")]
FiguresDuration = Annotated[
    float | None, typer.Option(help="simulated time per scenario, s (default: its own)")
]


def _check_figures(
    out: Path,
    scenario: list[Scenario] | None,
    fmt: list[FigureFormat] | None,
    dpi: int,
    size_in: tuple[float, float],
) -> tuple[list[str], list[str]]:
    """The size, scenarios, formats and --out folder checked before any run: the scenarios'
    names (default every registered one) and the formats (default png)."""
    from fsarm_sim.review.figures import FIGURE_KINDS, check_output
    from fsarm_sim.sim import scenarios

    for v, name in zip(size_in, ("--width", "--height"), strict=True):
        if not math.isfinite(v) or not 0.5 <= v <= 40.0:
            raise InvalidParameterError(f"{name} must be between 0.5 and 40 inches, got {v!r}")
    names = [str(s) for s in scenario] if scenario else list(scenarios.REGISTRY)
    for n in names:
        scenarios.get(n)  # unknown names fail before any run
    formats = [str(f) for f in fmt] if fmt else ["png"]
    check_output(formats, dpi)
    OutputPlan().folder(
        "--out",
        out,
        {
            f"{n}_{k}.{f}": f"the {k} figure of {n} ({f})"
            for n in dict.fromkeys(names)
            for k in FIGURE_KINDS
            for f in formats
        },
    ).check()
    return names, formats


def figures_cmd(
    out: FiguresOut = Path("figures"),
    scenario: FiguresScenario = None,
    fmt: FiguresFmt = None,
    dpi: FiguresDpi = 110,
    width: FiguresWidth = 6.4,
    height: FiguresHeight = 4.0,
    duration: FiguresDuration = None,
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
) -> None:
    """Run every scenario and write its figures: tracking (Fig. 14 style), torque vs twist
    (Fig. 6/7) and bending moment vs bend (Fig. 9), as <out>/<scenario>_<kind>.<format>."""
    from fsarm_sim.cli.progress import steps
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.review.figures import all_scenario_figures

    names, formats = _check_figures(out, scenario, fmt, dpi, (width, height))
    cfg = SimConfig(shaft=load_catalogue().shaft(diameter_mm, length_mm))
    console = make_console()
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    skipped: dict[str, str] = {}
    with steps("figures") as progress:
        written = writes.write(
            out,
            lambda d: all_scenario_figures(
                d,
                cfg,
                scenarios=names,
                duration_s=duration,
                formats=formats,
                dpi=dpi,
                size_in=(width, height),
                skipped=skipped,
                progress=progress,
            ),
            "the figures (--out)",
            folder=True,
        )
    for name, paths in (written or {}).items():
        console.print(f"{name}: {', '.join(str(p) for p in paths)}", markup=False)
    for fig, why in skipped.items():
        console.print(f"no {fig} figure: {why}", markup=False)
    writes.finish()


def register(app: typer.Typer) -> None:
    app.command("figures")(figures_cmd)
