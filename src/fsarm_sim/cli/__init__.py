"""The ``fsarm`` command. Thin: parse arguments, call the library, print tables."""

from __future__ import annotations

import contextlib
import importlib
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim import choices
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.errors import FsarmError
from fsarm_sim.lazy_commands import (
    LazyTyper,
    command_name,
    freeze_at_exit,
    freeze_imports_if_entry,
)
from fsarm_sim.outputs import guarded_streams

if TYPE_CHECKING:
    from fsarm_sim.run_request import RunRequest
    from fsarm_sim.sim.simulation import RunResult

# the extension modules' commands are registered when first needed (fsarm_sim.lazy_commands)
app = LazyTyper(
    register_extensions=lambda: _register_extensions(),
    help="Flexible-shaft arm simulator (MuJoCo). Run scenarios headless and report tracking metrics.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = make_console()
err_console = make_console(stderr=True)


@app.command("scenarios")
def scenarios_cmd() -> None:
    """List the registered scenarios."""
    from fsarm_sim.sim import scenarios

    table = Table(title="fsarm scenarios")
    for col in ("name", "duration [s]", "payload [kg]", "description"):
        table.add_column(escape(col))
    for sc in scenarios.REGISTRY.values():
        table.add_row(sc.name, f"{sc.duration_s:g}", f"{sc.payload_kg:g}", sc.description)
    console.print(table)


@app.command("shafts")
def shafts_cmd(
    shaft_file: opt.ShaftFile = None,
    export: Annotated[
        Path | None,
        typer.Option(
            help="write the coefficient file (with every comment: a template for your own "
            "bench) to this path instead of listing it"
        ),
    ] = None,
) -> None:
    """List the catalogue's bench shafts with their eq. 3/4 stiffnesses."""
    from fsarm_sim.outputs import check_file_path, safe_write, write_text
    from fsarm_sim.plant.shaft import catalogue_text, load_catalogue

    cat = load_catalogue(shaft_file)
    if export is not None:
        path = check_file_path("--export", export)
        text = catalogue_text(shaft_file)
        safe_write(path, lambda p: write_text(p, text), "the coefficient template")
        console.print(
            f"wrote {path}: edit its numbers, then `fsarm run SCENARIO --shaft-file {path}`"
        )
        return
    table = number_table(
        f"shafts of {cat.source}",
        ("name", "D [mm]", "L [mm]", "K_sp(0)", "K_sn(0)", "K_sp(90°)", "K_b", "rating [N·m]"),
    )
    for s in cat.shafts:
        p = cat.shaft(s.diameter_mm, s.length_mm)
        table.add_row(
            s.name,
            f"{s.diameter_mm:g}",
            f"{s.length_mm:g}",
            f"{p.k_series(0.0, 1):.2f}",
            f"{p.k_series(0.0, -1):.2f}",
            f"{p.k_series(math.pi / 2, 1):.2f}",
            f"{p.kb_eq4:.2f}",  # eq. 4 (what eq. 2's test identifies)
            f"{p.rating_nm:.2f}",
        )
    console.print(table)
    console.print("stiffness in N·m/rad; all coefficients are documented estimates (see the file)")


@app.command("run")
def run_cmd(
    ctx: typer.Context,
    scenario_choice: opt.ScenarioArgument,
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
    payload_kg: opt.PayloadKg = None,
    duration: opt.Duration = None,
    out: opt.RunOut = Path("runs"),
    json_file: opt.SummaryJson = None,
    fmt: opt.Format = choices.TimeseriesFormat.CSV,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    series_hysteresis: opt.SeriesHysteresis = None,
    integrator: opt.Integrator = None,
    timestep: opt.Timestep = None,
    ctrl_dt: opt.CtrlDt = 0.001,
    log_every: opt.LogEvery = 1,
    backend: opt.Backend = choices.Backend.NATIVE,
    rrd: opt.Rrd = None,
    rrd_rate: opt.RrdRate = None,
    spawn: opt.Spawn = False,
    figures: opt.Figures = None,
    rrd_compare: opt.RrdCompare = None,
    transmission: opt.Transmission = choices.Transmission.FLEXIBLE_SHAFT,
    tr_param: opt.TrParam = None,
    controller: opt.Controller = choices.Controller.DEFAULT,
    hysteresis_model: opt.HysteresisModelFile = None,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
    effect: opt.Effect = None,
) -> None:
    """Run a scenario headless, print tracking metrics, write its time series."""
    from fsarm_sim.run_request import SHAFT_OPTIONS, RunRequest, run_output_plan

    options = {**locals(), "scenario": scenario_choice}
    # (by name: typer 0.28 carries its own click, whose enum is not click's)
    given = tuple(
        name
        for name in SHAFT_OPTIONS
        if getattr(ctx.get_parameter_source(name), "name", "") == "COMMANDLINE"
    )
    request = RunRequest.from_options(options, given)
    request.check()
    run_output_plan(request).check()
    _run(request)


def _run(request: RunRequest) -> None:
    """Run a checked request; save its files before anything is printed, then report."""
    from fsarm_sim.cli.review import review_outputs
    from fsarm_sim.outputs import SafeWriter

    try:
        result = request.run()
    except KeyboardInterrupt:
        err_console.print("[bold yellow]interrupted[/] before anything was recorded: no output")
        raise typer.Exit(130) from None
    writes = SafeWriter(lambda msg: err_console.print(f"[bold yellow]warning:[/] {escape(msg)}"))
    path, where = request.save(result, writes)
    _print_run(request, result)
    if path is not None:
        console.print(f"time series: {path}  (sidecar {path.with_suffix('.json')})")
    if where is not None:
        console.print(f"summary: {where}")
    compare = request.compare_run(result)
    if request.uncertainty:
        from fsarm_sim.cli.uncertainty import run_uncertainty

        run_uncertainty(request, result, writes)
    review_outputs(
        result,
        rrd=request.rrd,
        rrd_rate=request.rrd_rate,
        spawn=request.spawn,
        figures_dir=request.figures,
        out=request.out,
        console=console,
        writes=writes,
        compare=compare,
    )
    writes.finish()
    if result.interrupted:
        raise typer.Exit(130)


def _print_run(request: RunRequest, result: RunResult) -> None:
    """The run's metrics table and lines, and its warnings."""
    m = result.metrics
    if result.interrupted:
        err_console.print(
            f"[bold yellow]interrupted[/] at t = {result.duration_s:.3f} s: metrics and time series "
            "cover the finished part only"
        )
    table = Table(title=request.title(result))
    table.add_column("metric")
    for j in ("q1", "q2", "q3"):
        table.add_column(j, justify="right")
    for key, label in (("rmse_deg", r"RMSE \[deg]"), ("max_abs_err_deg", r"max |error| \[deg]")):
        vals = m[key]
        assert isinstance(vals, dict)
        table.add_row(label, *(f"{vals[j]:.4f}" for j in ("q1", "q2", "q3")))
    console.print(table)
    for key, label in RUN_LINES:
        console.print(f"{label:<45} {m[key]:.4g}", markup=False)
    warning = request.rating_warning(result)
    if warning is not None:
        err_console.print(f"[bold yellow]warning:[/] {warning}")
    for warning in result.warnings:
        err_console.print(f"[bold yellow]warning:[/] {escape(warning)}")


RUN_LINES = (
    ("tau_estimate_rmse_nm", "joint-3 torque estimate error, RMSE [N·m]"),
    ("tau_estimate_max_abs_err_nm", "joint-3 torque estimate error, max [N·m]"),
    ("peak_shaft_torque_nm", "peak shaft torque [N·m]"),
    ("peak_motor_torque_nm", "peak joint-3 motor torque [N·m]"),
    ("peak_motor_speed_rad_s", "peak joint-3 motor speed [rad/s]"),
    ("motor_energy_j", "joint-3 motor work [J]"),
    ("realtime_factor", "real-time factor"),
)


def _register_extensions() -> None:
    """Commands defined in their own modules (one line each)."""
    importlib.import_module("fsarm_sim.cli.review").register(app)
    importlib.import_module("fsarm_sim.cli.speed").register(app)
    importlib.import_module("fsarm_sim.cli.dynamics").register(app)
    importlib.import_module("fsarm_sim.cli.sweep").register(app)
    importlib.import_module("fsarm_sim.cli.discrepancy").register(app)
    importlib.import_module("fsarm_sim.cli.transmissions").register(app)
    importlib.import_module("fsarm_sim.cli.controllers").register(app)
    importlib.import_module("fsarm_sim.cli.collision").register(app)
    importlib.import_module("fsarm_sim.cli.reproduce").register(app)
    importlib.import_module("fsarm_sim.cli.seed_experiments").register(app)
    importlib.import_module("fsarm_sim.cli.model_export").register(app)
    importlib.import_module("fsarm_sim.cli.design").register(app)


app.ready()


def main() -> None:
    """Entry point: named errors become one red line and exit code 2, never a traceback. A
    failing standard output (a full device, a closed terminal) stops no command's work: the
    files are written, the error is named at the end (a reader that closed the pipe, as
    ``| head`` does, is no error)."""
    import errno

    from fsarm_sim.paths import os_problem

    # a command defined in this module (`fsarm run ...`) needs none of the extension modules
    core = command_name(sys.argv[1:]) in app.core_names()
    freeze_imports_if_entry(main)  # the garbage collector skips the imports' objects
    freeze_at_exit()
    code: int | str | None = 0
    with guarded_streams() as (out, _):
        try:
            with app.core_only() if core else contextlib.nullcontext():
                # not standalone: Typer's usage errors come here, to be printed as one line
                returned = app(standalone_mode=False, prog_name="fsarm")
            code = returned if isinstance(returned, int) else 0
        except typer.TyperException as exc:  # a usage error: bad choice, missing argument...
            code = exc.exit_code
            if type(exc).__name__ != "NoArgsIsHelpError":  # (that one printed the help)
                _error_line(_usage_message(exc))
        except typer.Abort:
            _error_line("aborted")
            code = 1
        except FsarmError as exc:
            _error_line(str(exc).strip())
            code = 2
        except OSError as exc:  # the file system failed where no command named it
            where = f" ({exc.filename})" if exc.filename else ""
            _error_line(f"{os_problem(exc)}{where}")
            code = 2
        except SystemExit as exc:
            code = exc.code
    if out.error is not None and out.error.errno != errno.EPIPE:
        _error_line(
            f"standard output could not be written ({os_problem(out.error)}): what the command "
            "printed is lost; the files it wrote are kept"
        )
        code = code or 2
    raise SystemExit(code)


def _usage_message(exc: typer.TyperException) -> str:
    """A usage error as one line, with where to read the command's options."""
    ctx = getattr(exc, "ctx", None)
    where = f" (see `{ctx.command_path} --help`)" if ctx is not None else ""
    return " ".join(exc.format_message().split()) + where


def _error_line(message: str) -> None:
    with contextlib.suppress(OSError):  # a closed terminal: nothing left to tell
        err_console.print(f"[bold red]error:[/] {escape(message)}", soft_wrap=True)
