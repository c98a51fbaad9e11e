"""``fsarm datasheet`` and ``fsarm select``: designing a shaft (issue 32). Thin over
:mod:`fsarm_sim.studies.datasheet`, :mod:`~fsarm_sim.studies.task_selection` and
:mod:`~fsarm_sim.studies.uncertainty`."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Annotated

import typer

from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.outputs import OutputPlan

console = make_console()


def register(app: typer.Typer) -> None:
    @app.command("datasheet")
    def datasheet_cmd(
        shaft: Annotated[
            list[str] | None,
            typer.Option(help="catalogue shaft name (repeatable; see `fsarm shafts`)"),
        ] = None,
        all_shafts: Annotated[
            bool, typer.Option("--all", help="every shaft of the catalogue")
        ] = False,
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
                prop = unc.propagate(metric, cat, uncertainty)
                report = unc.to_json(prop)
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
