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

from fsarm_sim.console import make_console
from fsarm_sim.errors import InvalidParameterError

if TYPE_CHECKING:
    from fsarm_sim.simulation import RunResult


def check_review_options(rrd_rate: float | None) -> None:
    """Fail before the run, not after it, on a bad ``--rrd-rate``."""
    if rrd_rate is not None and (not math.isfinite(rrd_rate) or rrd_rate <= 0.0):
        raise InvalidParameterError(
            f"--rrd-rate must be a finite number of Hz > 0, got {rrd_rate!r}"
        )


def review_outputs(
    result: RunResult,
    *,
    rrd: Path | None,
    rrd_rate: float | None,
    spawn: bool,
    figures_dir: Path | None,
    out: Path,
    console: Console,
) -> None:
    """Write the recording / figures a ``run`` asked for and report where they are."""
    if rrd is not None or spawn:
        from fsarm_sim.recording import DEFAULT_RATE_HZ, record_run, spawn_viewer

        path = rrd if rrd is not None else out / f"{result.scenario}.rrd"
        record_run(result, path, DEFAULT_RATE_HZ if rrd_rate is None else rrd_rate)
        console.print(f"rerun recording: {path}")
        if spawn:
            console.print(spawn_viewer(path), markup=False)
    if figures_dir is not None:
        from fsarm_sim.figures import run_figures

        paths = run_figures(result, figures_dir)
        console.print(f"figures: {', '.join(str(p) for p in paths)}", markup=False)


def register(app: typer.Typer) -> None:
    @app.command("figures")
    def figures_cmd(
        out: Annotated[Path, typer.Option(help="folder for the figures")] = Path("figures"),
        scenario: Annotated[
            list[str] | None,
            typer.Option(help="scenario to draw (repeatable; default: every registered one)"),
        ] = None,
        fmt: Annotated[
            list[str] | None,
            typer.Option("--format", help="png, svg or pdf (repeatable; default png)"),
        ] = None,
        dpi: Annotated[int, typer.Option(help="resolution of raster formats")] = 110,
        width: Annotated[float, typer.Option(help="figure width, inches")] = 6.4,
        height: Annotated[float, typer.Option(help="figure height, inches")] = 4.0,
        duration: Annotated[
            float | None, typer.Option(help="simulated time per scenario, s (default: its own)")
        ] = None,
        diameter_mm: Annotated[float, typer.Option(help="shaft diameter D, mm")] = 9.0,
        length_mm: Annotated[float, typer.Option(help="shaft length L, mm")] = 450.0,
    ) -> None:
        """Run every scenario and write its figures: tracking (Fig. 14 style), torque vs twist
        (Fig. 6/7) and bending moment vs bend (Fig. 9), as <out>/<scenario>_<kind>.<format>."""
        from fsarm_sim import scenarios
        from fsarm_sim.figures import all_scenario_figures
        from fsarm_sim.model import SimConfig
        from fsarm_sim.shaft import load_catalogue

        for v, name in ((width, "--width"), (height, "--height")):
            if not math.isfinite(v) or not 0.5 <= v <= 40.0:
                raise InvalidParameterError(f"{name} must be between 0.5 and 40 inches, got {v!r}")
        names = scenario or list(scenarios.REGISTRY)
        for n in names:
            scenarios.get(n)  # unknown names fail before any run
        cfg = SimConfig(shaft=load_catalogue().shaft(diameter_mm, length_mm))
        console = make_console()
        written = all_scenario_figures(
            out,
            cfg,
            scenarios=names,
            duration_s=duration,
            formats=fmt or ["png"],
            dpi=dpi,
            size_in=(width, height),
        )
        for name, paths in written.items():
            console.print(f"{name}: {', '.join(str(p) for p in paths)}", markup=False)
