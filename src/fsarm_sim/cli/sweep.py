"""CLI commands: ``select-shaft``, ``sweep``, ``sweep-report``, ``bench series|parallel``,
``campaign``. Thin: parse, call :mod:`fsarm_sim.studies.shaft_selection`, :mod:`fsarm_sim.studies.sweep`,
:mod:`fsarm_sim.studies.campaign`, print tables."""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim import choices
from fsarm_sim.choices import Executor, Pool, ShaftKind
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.errors import FsarmError
from fsarm_sim.outputs import OutputPlan, SafeWriter
from fsarm_sim.paths import checked_path

if TYPE_CHECKING:
    from fsarm_sim.studies.campaign import CampaignResult

console = make_console()


def _floats(text: str | None, what: str) -> tuple[float, ...] | None:
    if text is None:
        return None
    try:
        vals = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise FsarmError(f"{what}: expected comma-separated numbers, got {text!r}") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise FsarmError(f"{what}: expected finite numbers, got {text!r}")
    return vals


def _print_series_table(name: str, fits: Any) -> None:
    from fsarm_sim.studies.campaign_output import series_table_rows

    table = Table(
        title=f"{escape(name)}: series test fits (Table I-like; K in N·m/rad, RMSE in N·m)"
    )
    rows = series_table_rows(fits)
    cols = ("bend_deg", "K_sp", "K_sn", "RMSE_p", "RMSE_n", "eq1_J", "eq1_B_p", "eq1_B_n")
    for c in cols:
        table.add_column(escape(c), justify="right")
    for r in rows:
        table.add_row(*(f"{r[c]:.4g}" for c in cols))
    console.print(table)
    note = inertia_note([float(r["eq1_J"]) for r in rows])
    if note:
        console.print(note, markup=False)


def inertia_note(fitted_j: list[float]) -> str:
    """What a negative eq. 1 inertia in a series table means (empty when none is negative)."""
    if not any(j < 0.0 for j in fitted_j):
        return ""
    return (
        f"note: eq1_J < 0 (down to {min(fitted_j):.3g} kg·m²) is no inertia: eq. 1's J is not "
        "identifiable from this test. The output is blocked, so the measured torque carries "
        "only the shaft's own inertia (the built-in coefficient file sets it to 0: "
        "series.dynamic.inertia_kgm2; seed 000 gives none); at the chirp's frequencies the "
        "acceleration column is nearly -ω²·twist, so the fitted J trades against K and takes "
        "up what eq. 1 lacks (the hysteresis' lag). Read J as undetermined, not as a value."
    )


def _print_parallel_table(name: str, fits: Any) -> None:
    table = Table(title=f"{escape(name)}: parallel test fits (K_b in N·m/rad)")
    cols = (
        ("torsion", "torsion"),
        ("kb_linear", "K_b eq.2"),
        ("rmse_linear", "RMSE"),
        ("kb_pos_bend", "K_b φ>0"),
        ("kb_neg_bend", "K_b φ<0"),
        ("kb_cubic", "K_b cubic"),
        ("beta_cubic", "β [1/rad²]"),
        ("loop_energy_j", "loop [J]"),
        ("moment_at_max_bend_nm", "|M| at max bend"),
    )
    for _, label in cols:
        table.add_column(escape(label), justify="right")
    for f in fits:
        table.add_row(
            *(
                str(getattr(f, k)) if isinstance(getattr(f, k), bool) else f"{getattr(f, k):.4g}"
                for k, _ in cols
            )
        )
    console.print(table)


def _print_comparisons(comparisons: Any, fits: Any) -> None:
    table = number_table(
        "re-fit vs the catalogue coefficients the simulator was given",
        (
            "equation",
            "n",
            "fit RMSE",
            "surface RMS err",
            "surface max err",
            "rel RMS",
            "rel max",
        ),
    )
    for eq, c in comparisons.items():
        f = fits[eq]
        table.add_row(
            escape(eq),
            str(f.n),
            f"{f.rmse:.3g}",
            f"{c.surface_rms_error:.3g}",
            f"{c.surface_max_abs_error:.3g}",
            f"{100 * c.surface_rms_rel_error:.3g} %",
            f"{100 * c.surface_max_rel_error:.3g} %",
        )
    console.print(table)
    for eq, c in comparisons.items():
        parts = ", ".join(
            coefficient_change(n, r, f, cat)
            for n, r, f, cat in zip(
                fits[eq].names, c.coefficient_rel_error, c.refit, c.catalogue, strict=True
            )
        )
        console.print(f"  {eq} coefficients (refit − catalogue)/catalogue: {parts}", markup=False)


def coefficient_change(name: str, rel: float, refit: float, catalogue: float) -> str:
    """A coefficient's (refit − catalogue)/catalogue; one the catalogue holds at 0 (eq. 3's p4
    under the inverse-length law) has no relative change: its refit is said as it is."""
    if catalogue != 0.0:
        return f"{name}: {100 * rel:+.2g} %"
    if refit == 0.0:
        return f"{name}: 0 in both (held at 0, not fitted)"
    return f"{name}: catalogue 0, refit {refit:+.3g}"


def _write_folder(out: Path, write: Any, what: str) -> None:
    """``write(folder)`` into ``out``; a failed write goes to a rescue folder (named error)."""
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    where = writes.write(out, write, what, folder=True)
    if where is not None:
        console.print(f"table and figure in {where}", markup=False)
    writes.finish()


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
        diameters_mm=_floats(diameters, "--diameters"),
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
    if store is None:
        raise FsarmError("--store FILE is required: every finished point is written there")
    OutputPlan().file("--store", store).folder("--out", out).input(
        "the sweep spec of --spec", spec
    ).input("the coefficient file of --shaft-file", shaft_file).check()
    data = sweep.load_spec_file(spec) if spec is not None else None
    the_spec = sweep.build_spec(
        data,
        grid=grid or (),
        fixed=set_ or (),
        name=name,
        outputs=outputs.split(",") if outputs else None,
        shaft_file=str(shaft_file) if shaft_file is not None else None,
        extrapolate=extrapolate or None,
    )
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
        _print_comparisons(res.comparisons, res.fits)
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


def _settings(**kw: Any) -> Any:
    from fsarm_sim.studies.campaign import BenchSettings

    return BenchSettings(**{k: v for k, v in kw.items() if v is not None})


def _run_bench_test(
    diameter_mm: float,
    length_mm: float,
    shaft_file: Path | None,
    out: Path | None,
    workers: int | None,
    settings: dict[str, Any],
    tasks: Callable[[Any, Any], Callable[[Any, str | None], list[dict[str, Any]]]],
) -> tuple[Any, str, Any]:
    """One shaft's bench test: outputs checked, the shaft and ``settings`` validated, the tasks
    ``tasks(catalogue, settings)`` makes run; the shaft's parameters, its name and the result."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import campaign as cp

    OutputPlan().folder("--out", out).input(
        "the coefficient file of --shaft-file", shaft_file
    ).check()
    cat = load_catalogue(shaft_file)
    params = cat.shaft(diameter_mm, length_mm)
    s = _settings(**settings)
    s.validate()
    make_tasks = tasks(cat, s)
    name, result = cp.run_one_shaft(cat, diameter_mm, length_mm, shaft_file, s, make_tasks, workers)
    return params, name, result


# the options of `bench_series_cmd`
BenchSeriesBends = Annotated[str, typer.Option(help="bend angles, deg")]
BenchSeriesChirpS = Annotated[float | None, typer.Option(help="chirp length, s")]
BenchSeriesAmplitudeFraction = Annotated[
    float | None, typer.Option(help="chirp amplitude / rating")
]
BenchSeriesSeriesHysteresis = Annotated[
    bool | None, typer.Option(help="Maxwell-slip hysteresis on/off (default: catalogue's)")
]
BenchSeriesOut = Annotated[
    Path | None, typer.Option(help="folder for the table (CSV) and Fig. 6 loops")
]
BenchSeriesWorkers = Annotated[
    int | None, typer.Option(help="worker processes (default: all cores)")
]


def bench_series_cmd(
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
    bends: BenchSeriesBends = "0,15,30,45,60,75,90",
    chirp_s: BenchSeriesChirpS = None,
    amplitude_fraction: BenchSeriesAmplitudeFraction = None,
    series_hysteresis: BenchSeriesSeriesHysteresis = None,
    out: BenchSeriesOut = None,
    workers: BenchSeriesWorkers = None,
    shaft_file: opt.ShaftFile = None,
) -> None:
    """Series test: chirp into the torque controller at each bend; eq. 8/eq. 1 fits per sign."""
    from fsarm_sim.studies import campaign as cp
    from fsarm_sim.studies import campaign_output

    def tasks(cat: Any, s: Any) -> Callable[[Any, str | None], list[dict[str, Any]]]:
        bend_list = cp.check_bends(_floats(bends, "--bends") or (), cat)
        return lambda sh, text: cp.series_tasks(sh, bend_list, s, text, True)

    settings = {
        "chirp_s": chirp_s,
        "amplitude_fraction": amplitude_fraction,
        "series_hysteresis": series_hysteresis,
    }
    _, name, result = _run_bench_test(
        diameter_mm, length_mm, shaft_file, out, workers, settings, tasks
    )
    fits = result.series[name]
    _print_series_table(name, fits)
    if name in result.trends:
        tr = result.trends[name]
        console.print(
            f"bend trend (eq. 8 f_p): K_sp = {tr.k0_pos:.4g} {tr.slope_pos:+.4g}·|φ|, "
            f"K_sn = {tr.k0_neg:.4g} {tr.slope_neg:+.4g}·|φ|  (N·m/rad, φ in rad)",
            markup=False,
        )
    if out is not None:
        _write_folder(
            out,
            lambda d: campaign_output.write_series_test(result, name, d),
            "the table and figure (--out)",
        )


# the options of `bench_parallel_cmd`
BenchParallelPeriodS = Annotated[float | None, typer.Option(help="bending cycle period, s")]
BenchParallelAmplitudeDeg = Annotated[float | None, typer.Option(help="bend amplitude, deg")]
BenchParallelTorsionFraction = Annotated[
    float | None, typer.Option(help="held twist torque / rating")
]
BenchParallelOut = Annotated[Path | None, typer.Option(help="folder for the table and Fig. 9 loop")]
BenchParallelWorkers = Annotated[
    int | None, typer.Option(help="worker processes (default: all cores)")
]


def bench_parallel_cmd(
    diameter_mm: opt.DiameterMm = 9.0,
    length_mm: opt.LengthMm = 450.0,
    period_s: BenchParallelPeriodS = None,
    amplitude_deg: BenchParallelAmplitudeDeg = None,
    torsion_fraction: BenchParallelTorsionFraction = None,
    out: BenchParallelOut = None,
    workers: BenchParallelWorkers = None,
    shaft_file: opt.ShaftFile = None,
) -> None:
    """Parallel test: bend both ways with and without torsion; eq. 2 K_b fits of the moment loop."""
    from fsarm_sim.studies import campaign as cp
    from fsarm_sim.studies import campaign_output

    settings = {
        "bend_period_s": period_s,
        "bend_amplitude_deg": amplitude_deg,
        "torsion_fraction": torsion_fraction,
    }
    p, name, result = _run_bench_test(
        diameter_mm,
        length_mm,
        shaft_file,
        out,
        workers,
        settings,
        lambda _cat, s: lambda sh, text: cp.parallel_tasks(sh, s, text, True),
    )
    fits = result.parallel[name]
    _print_parallel_table(name, fits)
    console.print(
        f"catalogue (eq. 4) K_b = {p.kb_eq4:.4g} N·m/rad (elastic {p.kb:.4g}), "
        f"stiffening β = {p.beta:g} /rad²; "
        f"static relief at 90° = {p.static_relief_nm(math.pi / 2):.3g} N·m",
        markup=False,
    )
    if out is not None:
        _write_folder(
            out,
            lambda d: campaign_output.write_parallel_test(result, name, d),
            "the table and figure (--out)",
        )


def _chosen_shafts(cat: Any, shafts: str | None) -> list[Any]:
    """The catalogue's shafts named in ``shafts`` (comma-separated; None: every one)."""
    if not shafts:
        return list(cat.shafts)
    wanted = [s.strip() for s in shafts.split(",") if s.strip()]
    names = {s.name: s for s in cat.shafts}
    missing = [w for w in wanted if w not in names]
    if missing:
        raise FsarmError(f"unknown shaft(s) {missing}; the catalogue has {sorted(names)}")
    return [names[w] for w in wanted]


@contextlib.contextmanager
def _bench_bar(n_tasks: int, show: bool) -> Iterator[Callable[[Any], None] | None]:
    """A progress bar of ``n_tasks`` bench runs on stderr (``show``), its advance callback."""
    if not show:
        yield None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    bar = Progress(
        TextColumn("bench runs"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=make_console(stderr=True),
    )
    task_id = bar.add_task("runs", total=n_tasks)
    bar.start()
    try:
        yield lambda _o: bar.advance(task_id)
    finally:
        bar.stop()


def _print_campaign(result: CampaignResult, written: tuple[Path, Any] | None) -> None:
    """The prototype's tables, the comparisons, the errors and where the files went."""
    proto = "MF09-450" if "MF09-450" in result.series else next(iter(result.series), None)
    if proto is not None:
        _print_series_table(proto, result.series[proto])
    if proto in result.parallel:
        _print_parallel_table(proto, result.parallel[proto])
    _print_comparisons(result.comparisons, result.fits)
    for e in result.errors:
        console.print(f"error: {e}", markup=False)
    if written is not None:
        console.print(f"{len(written[1])} files in {written[0]}", markup=False)


# the options of `campaign_cmd`
CampaignOut = Annotated[Path, typer.Option(help="output folder (tables, campaign.json, figures)")]
CampaignShafts = Annotated[
    str | None, typer.Option(help="comma-separated shaft names (default: all nine)")
]
CampaignBends = Annotated[str, typer.Option(help="bend angles, deg")]
CampaignChirpS = Annotated[float | None, typer.Option(help="series chirp length, s")]
CampaignPeriodS = Annotated[float | None, typer.Option(help="parallel bending period, s")]
CampaignSeriesHysteresis = Annotated[
    bool | None, typer.Option(help="Maxwell-slip hysteresis on/off (default: catalogue's)")
]
CampaignExecutor = Annotated[
    Pool,
    typer.Option(
        help="local (process pool), threads (this process; best for many short runs) or dask",
        case_sensitive=False,
    ),
]
CampaignWorkers = Annotated[int | None, typer.Option(help="worker processes (default: all cores)")]
CampaignScheduler = Annotated[str | None, typer.Option(help="Dask scheduler address")]
CampaignProgress = Annotated[bool, typer.Option(help="progress bar with ETA")]


def campaign_cmd(
    out: CampaignOut,
    shafts: CampaignShafts = None,
    bends: CampaignBends = "0,15,30,45,60,75,90",
    chirp_s: CampaignChirpS = None,
    period_s: CampaignPeriodS = None,
    series_hysteresis: CampaignSeriesHysteresis = None,
    executor: CampaignExecutor = Pool.LOCAL,
    workers: CampaignWorkers = None,
    scheduler: CampaignScheduler = None,
    shaft_file: opt.ShaftFile = None,
    progress: CampaignProgress = True,
) -> None:
    """The nine-shaft bench campaign: both tests per shaft, eq. 3/4 re-fit, error vs catalogue."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import campaign as cp
    from fsarm_sim.studies import campaign_output

    OutputPlan().folder("--out", out).input(
        "the coefficient file of --shaft-file", shaft_file
    ).check()
    cat = load_catalogue(shaft_file)
    chosen = _chosen_shafts(cat, shafts)
    s = _settings(chirp_s=chirp_s, bend_period_s=period_s, series_hysteresis=series_hysteresis)
    bend_list = cp.check_bends(_floats(bends, "--bends") or (), cat)
    with _bench_bar(len(chosen) * (len(bend_list) + 2), progress) as on_done:
        result = cp.run_campaign(
            shaft_file,
            shafts=chosen,
            bends_deg=bend_list,
            settings=s,
            executor=str(executor),
            workers=workers,
            scheduler=scheduler,
            on_done=on_done,
        )
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    written = writes.write(
        out,
        lambda d: (d, campaign_output.write_campaign(result, cat, d)),
        "the campaign's files (--out)",
        folder=True,
    )
    _print_campaign(result, written)
    writes.finish()
    if result.errors:
        raise FsarmError(f"{len(result.errors)} bench run(s) of the campaign failed (listed above)")


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
