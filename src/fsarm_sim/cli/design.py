"""``fsarm datasheet`` and ``fsarm select``: designing a shaft (issue 32). Thin over
:mod:`fsarm_sim.studies.datasheet`, :mod:`~fsarm_sim.studies.task_selection` and
:mod:`~fsarm_sim.studies.uncertainty`."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Annotated

import typer

from fsarm_sim import choices
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.outputs import OutputPlan

console = make_console()


def datasheet_cmd(
    shaft: Annotated[
        list[str] | None,
        typer.Option(help="catalogue shaft name (repeatable; see `fsarm shafts`)"),
    ] = None,
    all_shafts: Annotated[bool, typer.Option("--all", help="every shaft of the catalogue")] = False,
    diameter_mm: Annotated[
        float | None, typer.Option(help="shaft diameter D, mm (any D/L in the box)")
    ] = None,
    length_mm: Annotated[float | None, typer.Option(help="shaft length L, mm")] = None,
    out: Annotated[Path, typer.Option(help="folder for <name>.json/.html/.pdf/.png")] = Path(
        "datasheets"
    ),
    duration: Annotated[
        float | None,
        typer.Option(help="simulated time of the tracking runs, s (default: each scenario's)"),
    ] = None,
    catalogue_only: Annotated[
        bool, typer.Option(help="catalogue numbers only, no simulation (instant)")
    ] = False,
    shaft_file: opt.ShaftFile = None,
    extrapolate: opt.Extrapolate = False,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
) -> None:
    """One page per shaft (HTML, PDF, PNG, JSON): stiffness per side, hysteresis, rating,
    joint-2 relief, inertia, torque bandwidth and output impedance vs bend, tracking at 0
    and 15 kg - each number with its source and, with --uncertainty N, its 5-95 % band."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import datasheet as ds
    from fsarm_sim.studies import datasheet_render
    from fsarm_sim.studies import uncertainty as unc

    OutputPlan().folder("--out", out).input(
        "the coefficient file of --shaft-file", shaft_file
    ).check()
    cat = load_catalogue(shaft_file)
    if uncertainty:
        unc.check_samples(uncertainty)
        unc.check_controller(str(uncertainty_controller))
    picks: list[tuple[str | None, float, float]] = []
    names = {s.name: s for s in cat.shafts}
    for wanted in shaft or []:
        if wanted not in names:
            raise ds.DatasheetError(
                f"--shaft {wanted!r} is not in {cat.source}; its shafts: {', '.join(names)}"
            )
        picks.append((wanted, names[wanted].diameter_mm, names[wanted].length_mm))
    if all_shafts:
        picks += [(s.name, s.diameter_mm, s.length_mm) for s in cat.shafts]
    if (diameter_mm is None) != (length_mm is None):
        raise ds.DatasheetError("give both --diameter-mm and --length-mm (or a --shaft)")
    if diameter_mm is not None and length_mm is not None:
        picks.append((None, diameter_mm, length_mm))
    if not picks:
        raise ds.DatasheetError(
            "say which shaft: --shaft NAME, --all, or --diameter-mm D --length-mm L"
        )
    for _, d, ell in picks:  # every shaft checked before the first is computed
        cat.shaft(d, ell, extrapolate=extrapolate)
    settings = ds.Settings(duration_s=duration, simulate=not catalogue_only)
    for pick_name, d, ell in picks:
        metric = functools.partial(
            ds.measure,
            diameter_mm=d,
            length_mm=ell,
            settings=settings,
            extrapolate=extrapolate,
        )
        values = metric(cat)
        bands, report = None, None
        if uncertainty:
            if uncertainty_controller == "nominal":
                metric = functools.partial(
                    metric, controller_shaft=cat.shaft(d, ell, extrapolate=extrapolate)
                )
            prop = unc.propagate(metric, cat, uncertainty)
            report = unc.to_json(prop, controller=str(uncertainty_controller))
            bands = report.pop("metrics")
        sheet = ds.datasheet(
            cat,
            diameter_mm=d,
            length_mm=ell,
            name=pick_name,
            settings=settings,
            values=values,
            bands=bands,
            uncertainty=report,
            extrapolate=extrapolate,
        )
        stem = sheet["shaft"]["name"]
        paths = datasheet_render.write(sheet, out, stem)
        nums = sheet["numbers"]
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
        console.print(line, markup=False)
        console.print(f"  {paths['html']}  {paths['pdf']}  {paths['json']}", markup=False)


def select_cmd(
    scenario: Annotated[str, typer.Argument(help="the task: a scenario (`fsarm scenarios`)")],
    objective: Annotated[
        str, typer.Option(help="q3_rmse_deg, motor_energy_j or peak_motor_torque_nm")
    ] = "q3_rmse_deg",
    payload_kg: Annotated[
        float | None, typer.Option(help="payload, kg (default: the scenario's)")
    ] = None,
    duration: Annotated[
        float | None, typer.Option(help="simulated time, s (default: the scenario's)")
    ] = None,
    rating_margin: Annotated[
        float, typer.Option(help="rating / peak shaft torque must be at least this")
    ] = 1.0,
    bandwidth_floor: Annotated[
        float, typer.Option(help="torque-loop bandwidth floor at every bend, Hz (0: none)")
    ] = 0.0,
    bend: Annotated[
        list[float] | None,
        typer.Option(help="joint-2 bend(s), deg, the task must work at (default 45)"),
    ] = None,
    budget: Annotated[int, typer.Option(help="shaft evaluations per optimisation")] = 96,
    pareto: Annotated[
        str | None,
        typer.Option(help="second objective: the Pareto front of --objective and this"),
    ] = None,
    store: Annotated[Path, typer.Option(help="results store (resumes where a run stopped)")] = Path(
        "select.sqlite"
    ),
    out: Annotated[
        Path | None, typer.Option(help="folder for the result JSON and the Pareto plot")
    ] = None,
    executor: Annotated[str, typer.Option(help="threads, local or dask")] = "threads",
    workers: Annotated[int, typer.Option(help="parallel simulations")] = 2,
    seed: Annotated[int, typer.Option(help="optimiser seed")] = 32,
    shaft_file: opt.ShaftFile = None,
    uncertainty: opt.Uncertainty = 0,
    uncertainty_controller: opt.UncertaintyController = choices.UncertaintyController.NOMINAL,
) -> None:
    """Find D and L (continuous, in the validity box) minimising a task objective under
    constraints, by differential evolution over simulations; then the nearest catalogue
    shafts. --pareto OBJ2: the front of two objectives and its plot."""
    import json

    from fsarm_sim.outputs import write_text
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import task_selection as ts
    from fsarm_sim.studies import uncertainty as unc

    ts.check_objective(objective)
    if pareto is not None:
        ts.check_objective(pareto)
    if uncertainty:
        unc.check_samples(uncertainty)
        unc.check_controller(str(uncertainty_controller))
    plan = OutputPlan().input("the coefficient file of --shaft-file", shaft_file)
    if out is not None:
        plan = plan.folder("--out", out)
    plan.check()
    task = ts.Task(
        scenario=scenario,
        payload_kg=payload_kg,
        duration_s=duration,
        bends_deg=tuple(bend) if bend else (45.0,),
        rating_margin=rating_margin,
        bandwidth_floor_hz=bandwidth_floor,
        shaft_file=None if shaft_file is None else str(shaft_file),
        executor=executor,
        workers=workers,
    )
    report: dict[str, object] = {"task": task.__dict__, "objective": objective}
    if pareto is not None:
        front, evaluated, sims = ts.pareto(
            task, store, (objective, pareto), budget_each=max(16, budget // 2), seed=seed
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
        report["pareto"] = [e.__dict__ for e in front]
        if out is not None:
            png = ts.pareto_plot(front, evaluated, objective, pareto, out / "pareto.png")
            console.print(f"plot: {png}", markup=False)
    else:
        s = ts.select(task, store, objective, budget=budget, seed=seed)
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
        report["best"] = b.__dict__
        report["nearest"] = {n: e.__dict__ for n, e in zip(s.nearest_names, s.nearest, strict=True)}
        report["simulations"] = s.simulations
        if uncertainty:
            metric = functools.partial(
                ts.shaft_metrics,
                diameter_mm=b.diameter_mm,
                length_mm=b.length_mm,
                scenario=scenario,
                payload_kg=payload_kg,
                duration_s=duration,
                bends_deg=task.bends_deg,
                controller_catalogue=load_catalogue(shaft_file)
                if uncertainty_controller == "nominal"
                else None,
            )
            prop = unc.propagate(metric, load_catalogue(shaft_file), uncertainty)
            band = prop.bands[objective]
            console.print(
                f"  {objective} at the optimum, 5-95 % over {prop.samples} coefficient "
                f"samples: [{band.low:.4g}, {band.high:.4g}] (median {band.median:.4g})",
                markup=False,
            )
            report["uncertainty"] = unc.to_json(prop, controller=str(uncertainty_controller))
    if out is not None:
        text = json.dumps(report, indent=2, default=str)
        console.print(f"result: {write_text(out / 'select.json', text)}", markup=False)


def register(app: typer.Typer) -> None:
    app.command("datasheet")(datasheet_cmd)
    app.command("select")(select_cmd)
