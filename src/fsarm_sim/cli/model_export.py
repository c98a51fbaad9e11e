"""``fsarm export-mjcf``: the standalone scene for the stock MuJoCo viewer."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.outputs import check_file_path, safe_write, write_text

console = make_console()


def export_mjcf_cmd(
    out: Annotated[Path, typer.Argument(help="the MJCF file to write (.xml)")],
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    bend_deg: Annotated[
        float, typer.Option(help="the bend at which the shaft's stiffness is linearised, °")
    ] = 45.0,
    payload_kg: Annotated[float, typer.Option(help="payload at the flange, kg (0-15)")] = 0.0,
) -> None:
    """Write a self-contained MJCF scene for the stock MuJoCo viewer (`python -m
    mujoco.viewer --mjcf OUT`): the shaft as its linearised stiffness (an approximation,
    stated in the file), position servos on q1, q2 and the elbow's motor."""
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.engine.standalone import linear_shaft_stiffness, standalone_xml
    from fsarm_sim.plant.shaft import load_catalogue

    path = check_file_path("OUT", out)
    shaft = load_catalogue(shaft_file).shaft(
        diameter_mm=diameter_mm, length_mm=length_mm, extrapolate=extrapolate
    )
    config = SimConfig(shaft=shaft, payload_kg=payload_kg)
    bend = math.radians(bend_deg)
    text = standalone_xml(config, bend)
    safe_write(path, lambda p: write_text(p, text), "the MJCF scene")
    console.print(
        f"wrote {path}: shaft as a linear spring of {linear_shaft_stiffness(config, bend):.4g} "
        f"N·m/rad (bent {bend_deg:g}°); open it with `python -m mujoco.viewer --mjcf {path}`"
    )


def register(app: typer.Typer) -> None:
    app.command("export-mjcf")(export_mjcf_cmd)
