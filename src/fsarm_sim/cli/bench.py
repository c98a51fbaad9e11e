"""fsarm bench series|parallel and fsarm campaign: seed 000 Sec. III's bench tests on one shaft or
on the whole catalogue (registered by :mod:).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim.choices import Pool
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.errors import FsarmError
from fsarm_sim.outputs import OutputPlan, SafeWriter

if TYPE_CHECKING:
    from fsarm_sim.studies.campaign import CampaignResult

console = make_console()


def parse_floats(text: str | None, what: str) -> tuple[float, ...] | None:
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


def print_comparisons(comparisons: Any, fits: Any) -> None:
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


def _write_folder(out: Path | None, write: Any) -> None:
    """``write(folder)`` (the table and figure) into ``out`` when given; a failed write goes to a
    rescue folder (named error)."""
    if out is None:
        return
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    where = writes.write(out, write, "the table and figure (--out)", folder=True)
    if where is not None:
        console.print(f"table and figure in {where}", markup=False)
    writes.finish()


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
        bend_list = cp.check_bends(parse_floats(bends, "--bends") or (), cat)
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
    _write_folder(out, lambda d: campaign_output.write_series_test(result, name, d))


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
    _write_folder(out, lambda d: campaign_output.write_parallel_test(result, name, d))


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
    print_comparisons(result.comparisons, result.fits)
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
    bend_list = cp.check_bends(parse_floats(bends, "--bends") or (), cat)
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
