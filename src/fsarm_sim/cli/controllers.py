"""``fsarm compare-controllers`` and ``fsarm identify-hysteresis``: joint 3's controller options."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from fsarm_sim.cli.console import make_console, number_table, write_rows_json
from fsarm_sim.cli.progress import steps
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan, SafeWriter, write_text

console = make_console()
err = make_console(stderr=True)


def parse_shaft(text: str) -> tuple[float, float]:
    """``D,L`` (mm) -> (D, L); InvalidParameterError otherwise."""
    parts = text.replace("x", ",").split(",")
    try:
        d, ell = (float(p) for p in parts)
    except ValueError:
        raise InvalidParameterError(
            f"--shaft takes D,L in mm (e.g. 9,450 or 9x450), got {text!r}"
        ) from None
    return d, ell


def _cell(x: float | None, fmt: str, above: str = "") -> str:
    if x is None:
        return "-"
    if math.isnan(x):
        return above or "n/a"
    return format(x, fmt)


# the options of `compare_controllers_cmd`
CompareController = Annotated[
    list[str] | None,
    typer.Option(help="controllers to compare (repeatable; default: all four)"),
]
CompareShaft = Annotated[
    list[str] | None,
    typer.Option(help="catalogue shaft D,L in mm (repeatable; default 9,450)"),
]
CompareBends = Annotated[str, typer.Option(help="bend angles for bandwidth/impedance, deg")]
CompareDuration = Annotated[
    float | None, typer.Option(help="length of each tracking run, s (default: scenario's)")
]
CompareIdentify = Annotated[
    bool,
    typer.Option(
        help="identify hysteresis-comp's model from each shaft's simulated bench records "
        "(minutes per shaft; else the identified default scaled to the shaft)"
    ),
]
CompareFrequency = Annotated[
    bool, typer.Option(help="also measure torque bandwidth and output impedance")
]
CompareJsonFile = Annotated[Path | None, typer.Option("--json", help="write the rows here")]


def compare_controllers_cmd(
    controller: CompareController = None,
    shaft: CompareShaft = None,
    bends: CompareBends = ("0,45,90"),
    duration: CompareDuration = None,
    identify: CompareIdentify = False,
    frequency: CompareFrequency = True,
    json_file: CompareJsonFile = None,
) -> None:
    """Joint-3 controllers side by side: tracking, torque estimate, bandwidth, impedance, work."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import controller_comparison

    OutputPlan().file("--json", json_file).check()
    try:
        bend_list = tuple(float(b) for b in bends.split(",") if b.strip())
    except ValueError:
        raise InvalidParameterError(
            f"--bends takes comma-separated numbers, got {bends!r}"
        ) from None
    cat = load_catalogue()
    shafts = [cat.shaft(*parse_shaft(s), series_hysteresis=True) for s in (shaft or ["9,450"])]
    controllers = tuple(controller) if controller else controller_comparison.DEFAULT_CONTROLLERS
    models = _identified_models(shafts) if identify and "hysteresis-comp" in controllers else {}
    with steps("compare-controllers") as report:
        count = itertools.count(1)
        rows = controller_comparison.compare(
            shafts,
            controllers,
            bends_deg=bend_list,
            duration_s=duration,
            models=models,
            frequency=frequency,
            progress=lambda msg: report(msg, next(count), None),
        )
    console.print(_comparison_table(rows, bend_list, frequency))
    if frequency:
        console.print(
            "BW >40: no -3 dB point below 40 Hz (the chirp's top band). |Z|: output impedance "
            "in its lowest band (near 0.8 Hz) with zero torque commanded (0 = transparent).",
            markup=False,
        )
    for r in rows:
        for f in r.failures:
            err.print(f"{r.shaft} {r.controller}: {f}", markup=False)
    write_rows_json(json_file, rows, console, err)


def _identified_models(shafts: list[Any]) -> dict[str, tuple[float, ...]]:
    """hysteresis-comp's model of each shaft, identified on its simulated bench records."""
    from fsarm_sim.studies import controller_comparison
    from fsarm_sim.studies.hysteresis_id import identify_shaft

    models: dict[str, tuple[float, ...]] = {}
    for sh in shafts:
        label = controller_comparison.shaft_label(sh)
        err.print(f"identifying {label} on its bench records ...", markup=False)
        models[label] = identify_shaft(sh).values
    return models


def _comparison_table(rows: list[Any], bend_list: tuple[float, ...], frequency: bool) -> Table:
    """One row per shaft and controller: tracking per case, estimate, work, bandwidth, |Z|."""
    from fsarm_sim.studies import controller_comparison

    cases = [c[0] for c in controller_comparison.TRACKING_CASES]
    cols = [
        "shaft",
        "controller",
        *[f"q3 {c} [°]" for c in cases],
        "τ-est [N·m]",
        "τ-est 15kg",
        "work [J]",
    ]
    if frequency:
        cols += [f"BW {b:g}° [Hz]" for b in bend_list]
        cols += [f"|Z| {b:g}°" for b in bend_list]
    table = number_table(
        "joint-3 controllers: q3 RMSE per case; τ estimate error RMS and motor work on "
        "fig14-sine; |Z| in N·m/rad",
        cols,
    )
    for r in rows:
        cells = [r.shaft, r.controller]
        cells += [_cell(r.q3_rmse_deg.get(c), ".4f") for c in cases]
        cells.append(_cell(r.tau_estimate_rmse_nm, ".4f"))
        cells.append(_cell(r.tau_estimate_rmse_15kg_nm, ".3f"))
        cells.append(_cell(r.motor_work_j, ".2f"))
        if frequency:
            cells += [_cell(r.bandwidth_hz.get(f"{b:g}"), ".1f", ">40") for b in bend_list]
            cells += [_cell(r.impedance_nm_per_rad.get(f"{b:g}"), ".4g") for b in bend_list]
        table.add_row(*cells)
    return table


def identify_hysteresis_cmd(
    out: Annotated[Path, typer.Option(help="model file to write (TOML, [model])")],
    diameter_mm: Annotated[float, typer.Option(help="catalogue shaft diameter, mm")] = 9.0,
    length_mm: Annotated[float, typer.Option(help="catalogue shaft length, mm")] = 450.0,
    record: Annotated[
        list[Path] | None,
        typer.Option(help="series-bench dataset(s) to fit instead of simulating (repeatable)"),
    ] = None,
) -> None:
    """Identify hysteresis-comp's Maxwell-slip model from series-bench records."""
    from fsarm_sim.engine.hysteresis_model import model_toml
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import hysteresis_id as hid

    plan = OutputPlan().file("--out", out)
    for r in record or []:
        plan = plan.input("a --record dataset", r)
    plan.check()
    if record:
        model = hid.identify_files(record)
        how = f"identified from {', '.join(str(r) for r in record)}"
    else:
        shaft = load_catalogue().shaft(diameter_mm, length_mm, series_hysteresis=True)
        model = hid.identify_shaft(shaft)
        how = (
            f"identified from the simulated series bench of {diameter_mm:g} x {length_mm:g} "
            f"mm at bends {', '.join(f'{b:g}' for b in model.bends_deg)} deg"
        )
    how += f"\nfit RMSE {model.rmse_nm:.4g} N*m (eq. 8 on the same records {model.eq8_rmse_nm:.4g})"
    for note in model.notes:
        how += f"\nnote: {note}"
    table = number_table("identified hysteresis model", ("parameter", "value"))
    for k, v in model.as_dict().items():
        table.add_row(k, f"{v:.5g}")
    console.print(table)
    console.print(how, markup=False)
    safe = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    where = safe.write(out, lambda p: write_text(p, model_toml(model.values, how)), "--out")
    if where is not None:
        console.print(
            f"model: {where}  (use: fsarm run ... --controller hysteresis-comp "
            f"--hysteresis-model {where})",
            markup=False,
        )
    safe.finish()


def register(app: typer.Typer) -> None:
    app.command("compare-controllers")(compare_controllers_cmd)
    app.command("identify-hysteresis")(identify_hysteresis_cmd)
