"""``fsarm bench-speed``: the speed benchmark of issue 4 (:mod:`fsarm_sim.studies.speed`). Thin: options
in, the report printed (and written as JSON)."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Annotated

import typer

# The benchmark (and the simulator) is imported inside the command, so that registering it keeps
# `fsarm` quick to start.


def bench_speed_cmd(
    reps: Annotated[int, typer.Option(help="repetitions of each per-step timing")] = 15,
    quick: Annotated[bool, typer.Option(help="fewer repetitions, shorter runs")] = False,
    max_workers: Annotated[
        int | None, typer.Option(help="largest number of batch workers (default: all cores)")
    ] = None,
    json_file: Annotated[
        Path | None, typer.Option("--json", help="also write the numbers as JSON here")
    ] = None,
) -> None:
    """Time raw MuJoCo vs the Python and native callbacks (full model and lean twin), the
    real-time factor with and without logging, whole `fsarm run` processes, a sweep and
    batch scaling - side by side in one run."""
    from fsarm_sim.errors import whole_number
    from fsarm_sim.executors import check_workers
    from fsarm_sim.outputs import OutputPlan, SafeWriter, write_text
    from fsarm_sim.studies.speed import MAX_REPS, format_report, measure_speed

    whole_number(reps, "--reps", 1, MAX_REPS)  # checked with --quick too, which sets its own
    check_workers(max_workers, "--max-workers")
    OutputPlan().file("--json", json_file).check()
    report = (
        measure_speed(
            reps=5,
            rtf_reps=2,
            rtf_duration_s=2.0,
            batch_reps=2,
            max_workers=max_workers,
            process_reps=1,
            sweep_reps=0,
        )
        if quick
        else measure_speed(reps=reps, max_workers=max_workers)
    )
    writes = SafeWriter(lambda msg: typer.echo(f"warning: {msg}", err=True))
    where = None
    if json_file is not None:  # saved before anything is printed
        text = json.dumps(asdict(report), indent=2)
        where = writes.write(json_file, lambda p: write_text(p, text), "the numbers (--json)")
    typer.echo(format_report(report))
    if where is not None:
        typer.echo(f"numbers: {where}")
    writes.finish()


def register(app: typer.Typer) -> None:
    app.command("bench-speed")(bench_speed_cmd)
