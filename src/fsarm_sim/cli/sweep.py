"""CLI commands: ``select-shaft``, ``sweep``, ``sweep-report``, ``bench series|parallel``,
``campaign``. Thin: parse, call :mod:`fsarm_sim.studies.shaft_selection`, :mod:`fsarm_sim.studies.sweep`,
:mod:`fsarm_sim.studies.campaign`, print tables."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim import choices
from fsarm_sim.choices import Executor, ShaftKind
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.bench import (
    bench_parallel_cmd,
    bench_series_cmd,
    campaign_cmd,
    parse_floats,
    print_comparisons,
)
from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.errors import FsarmError
from fsarm_sim.outputs import OutputPlan
from fsarm_sim.paths import checked_path

if TYPE_CHECKING:
    pass

console = make_console()


def _selection_table(title: str, selections: list[Any]) -> Table:
    """One row per selector's choice: D, L, K and its error, rating, whether it reaches K_des."""
    table = number_table(
        title,
        (
            "method",
            "D [mm]",
            "L [mm]",
            "K [N·m/rad]",
            "K − K_des",
            "rating [N·m]",
            "reaches K_des",
        ),
    )
    for s in selections:
        table.add_row(
            escape(s.method.split(" (")[0]),
            f"{s.diameter_mm:g}",
            f"{s.length_mm:.1f}",
            f"{s.k_nm_per_rad:.4g}",
            f"{s.error_nm_per_rad:+.3g} ({100 * s.relative_error:+.2g} %)",
            f"{s.rating_nm:.3g}",
            "yes" if s.feasible else "no",
        )
    return table


# the options of `select_shaft_cmd`
SelectShaftKDes = Annotated[float, typer.Option(help="desired stiffness K_des, N·m/rad")]
SelectShaftKind = Annotated[
    ShaftKind,
    typer.Option(help="series (eq. 3) or parallel (eq. 4)", case_sensitive=False),
]
SelectShaftBendDeg = Annotated[float, typer.Option(help="series: bend angle for K_des, deg")]
SelectShaftTorqueNm = Annotated[
    float,
    typer.Option(help="torque the shaft must carry, N·m (arm: joint-3 torque / i_G2)"),
]
SelectShaftLMin = Annotated[float | None, typer.Option(help="robot's L_min, mm")]
SelectShaftLMax = Annotated[float | None, typer.Option(help="robot's L_max, mm")]
SelectShaftSide = Annotated[
    int, typer.Option(help="series: +1 winding (K_sp), -1 unwinding (K_sn)")
]
SelectShaftDiameters = Annotated[
    str | None,
    typer.Option(help="available diameters, mm, comma-separated (default: the catalogue's)"),
]
SelectShaftSeed = Annotated[int, typer.Option(help="seed of Algorithm 1's random start length")]
SelectShaftTolerance = Annotated[float, typer.Option(help="accepted |K − K_des| / K_des")]
SelectShaftNearest = Annotated[
    bool, typer.Option(help="accept the nearest shaft if none reaches K_des")
]


def select_shaft_cmd(
    k_des: SelectShaftKDes,
    kind: SelectShaftKind = ShaftKind.SERIES,
    bend_deg: SelectShaftBendDeg = 0.0,
    torque_nm: SelectShaftTorqueNm = 0.0,
    l_min: SelectShaftLMin = None,
    l_max: SelectShaftLMax = None,
    side: SelectShaftSide = 1,
    diameters: SelectShaftDiameters = None,
    seed: SelectShaftSeed = 0,
    tolerance: SelectShaftTolerance = 0.01,
    nearest: SelectShaftNearest = False,
    shaft_file: opt.ShaftFile = None,
) -> None:
    """Choose a shaft for a desired stiffness: Algorithm 1 (seed 000) and the closed-form selector."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies.shaft_selection import SelectionRequest, algorithm1, select_shaft

    cat = load_catalogue(shaft_file)
    lrange = None
    if l_min is not None or l_max is not None:
        lrange = (
            l_min if l_min is not None else cat.length_range[0],
            l_max if l_max is not None else cat.length_range[1],
        )
    req = SelectionRequest(
        k_des=k_des,
        kind=str(kind),  # type: ignore[arg-type]
        bend_rad=math.radians(bend_deg),
        torque_nm=torque_nm,
        length_range_mm=lrange,
        side=side,
        diameters_mm=parse_floats(diameters, "--diameters"),
    )
    alg = algorithm1(cat, req, seed=seed, tolerance=tolerance)
    title = f"shaft for K_des = {k_des:g} N·m/rad ({kind}, bend {bend_deg:g}°, torque ≥ {torque_nm:g} N·m)"
    try:
        best = select_shaft(cat, req, tolerance=tolerance, nearest=nearest)
    except FsarmError:
        console.print(_selection_table(title, [alg]))
        raise
    console.print(_selection_table(title, [alg, best]))
    console.print(
        f"Algorithm 1 lands {alg.length_mm - best.length_mm:+.1f} mm and "
        f"{alg.k_nm_per_rad - best.k_nm_per_rad:+.3g} N·m/rad from the closed-form choice "
        f"(D {alg.diameter_mm:g} vs {best.diameter_mm:g} mm; {alg.iterations} iterations)",
        markup=False,
    )


# the options of `sweep_cmd`
SweepStore = Annotated[
    Path | None, typer.Option(help="results store (SQLite, required); rerun to resume")
]
SweepSpec = Annotated[Path | None, typer.Option(help="sweep spec (TOML)")]
SweepGrid = Annotated[
    list[str] | None,
    typer.Option(help="FIELD=VALUES to sweep: start:stop:count or v1,v2,... (repeatable)"),
]
SweepSet = Annotated[list[str] | None, typer.Option("--set", help="FIELD=VALUE fixed (repeatable)")]
SweepOutputs = Annotated[
    str | None, typer.Option(help="comma-separated: bench,tracking,bandwidth,relief")
]
SweepName = Annotated[str | None, typer.Option(help="sweep name stored with each point")]
SweepExecutor = Annotated[
    Executor,
    typer.Option(
        help="auto (threads when every point is a native simulation, else the process "
        "pool), local (process pool), threads (this process) or dask",
        case_sensitive=False,
    ),
]
SweepWorkers = Annotated[int | None, typer.Option(help="workers (default: all cores)")]
SweepScheduler = Annotated[
    str | None, typer.Option(help="Dask scheduler address, e.g. tcp://host:8786")
]
SweepOut = Annotated[
    Path | None, typer.Option(help="after the run: re-fit eq. 3/4 and write plots here")
]
SweepRetryFailed = Annotated[bool, typer.Option(help="recompute points that failed before")]
SweepDryRun = Annotated[bool, typer.Option(help="validate and count points, run nothing")]
SweepProgress = Annotated[bool, typer.Option(help="progress bar with ETA")]
SweepListFields = Annotated[bool, typer.Option(help="list the sweepable fields and exit")]


def sweep_cmd(
    store: SweepStore = None,
    spec: SweepSpec = None,
    grid: SweepGrid = None,
    set_: SweepSet = None,
    outputs: SweepOutputs = None,
    name: SweepName = None,
    executor: SweepExecutor = Executor.AUTO,
    workers: SweepWorkers = None,
    scheduler: SweepScheduler = None,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    out: SweepOut = None,
    retry_failed: SweepRetryFailed = False,
    dry_run: SweepDryRun = False,
    progress: SweepProgress = True,
    list_fields: SweepListFields = False,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
) -> None:
    """Sweep shafts, bends, payloads, gains and scenarios; store every point as it finishes."""
    from fsarm_sim.studies import sweep

    if list_fields:
        _print_fields()
        return
    store = _check_sweep_files(store, out, spec, shaft_file)
    the_spec = _sweep_spec(spec, grid, set_, name, outputs, shaft_file, extrapolate)
    pts = sweep.points(the_spec)
    if uncertainty:
        _check_sweep_uncertainty(the_spec, uncertainty, str(uncertainty_controller))
    if dry_run:
        _print_dry_run(the_spec.name, pts, store)
        return
    report = sweep.run_sweep(
        the_spec,
        store,
        executor=str(executor),
        workers=workers,
        scheduler=scheduler,
        retry_failed=retry_failed,
        progress=progress,
    )
    _print_sweep_report(report, store)
    if out is not None:
        _report(store, out, the_spec.name)
    if uncertainty:
        _bands(the_spec, store, uncertainty, str(uncertainty_controller))
    _raise_failed(report)


def _sweep_spec(
    spec: Path | None,
    grid: list[str] | None,
    set_: list[str] | None,
    name: str | None,
    outputs: str | None,
    shaft_file: Path | None,
    extrapolate: bool,
) -> Any:
    """The sweep: the --spec file (if any) with --grid, --set, --name, --outputs,
    --shaft-file and --extrapolate applied."""
    from fsarm_sim.studies import sweep

    data = sweep.load_spec_file(spec) if spec is not None else None
    return sweep.build_spec(
        data,
        grid=grid or (),
        fixed=set_ or (),
        name=name,
        outputs=outputs.split(",") if outputs else None,
        shaft_file=str(shaft_file) if shaft_file is not None else None,
        extrapolate=extrapolate or None,
    )


def _check_sweep_files(
    store: Path | None, out: Path | None, spec: Path | None, shaft_file: Path | None
) -> Path:
    """--store is given and writable, --out a folder, --spec and --shaft-file readable."""
    if store is None:
        raise FsarmError("--store FILE is required: every finished point is written there")
    OutputPlan().file("--store", store).folder("--out", out).input(
        "the sweep spec of --spec", spec
    ).input("the coefficient file of --shaft-file", shaft_file).check()
    return store


def _raise_failed(report: Any) -> None:
    """Points that failed (in this run or stored by an earlier one) are an error, exit 1."""
    if report.failed or report.failed_before:
        raise FsarmError(
            f"{report.failed + report.failed_before} point(s) of {report.name} failed "
            f"({report.failed} in this run, {report.failed_before} stored by an earlier run); "
            "they are stored with their error, --retry-failed reruns them"
        )


def _print_fields() -> None:
    """The sweepable fields (``--list-fields``)."""
    from fsarm_sim.studies import sweep

    table = Table(title="sweep fields")
    for col in ("field", "unit", "default", "meaning"):
        table.add_column(col)
    for f in sweep.fields().values():
        table.add_row(f.name, f.unit, str(f.default), escape(f.help))
    console.print(table)


def _check_sweep_uncertainty(the_spec: Any, samples: int, controller: str) -> None:
    """--uncertainty's settings, and ranges declared in the sweep's coefficient file."""
    from fsarm_sim.studies import sweep
    from fsarm_sim.studies import uncertainty as unc

    unc.check_samples(samples)
    unc.check_controller(controller)
    if not sweep.spec_catalogue(the_spec)[0].uncertainty:
        raise unc.UncertaintyError(
            "--uncertainty: the coefficient file declares no [uncertainty] ranges"
        )


def _print_dry_run(name: str, pts: list[Any], store: Path) -> None:
    """How many of the points are valid and already stored (``--dry-run``)."""
    from fsarm_sim.records.store import ResultStore, point_key

    done = failed = 0
    if store.exists():
        with ResultStore(store) as rs:
            keys, errors = rs.keys(), rs.errors()
        done = sum(point_key(p) in keys for p in pts)
        failed = sum(point_key(p) in errors for p in pts)
    console.print(
        f"{name}: {len(pts)} points valid, {done} already in {store}"
        + (f" ({failed} of them failed; --retry-failed reruns them)" if failed else ""),
        markup=False,
    )


def _print_sweep_report(report: Any, store: Path) -> None:
    """What the sweep computed, stored and failed (the first five errors)."""
    console.print(
        f"{report.name}: {report.total} points, {report.already} already stored, "
        f"{report.computed} computed, {report.failed} failed in {report.wall_s:.1f} s "
        f"({report.points_per_s:.3g} points/s; executor {report.executor}) -> {store}",
        markup=False,
    )
    if report.table is not None:
        console.print(f"tidy table (units in its schema): {report.table}", markup=False)
    if report.failed_before:
        console.print(
            f"{report.failed_before} of the {report.already} stored point(s) had failed in an "
            "earlier run and were not rerun",
            markup=False,
        )
    for e in report.errors[:5]:
        console.print(f"  failed: {e}", markup=False)
    if len(report.errors) > 5:
        console.print(f"  ... and {len(report.errors) - 5} more", markup=False)


def _bands(the_spec: Any, store: Path, n: int, controller: str) -> None:
    import csv

    from fsarm_sim.outputs import write_text
    from fsarm_sim.studies import uncertainty as unc

    rows, wall = unc.sweep_bands(the_spec, n, controller=controller)
    path = store.with_name(store.stem + ".uncertainty.csv")
    if rows:
        import io

        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
        write_text(path, buf.getvalue())
    console.print(
        f"5-95 % bands over {n} coefficient samples per point ({controller} controller, "
        f"{wall:.1f} s): {path}",
        markup=False,
    )


def _report(store: Path, out: Path, sweep: str | None) -> None:
    from fsarm_sim.studies.sweep_analysis import analyze

    res = analyze(store, out, sweep)
    if res.comparisons:
        print_comparisons(res.comparisons, res.fits)
    for eq, f in res.fits.items():
        if eq not in res.comparisons:
            console.print(f"{eq}: RMSE {f.rmse:.3g} N·m/rad over {f.n} points", markup=False)
    for s in res.skipped:
        console.print(f"skipped: {s}", markup=False)
    console.print(f"{res.n_points} points analysed; files in {out}", markup=False)


def sweep_report_cmd(
    store: Annotated[Path, typer.Option(help="results store (SQLite)")],
    out: Annotated[Path, typer.Option(help="folder for tables and plots")],
    name: Annotated[str | None, typer.Option(help="only this sweep's points")] = None,
) -> None:
    """Re-fit eq. 3/4 to a stored sweep and plot its metrics (maps, 3-D surfaces)."""
    from fsarm_sim.records.store import check_store_file

    checked_path(store, "--store", FsarmError)  # loops, long names ...
    if not store.is_file():
        raise FsarmError(f"results store not found: {store}")
    check_store_file(store)
    OutputPlan().folder("--out", out).input("the results store of --store", store).check()
    _report(store, out, name)


def register(app: typer.Typer) -> None:
    app.command("select-shaft")(select_shaft_cmd)
    app.command("sweep")(sweep_cmd)
    app.command("sweep-report")(sweep_report_cmd)
    bench_app = typer.Typer(
        help="Simulated test-bench experiments of seed 000 Sec. III.", no_args_is_help=True
    )
    app.add_typer(bench_app, name="bench")
    bench_app.command("series")(bench_series_cmd)
    bench_app.command("parallel")(bench_parallel_cmd)
    app.command("campaign")(campaign_cmd)
