"""``fsarm datasheet`` and ``fsarm select``: designing a shaft (issue 32). Thin over
:mod:`fsarm_sim.studies.datasheet`, :mod:`~fsarm_sim.studies.task_selection` and
:mod:`~fsarm_sim.studies.uncertainty`."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Annotated, Any

import typer

from fsarm_sim import choices
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.outputs import OutputPlan

console = make_console()


# the options of `datasheet_cmd`
DatasheetShaft = Annotated[
    list[str] | None,
    typer.Option(help="catalogue shaft name (repeatable; see `fsarm shafts`)"),
]
DatasheetAllShafts = Annotated[bool, typer.Option("--all", help="every shaft of the catalogue")]
DatasheetDiameterMm = Annotated[
    float | None, typer.Option(help="shaft diameter D, mm (any D/L in the box)")
]
DatasheetLengthMm = Annotated[float | None, typer.Option(help="shaft length L, mm")]
DatasheetOut = Annotated[Path, typer.Option(help="folder for <name>.json/.html/.pdf/.png")]
DatasheetDuration = Annotated[
    float | None,
    typer.Option(help="simulated time of the tracking runs, s (default: each scenario's)"),
]
DatasheetCatalogueOnly = Annotated[
    bool, typer.Option(help="catalogue numbers only, no simulation (instant)")
]


def datasheet_cmd(
    shaft: DatasheetShaft = None,
    all_shafts: DatasheetAllShafts = False,
    diameter_mm: DatasheetDiameterMm = None,
    length_mm: DatasheetLengthMm = None,
    out: DatasheetOut = Path("datasheets"),
    duration: DatasheetDuration = None,
    catalogue_only: DatasheetCatalogueOnly = False,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
) -> None:
    """One page per shaft (HTML, PDF, PNG, JSON): stiffness per side, hysteresis, rating,
    joint-2 relief, inertia, torque bandwidth and output impedance vs bend, tracking at 0
    and 15 kg - each number with its source and, with --uncertainty N, its 5-95 % band."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import datasheet, datasheet_render
    from fsarm_sim.studies import uncertainty as unc

    OutputPlan().folder("--out", out).input(
        "the coefficient file of --shaft-file", shaft_file
    ).check()
    cat = load_catalogue(shaft_file)
    if uncertainty:
        unc.check_samples(uncertainty)
        unc.check_controller(str(uncertainty_controller))
    picks = datasheet.picks(
        cat,
        shaft or [],
        every=all_shafts,
        diameter_mm=diameter_mm,
        length_mm=length_mm,
        extrapolate=extrapolate,
    )
    settings = datasheet.Settings(duration_s=duration, simulate=not catalogue_only)
    for pick in picks:
        sheet = datasheet.sheet_for(
            cat,
            pick,
            settings,
            samples=uncertainty,
            controller=str(uncertainty_controller),
            extrapolate=extrapolate,
        )
        stem = sheet["shaft"]["name"]
        paths = datasheet_render.write(sheet, out, stem)
        console.print(_sheet_line(stem, sheet["numbers"]), markup=False)
        console.print(f"  {paths['html']}  {paths['pdf']}  {paths['json']}", markup=False)


def _sheet_line(stem: str, nums: dict[str, Any]) -> str:
    """A datasheet's headline numbers in one line."""
    line = (
        f"{stem}: K_sp {nums['k_sp.0deg']['value']:.3g} N*m/rad straight, rating "
        f"{nums['rating_nm']['value']:.3g} N*m, relief at 90 deg "
        f"{nums['relief_nm.90deg']['value']:.3g} N*m"
    )
    key = "track.fig14-sine.0kg.q3_rmse_deg"
    if key in nums:
        e = nums[key]
        band = e.get("band")
        line += f", fig14-sine q3 RMSE {e['value']:.3g} deg" + (
            f" [{band['p05']:.3g}, {band['p95']:.3g}]" if band else ""
        )
    return line


# the options of `select_cmd`
SelectScenario = Annotated[
    choices.Scenario | None,
    typer.Argument(
        metavar="[SCENARIO]",
        help="the task: a scenario (`fsarm scenarios`), or --trajectory-file",
        case_sensitive=False,
        show_default=False,
    ),
]
SelectTrajectoryFile = Annotated[
    Path | None,
    typer.Option(
        help="the task as your trajectory: .csv or .parquet, columns t (s, from 0), "
        "q1_ref q2_ref q3_ref (rad), optional qd1_ref..qd3_ref (rad/s) and "
        "qdd1_ref..qdd3_ref (rad/s^2) (an `fsarm run` record works as it is); payload "
        "0 kg unless --payload-kg",
    ),
]
SelectObjective = Annotated[
    str, typer.Option(help="q3_rmse_deg, motor_energy_j or peak_motor_torque_nm")
]
SelectPayloadKg = Annotated[
    float | None, typer.Option(help="payload, kg (default: the scenario's)")
]
SelectDuration = Annotated[
    float | None, typer.Option(help="simulated time, s (default: the scenario's)")
]
SelectRatingMargin = Annotated[
    float, typer.Option(help="rating / peak shaft torque must be at least this")
]
SelectBandwidthFloor = Annotated[
    float, typer.Option(help="torque-loop bandwidth floor at every bend, Hz (0: none)")
]
SelectBend = Annotated[
    list[float] | None,
    typer.Option(help="joint-2 bend(s), deg, the task must work at (default 45)"),
]
SelectBudget = Annotated[int, typer.Option(help="shaft evaluations per optimisation")]
SelectPareto = Annotated[
    str | None,
    typer.Option(help="second objective: the Pareto front of --objective and this"),
]
SelectStore = Annotated[Path, typer.Option(help="results store (resumes where a run stopped)")]
SelectOut = Annotated[
    Path | None, typer.Option(help="folder for the result JSON and the Pareto plot")
]
SelectExecutor = Annotated[str, typer.Option(help="threads, local or dask")]
SelectWorkers = Annotated[int, typer.Option(help="parallel simulations")]
SelectSeed = Annotated[int, typer.Option(help="optimiser seed")]


def _check_select(
    objective: str,
    pareto: str | None,
    samples: int,
    controller: str,
    scenario: str | None,
    trajectory_file: Path | None,
) -> None:
    """The objectives, the task (a scenario or a trajectory file) and the --uncertainty
    settings, before any simulation."""
    from fsarm_sim.studies import task_selection
    from fsarm_sim.studies import uncertainty as unc

    task_selection.check_objective(objective)
    if (scenario is None) == (trajectory_file is None):
        raise task_selection.SelectionError(
            "give the task as a scenario name or as --trajectory-file FILE (one of the two)"
        )
    if pareto is not None:
        task_selection.check_objective(pareto)
    if samples:
        unc.check_samples(samples)
        unc.check_controller(controller)


def _select_pareto(
    task: Any, store: Path, objectives: tuple[str, str], budget: int, seed: int, out: Path | None
) -> list[dict[str, Any]]:
    """The Pareto front of two objectives, printed (and plotted into ``out``)."""
    from fsarm_sim.studies import task_selection

    objective, pareto = objectives
    front, evaluated, sims = task_selection.pareto(
        task, store, objectives, budget_each=max(16, budget // 2), seed=seed
    )
    console.print(
        f"Pareto front of {objective} and {pareto}: {len(front)} shafts of "
        f"{len(evaluated)} evaluated ({sims} simulated, the rest from {store})",
        markup=False,
    )
    for e in front:
        console.print(
            f"  D {e.diameter_mm:6.2f} mm  L {e.length_mm:6.1f} mm  "
            f"{objective} {e.outputs[objective]:.4g}  {pareto} {e.outputs[pareto]:.4g}",
            markup=False,
        )
    if out is not None:
        png = task_selection.pareto_plot(front, evaluated, objective, pareto, out / "pareto.png")
        console.print(f"plot: {png}", markup=False)
    return [e.__dict__ for e in front]


def _select_optimum(
    task: Any, store: Path, objective: str, budget: int, seed: int
) -> dict[str, Any]:
    """The optimum and the nearest catalogue shafts, printed; exit 1 when none is feasible."""
    from fsarm_sim.studies import task_selection

    s = task_selection.select(task, store, objective, budget=budget, seed=seed)
    if s.best is None:
        console.print(
            f"no shaft of the {len(s.evaluated)} evaluated meets the constraints; first "
            f"reason: {s.evaluated[0].why if s.evaluated else '-'}",
            markup=False,
        )
        raise typer.Exit(1)
    b = s.best
    console.print(
        f"optimum: D = {b.diameter_mm:.2f} mm, L = {b.length_mm:.1f} mm: {objective} "
        f"{b.outputs[objective]:.4g}, rating margin {b.outputs['rating_margin']:.2f} "
        f"({s.simulations} simulated, {s.stored} read from {store})",
        markup=False,
    )
    for name, e in zip(s.nearest_names, s.nearest, strict=True):
        value = e.outputs.get(objective, float("nan"))
        console.print(
            f"  nearest catalogue shaft {name}: {objective} {value:.4g}"
            + ("" if e.feasible else f" (infeasible: {e.why})"),
            markup=False,
        )
    return {
        "best": b.__dict__,
        "nearest": {n: e.__dict__ for n, e in zip(s.nearest_names, s.nearest, strict=True)},
        "simulations": s.simulations,
    }


def _optimum_band(
    task: Any,
    best: Any,
    objective: str,
    shaft_file: Path | None,
    samples: int,
    controller: str,
) -> dict[str, Any]:
    """The objective's 5-95 % band at the optimum over the coefficient ranges, printed."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import task_selection
    from fsarm_sim.studies import uncertainty as unc

    metric = functools.partial(
        task_selection.shaft_metrics,
        diameter_mm=best["diameter_mm"],
        length_mm=best["length_mm"],
        scenario=task.scenario,
        payload_kg=task.payload_kg,
        duration_s=task.duration_s,
        bends_deg=task.bends_deg,
        controller_catalogue=load_catalogue(shaft_file) if controller == "nominal" else None,
    )
    prop = unc.propagate(metric, load_catalogue(shaft_file), samples)
    band = prop.bands[objective]
    console.print(
        f"  {objective} at the optimum, 5-95 % over {prop.samples} coefficient "
        f"samples: [{band.low:.4g}, {band.high:.4g}] (median {band.median:.4g})",
        markup=False,
    )
    return unc.to_json(prop, controller=controller)


def _select_task(
    scenario: str | None,
    trajectory_file: Path | None,
    shaft_file: Path | None,
    out: Path | None,
    limits: tuple[float | None, float | None, tuple[float, ...], float, float],
    parallel: tuple[str, int],
) -> Any:
    """Check the input files and the --out folder, then the task: the scenario (or the
    trajectory file's), ``limits`` = (payload kg, duration s, bends deg, rating margin,
    bandwidth floor Hz), ``parallel`` = (executor, workers)."""
    from fsarm_sim.studies import task_selection

    plan = OutputPlan().input("the coefficient file of --shaft-file", shaft_file)
    if out is not None:
        plan = plan.folder("--out", out)
    if trajectory_file is not None:
        plan = plan.input("the trajectory file of --trajectory-file", trajectory_file)
    plan.check()
    if trajectory_file is not None:
        from fsarm_sim.studies import trajectory_file as trajectory

        scenario = trajectory.scenario_name(trajectory_file)
    assert scenario is not None
    payload_kg, duration, bends, rating_margin, bandwidth_floor = limits
    return task_selection.Task(
        scenario=scenario,
        payload_kg=payload_kg,
        duration_s=duration,
        bends_deg=bends,
        rating_margin=rating_margin,
        bandwidth_floor_hz=bandwidth_floor,
        shaft_file=None if shaft_file is None else str(shaft_file),
        executor=parallel[0],
        workers=parallel[1],
    )


def select_cmd(
    scenario_choice: SelectScenario = None,
    objective: SelectObjective = "q3_rmse_deg",
    payload_kg: SelectPayloadKg = None,
    duration: SelectDuration = None,
    rating_margin: SelectRatingMargin = 1.0,
    bandwidth_floor: SelectBandwidthFloor = 0.0,
    bend: SelectBend = None,
    budget: SelectBudget = 96,
    pareto: SelectPareto = None,
    store: SelectStore = Path("select.sqlite"),
    out: SelectOut = None,
    executor: SelectExecutor = "threads",
    workers: SelectWorkers = 2,
    seed: SelectSeed = 32,
    shaft_file: opt.ShaftFile = None,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
    trajectory_file: SelectTrajectoryFile = None,
) -> None:
    """Find D and L (continuous, in the validity box) minimising a task objective under
    constraints, by differential evolution over simulations; then the nearest catalogue
    shafts. --pareto OBJ2: the front of two objectives and its plot."""
    import json

    from fsarm_sim.outputs import write_text

    scenario = None if scenario_choice is None else str(scenario_choice)
    _check_select(
        objective, pareto, uncertainty, str(uncertainty_controller), scenario, trajectory_file
    )
    task = _select_task(
        scenario,
        trajectory_file,
        shaft_file,
        out,
        (payload_kg, duration, tuple(bend) if bend else (45.0,), rating_margin, bandwidth_floor),
        (executor, workers),
    )
    report: dict[str, object] = {"task": task.__dict__, "objective": objective}
    if pareto is not None:
        report["pareto"] = _select_pareto(task, store, (objective, pareto), budget, seed, out)
    else:
        report.update(_select_optimum(task, store, objective, budget, seed))
        if uncertainty:
            args = (report["best"], objective, shaft_file, uncertainty, str(uncertainty_controller))
            report["uncertainty"] = _optimum_band(task, *args)
    if out is not None:
        text = json.dumps(report, indent=2, default=str)
        console.print(f"result: {write_text(out / 'select.json', text)}", markup=False)


def register(app: typer.Typer) -> None:
    app.command("datasheet")(datasheet_cmd)
    app.command("select")(select_cmd)
