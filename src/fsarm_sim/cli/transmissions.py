"""``fsarm transmissions``, ``fsarm compare-transmissions``, ``fsarm transparency``."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim.choices import Scenario, Transmission
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console, number_table, write_rows_json
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan, safe_write, write_text
from fsarm_sim.run_request import parse_params

console = make_console()

SCALAR_GAINS = (
    "torque_bandwidth_rad_s",
    "torque_integral_rad_s",
    "torque_derivative",
    "speed_kp",
    "speed_ki",
)


def parse_gains(items: list[str]) -> dict[str, float]:
    """``NAME=VALUE`` for the scalar torque/speed-loop gains of :class:`fsarm_sim.engine.model.Gains`."""
    out = dict(parse_params(items))
    for name in out:
        if name not in SCALAR_GAINS:
            raise InvalidParameterError(
                f"--gain {name!r} is not a tunable gain; allowed: {', '.join(SCALAR_GAINS)}"
            )
    return out


def transmissions_cmd(
    name: Annotated[
        Transmission | None,
        typer.Argument(help="show one transmission's parameters", case_sensitive=False),
    ] = None,
) -> None:
    """List joint 3's transmissions (or one with its parameters and their sources)."""
    from fsarm_sim.plant import transmissions

    if name is None:
        table = Table(title="joint-3 transmissions (fsarm run --transmission NAME)")
        for col in ("name", "title", "source", "states", "over joint 2"):
            table.add_column(col)
        for n in transmissions.names():
            tr = transmissions.get(n)
            table.add_row(
                n,
                tr.title,
                tr.source,
                ", ".join(tr.states) or "-",
                "yes" if tr.routed_over_joint2 else "no",
            )
        console.print(table)
        return
    tr = transmissions.get(str(name))
    table = Table(title=f"{name}: {tr.title}")
    for col in ("parameter", "value", "unit", "source"):
        table.add_column(col)
    for p in tr.params:
        table.add_row(p.name, f"{p.value:.6g}", escape(p.unit), escape(p.source))
    console.print(table)


# the options of `compare_cmd`
CompareTransmissionsOnly = Annotated[
    list[Transmission] | None,
    typer.Option(help="compare only these (repeatable)", case_sensitive=False),
]
CompareTransmissionsPayloadKg = Annotated[float | None, typer.Option(help="payload, kg")]
CompareTransmissionsDuration = Annotated[float | None, typer.Option(help="simulated time, s")]
CompareTransmissionsQuick = Annotated[
    bool, typer.Option(help="tracking only: skip bandwidth/impedance")
]
CompareTransmissionsGain = Annotated[
    list[str] | None,
    typer.Option(help="joint-3 loop gain for all, NAME=VALUE (repeatable)"),
]
CompareTransmissionsJsonFile = Annotated[
    Path | None, typer.Option("--json", help="write rows here")
]


def _check_compare(
    payload_kg: float | None, duration: float | None, json_file: Path | None
) -> None:
    """--duration, --payload-kg (0..PAYLOAD_MAX_KG) and --json, before any simulation."""
    from fsarm_sim.engine.model import PAYLOAD_MAX_KG
    from fsarm_sim.sim.simulation import check_duration

    if duration is not None:
        check_duration(duration)
    if payload_kg is not None and not (
        math.isfinite(payload_kg) and 0.0 <= payload_kg <= PAYLOAD_MAX_KG
    ):
        raise InvalidParameterError(
            f"--payload-kg must be between 0 and {PAYLOAD_MAX_KG:g} kg, got {payload_kg!r}"
        )
    OutputPlan().file("--json", json_file).check()


def compare_cmd(
    scenario: opt.ScenarioOption = Scenario.FIG14_SINE,
    only: CompareTransmissionsOnly = None,
    payload_kg: CompareTransmissionsPayloadKg = None,
    duration: CompareTransmissionsDuration = None,
    quick: CompareTransmissionsQuick = False,
    gain: CompareTransmissionsGain = None,
    json_file: CompareTransmissionsJsonFile = None,
) -> None:
    """Tracking RMSE, peak torque, motor work, bandwidth and impedance across transmissions."""
    from fsarm_sim.engine.model import Gains, SimConfig
    from fsarm_sim.studies.comparison import COLUMNS, compare, fmt

    _check_compare(payload_kg, duration, json_file)
    base = SimConfig(gains=Gains(**parse_gains(gain or [])))  # type: ignore[arg-type]
    rows = compare(
        [str(t) for t in only] if only else None,
        str(scenario),
        payload_kg=payload_kg,
        duration_s=duration,
        base=base,
        analyses=not quick,
    )
    table = Table(title=f"transmissions on {scenario}")
    table.add_column("transmission")
    for _, label, _ in COLUMNS:
        table.add_column(escape(label), justify="right")
    notes = []
    for r in rows:
        if r.error:
            notes.append(f"{r.transmission}: {r.error}")
            table.add_row(r.transmission, "[red]failed[/]", *[""] * (len(COLUMNS) - 1))
        else:
            table.add_row(r.transmission, *(fmt(r.metrics.get(k), p) for k, _, p in COLUMNS))
    console.print(table)
    for note in notes:
        console.print(f"[red]failed[/] {escape(note)}")
    err = make_console(stderr=True)
    write_rows_json(json_file, rows, console, err)
    if notes:
        err.print(f"{len(notes)} of {len(rows)} transmission(s) failed", markup=False)
        raise typer.Exit(code=1)


# the options of `transparency_cmd`
TransparencyBend = Annotated[list[float] | None, typer.Option(help="bend angles, deg (repeatable)")]
TransparencyFixedGains = Annotated[
    bool, typer.Option(help="torque PID gains fixed at the straight stiffness (seed 001)")
]
TransparencyJsonFile = Annotated[Path | None, typer.Option("--json", help="write results here")]


def transparency_cmd(
    transmission: opt.Transmission = Transmission.FLEXIBLE_SHAFT,
    bend: TransparencyBend = None,
    fixed_gains: TransparencyFixedGains = False,
    json_file: TransparencyJsonFile = None,
) -> None:
    """Torque-loop bandwidth and output impedance vs bend (seed 001 Sec. 4.1.2, 4.2)."""
    from fsarm_sim.engine.model import Gains, SimConfig
    from fsarm_sim.studies.transparency import DEFAULT_BENDS_DEG, bend_note, versus_bend

    OutputPlan().file("--json", json_file).check()
    cfg = SimConfig(transmission=str(transmission), gains=Gains(gain_schedule=not fixed_gains))
    bends = tuple(bend) if bend else DEFAULT_BENDS_DEG
    points = versus_bend(cfg, bends)
    mode = "fixed" if fixed_gains else "scheduled"
    table = number_table(
        f"{transmission}: torque loop vs bend ({mode} gains)",
        ("bend [deg]", "bandwidth [Hz]", "|Z| low f [N·m/rad]", "passive K [N·m/rad]"),
    )
    for p in points:
        table.add_row(
            f"{p.bend_deg:g}",
            f"{p.bandwidth.bandwidth_hz:.2f}",
            f"{p.impedance.low_freq_nm_per_rad:.2f}",
            f"{p.impedance.passive_nm_per_rad:.1f}",
        )
    console.print(table)
    if not cfg.transmission_model().routed_over_joint2:
        console.print(
            f"note: {transmission} is not routed over joint 2: its law does not read the "
            "bend, so these rows differ only where joint 2's pose changes the arm",
            markup=False,
        )
    note = bend_note(cfg, bends)
    if note:
        console.print(note, markup=False)
    if json_file is not None:
        _write_transparency_json(json_file, points)


def _write_transparency_json(json_file: Path, points: Sequence[Any]) -> None:
    """The bend points as a JSON list (--json), and where it went."""
    text = json.dumps(
        [
            {
                "bend_deg": p.bend_deg,
                "bandwidth_hz": p.bandwidth.bandwidth_hz,
                "impedance_low_nm_per_rad": p.impedance.low_freq_nm_per_rad,
                "passive_stiffness_nm_per_rad": p.impedance.passive_nm_per_rad,
            }
            for p in points
        ],
        indent=2,
    )
    where = safe_write(json_file, lambda q: write_text(q, text), "the results (--json)")
    console.print(f"results: {where}", markup=False)


def register(app: typer.Typer) -> None:
    app.command("transmissions")(transmissions_cmd)
    app.command("compare-transmissions")(compare_cmd)
    app.command("transparency")(transparency_cmd)
