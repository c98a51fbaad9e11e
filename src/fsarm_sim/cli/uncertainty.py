"""``--uncertainty N`` of ``fsarm run`` (and the band table the design commands share): thin
over :mod:`fsarm_sim.studies.uncertainty`."""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from rich.table import Table

from fsarm_sim.cli.console import make_console
from fsarm_sim.errors import FsarmError
from fsarm_sim.outputs import SafeWriter, write_text

if TYPE_CHECKING:
    from fsarm_sim.run_request import RunRequest

console = make_console()


def band_table(
    title: str, report: Mapping[str, Any], keys: Iterable[tuple[str, str]], unit_note: str = ""
) -> Table:
    """Nominal, 5 %, 50 %, 95 % of the chosen metrics of a :func:`to_json` report."""
    table = Table(title=title + unit_note)
    for col in ("metric", "nominal", "5 %", "50 %", "95 %"):
        table.add_column(col, justify="left" if col == "metric" else "right")
    metrics = report["metrics"]
    for key, label in keys:
        if key not in metrics:
            continue
        m = metrics[key]
        nominal = m.get("nominal")
        table.add_row(
            label,
            "-" if nominal is None else f"{nominal:.4g}",
            f"{m['p05']:.4g}",
            f"{m['p50']:.4g}",
            f"{m['p95']:.4g}",
        )
    return table


def run_uncertainty(request: RunRequest, result: Any, writes: SafeWriter) -> dict[str, Any]:
    """Sample the run's metrics over the declared coefficient ranges, print their band and,
    with ``--json``, write it beside the summary as ``<name>.uncertainty.json``."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import uncertainty as unc

    controller, json_file = request.uncertainty_controller, request.json_file
    cat = load_catalogue(request.shaft_file)
    metric = functools.partial(
        unc.run_metrics,
        scenario=result.scenario,
        config=result.config,
        diameter_mm=request.diameter_mm,
        length_mm=request.length_mm,
        extrapolate=request.extrapolate,
        series_hysteresis=request.series_hysteresis,
        duration_s=result.duration_s,
        payload_kg=result.config.payload_kg,
        backend=request.backend,
        controller=controller,
    )
    prop = unc.propagate(metric, cat, request.uncertainty)
    report = unc.to_json(prop, result.metrics, controller)
    console.print(
        band_table(
            f"{result.scenario}: 5-95 % band over {prop.samples} samples of the coefficient "
            f"ranges ({', '.join(prop.groups)}; {controller} controller; {prop.wall_s:.1f} s)",
            report,
            unc.RUN_KEYS,
        )
    )
    if prop.failed:
        console.print(f"{prop.failed} sample(s) failed: {prop.errors[0]}", markup=False)
    if json_file is not None:
        path = json_file.with_name(json_file.stem + ".uncertainty.json")
        text = json.dumps(report, indent=2)
        where = writes.write(path, lambda p: write_text(p, text), "the band (--uncertainty)")
        if where is not None:
            console.print(f"uncertainty: {where}")
    if prop.failed == prop.samples:
        raise FsarmError(f"--uncertainty: every sample failed ({prop.errors[0]})")
    return report
