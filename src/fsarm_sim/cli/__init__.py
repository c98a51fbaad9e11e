"""The ``fsarm`` command. Thin: parse arguments, call the library, print tables."""

from __future__ import annotations

import contextlib
import importlib
import math
import sys
from pathlib import Path
from typing import Annotated

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
    preload,
)
from fsarm_sim.outputs import guarded_streams

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
    scenario_choice: Annotated[
        choices.Scenario,
        typer.Argument(
            metavar="SCENARIO",
            help="scenario (`fsarm scenarios` describes them)",
            case_sensitive=False,
            show_default=False,
        ),
    ],
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
    payload_kg: Annotated[
        float | None, typer.Option(help="payload at the flange, kg (default: the scenario's)")
    ] = None,
    duration: Annotated[
        float | None, typer.Option(help="simulated time, s (default: the scenario's)")
    ] = None,
    out: Annotated[Path, typer.Option(help="folder for the time series and its sidecar")] = Path(
        "runs"
    ),
    json_file: Annotated[
        Path | None, typer.Option("--json", help="write a JSON summary here")
    ] = None,
    fmt: Annotated[
        choices.TimeseriesFormat,
        typer.Option("--format", help="time-series format", case_sensitive=False),
    ] = choices.TimeseriesFormat.CSV,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    series_hysteresis: Annotated[
        bool | None,
        typer.Option(
            help="Maxwell-slip series hysteresis on/off "
            "(default: the coefficient file's series.maxwell_slip.enabled)"
        ),
    ] = None,
    integrator: Annotated[
        choices.Integrator | None,
        typer.Option(help="MuJoCo's integrator [default: the model's]", case_sensitive=False),
    ] = None,
    timestep: Annotated[
        float | None, typer.Option(help="physics timestep, s (default 0.001)")
    ] = None,
    ctrl_dt: Annotated[float, typer.Option(help="control period, s")] = 0.001,
    log_every: Annotated[int, typer.Option(help="log one row every N control ticks")] = 1,
    backend: opt.Backend = choices.Backend.NATIVE,
    rrd: Annotated[
        Path | None, typer.Option(help="write a Rerun recording (.rrd) of the run here")
    ] = None,
    rrd_rate: Annotated[
        float | None, typer.Option(help="recording rate, rows per simulated s (default 100)")
    ] = None,
    spawn: Annotated[
        bool, typer.Option(help="open the recording in the Rerun viewer if one can run here")
    ] = False,
    figures: Annotated[
        Path | None, typer.Option(help="write the run's static figures (PNG) into this folder")
    ] = None,
    rrd_compare: Annotated[
        list[str] | None,
        typer.Option(
            help="also run with KEY=VALUE changed (series-hysteresis=on|off, diameter-mm, "
            "length-mm, payload-kg, backend; repeatable) and record both into --rrd"
        ),
    ] = None,
    transmission: opt.Transmission = choices.Transmission.FLEXIBLE_SHAFT,
    tr_param: opt.TrParam = None,
    controller: opt.Controller = choices.Controller.DEFAULT,
    hysteresis_model: opt.HysteresisModelFile = None,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
    effect: opt.Effect = None,
) -> None:
    """Run a scenario headless, print tracking metrics, write its time series."""
    scenario = str(scenario_choice)
    from fsarm_sim.cli.review import check_review_options, review_outputs, run_output_plan
    from fsarm_sim.engine.model import Effects, Gains, SimConfig
    from fsarm_sim.outputs import SafeWriter
    from fsarm_sim.plant.effects.registry import parse_laws
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.records.timeseries import write_summary, write_timeseries
    from fsarm_sim.sim.simulation import run_scenario

    check_review_options(rrd_rate)
    from fsarm_sim.cli.review import parse_compare

    compare_changes = parse_compare(rrd_compare or [], rrd)
    from fsarm_sim.cli.transmissions import check_shaft_options, parse_params

    shaft_flags = {
        "diameter_mm": "--diameter-mm",
        "length_mm": "--length-mm",
        "shaft_file": "--shaft-file",
        "extrapolate": "--extrapolate",
        "series_hysteresis": "--[no-]series-hysteresis",
    }
    given = [
        flag
        for name, flag in shaft_flags.items()
        # (by name: typer 0.28 carries its own click, whose enum is not click's)
        if getattr(ctx.get_parameter_source(name), "name", "") == "COMMANDLINE"
    ]
    compared = {"diameter-mm", "length-mm", "series-hysteresis"} & set(compare_changes)
    check_shaft_options(str(transmission), given + [f"--rrd-compare {k}" for k in sorted(compared)])
    if uncertainty:
        from fsarm_sim.cli.uncertainty import check_run_uncertainty

        check_run_uncertainty(
            uncertainty, str(transmission), shaft_file, str(uncertainty_controller)
        )
    run_output_plan(
        scenario, str(fmt), out=out, json_file=json_file, rrd=rrd, spawn=spawn, figures=figures
    ).input("the coefficient file of --shaft-file", shaft_file).input(
        "the hysteresis model of --hysteresis-model", hysteresis_model
    ).check()
    shaft = load_catalogue(shaft_file).shaft(
        diameter_mm, length_mm, extrapolate=extrapolate, series_hysteresis=series_hysteresis
    )
    cfg = SimConfig(
        shaft=shaft,
        gains=Gains(
            ctrl_dt_s=ctrl_dt,
            controller=str(controller),
            hysteresis_model=opt.read_hysteresis_model(hysteresis_model),
        ),
        timestep_s=timestep,
        integrator=None if integrator is None else str(integrator),
        transmission=str(transmission),
        transmission_params=parse_params(tr_param or []),
        effects=Effects(laws=parse_laws(effect or [])),
    )
    if backend == "native":
        # the kernels, which the run would load anyway, now: this thread then imports nothing
        # of its own while the writer is imported beside the run
        from fsarm_sim.engine.callbacks import load_native

        load_native()
    preload("pyarrow.csv" if fmt == "csv" else "pyarrow.parquet")  # while the run steps
    try:
        result = run_scenario(
            scenario,
            cfg,
            duration_s=duration,
            payload_kg=payload_kg,
            backend=str(backend),  # type: ignore[arg-type]
            log_every_ticks=log_every,
            keep_partial=True,  # a long run cut by Ctrl-C keeps its finished part
        )
    except KeyboardInterrupt:
        err_console.print("[bold yellow]interrupted[/] before anything was recorded: no output")
        raise typer.Exit(130) from None
    # the finished work is saved before anything is printed
    writes = SafeWriter(lambda msg: err_console.print(f"[bold yellow]warning:[/] {escape(msg)}"))
    path = writes.write(
        out, lambda d: write_timeseries(result, d, str(fmt)), "the time series (--out)", folder=True
    )

    def summary(p: Path) -> Path:
        write_summary(result, p)
        return p

    where = None if json_file is None else writes.write(json_file, summary, "the summary (--json)")
    m = result.metrics
    if result.interrupted:
        err_console.print(
            f"[bold yellow]interrupted[/] at t = {result.duration_s:.3f} s: metrics and time series "
            "cover the finished part only"
        )
    tr_model = result.config.transmission_model()
    what = (
        f"D={diameter_mm:g} mm, L={length_mm:g} mm"
        if tr_model.takes_shaft
        else f"transmission {transmission}"
        + (
            f" (bending on joint 2: D={diameter_mm:g} mm, L={length_mm:g} mm shaft)"
            if tr_model.routed_over_joint2
            else ""
        )
    )
    if controller != "default":
        what += f", controller {controller}"
    table = Table(title=f"{scenario}: {what}, payload={result.config.payload_kg:g} kg")
    table.add_column("metric")
    for j in ("q1", "q2", "q3"):
        table.add_column(j, justify="right")
    for key, label in (("rmse_deg", r"RMSE \[deg]"), ("max_abs_err_deg", r"max |error| \[deg]")):
        vals = m[key]
        assert isinstance(vals, dict)
        table.add_row(label, *(f"{vals[j]:.4f}" for j in ("q1", "q2", "q3")))
    console.print(table)
    for key, label in (
        ("tau_estimate_rmse_nm", "joint-3 torque estimate error, RMSE [N·m]"),
        ("tau_estimate_max_abs_err_nm", "joint-3 torque estimate error, max [N·m]"),
        ("peak_shaft_torque_nm", "peak shaft torque [N·m]"),
        ("peak_motor_torque_nm", "peak joint-3 motor torque [N·m]"),
        ("peak_motor_speed_rad_s", "peak joint-3 motor speed [rad/s]"),
        ("motor_energy_j", "joint-3 motor work [J]"),
        ("realtime_factor", "real-time factor"),
    ):
        console.print(f"{label:<45} {m[key]:.4g}", markup=False)
    over = m["peak_shaft_torque_over_rating"]
    if isinstance(over, float) and over > 1.0:
        advice = (
            f"for D = {diameter_mm:g} mm): choose a thicker shaft"
            if result.config.transmission_model().takes_shaft
            else f"of {transmission})"
        )
        err_console.print(
            f"[bold yellow]warning:[/] peak transmission torque is {over:.1f}x the nominal "
            f"rating ({result.config.rating_nm():.2f} N·m {advice}"
        )
    for warning in result.warnings:
        err_console.print(f"[bold yellow]warning:[/] {escape(warning)}")
    if path is not None:
        console.print(f"time series: {path}  (sidecar {path.with_suffix('.json')})")
    if where is not None:
        console.print(f"summary: {where}")
    compare = None
    if compare_changes:
        from fsarm_sim.cli.review import compare_run

        compare = compare_run(
            compare_changes,
            result,
            shaft_file=shaft_file,
            extrapolate=extrapolate,
            series_hysteresis=series_hysteresis,
            backend=str(backend),
            log_every=log_every,
        )
    if uncertainty:
        from fsarm_sim.cli.uncertainty import run_uncertainty

        run_uncertainty(
            uncertainty,
            result,
            shaft_file=shaft_file,
            diameter_mm=diameter_mm,
            length_mm=length_mm,
            extrapolate=extrapolate,
            series_hysteresis=series_hysteresis,
            backend=backend,
            json_file=json_file,
            writes=writes,
            controller=str(uncertainty_controller),
        )
    review_outputs(
        result,
        rrd=rrd,
        rrd_rate=rrd_rate,
        spawn=spawn,
        figures_dir=figures,
        out=out,
        console=console,
        writes=writes,
        compare=compare,
    )
    writes.finish()
    if result.interrupted:
        raise typer.Exit(130)


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
