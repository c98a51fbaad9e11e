"""``fsarm collision``: sensorless collision detection and hand guiding at joint 3 (seed 004).

Identifies the detection threshold on collision-free runs, then runs ``collision-hit`` (and its
collision-free twin), ``fig14-sine`` and ``p2p-payload`` through the momentum observer and, on the
same runs, seed 004's own Algorithm 1 (eq. 19 branches identified without disturbance, the delta
rule), and ``hand-guide`` through the admittance loop (:mod:`fsarm_sim.studies.collision`); prints detection delay, false alarms and the
hand-guided motion as tables, optionally as JSON.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from fsarm_sim.choices import Backend, Transmission
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.outputs import OutputPlan, safe_write, write_text

if TYPE_CHECKING:
    from fsarm_sim.studies.collision import Battery, GuidingReport


def _fmt(x: float | None, scale: float = 1.0, digits: int = 3) -> str:
    return "-" if x is None else f"{x * scale:.{digits}g}"


# the options of `collision_cmd`
CollisionSeriesHysteresis = Annotated[
    bool | None,
    typer.Option(
        help="flexible shaft: Maxwell-slip series hysteresis on/off "
        "(default: the coefficient file's, on)"
    ),
]
CollisionJsonFile = Annotated[
    Path | None, typer.Option("--json", help="write the results as JSON here")
]


def collision_cmd(
    transmission: opt.Transmission = Transmission.FLEXIBLE_SHAFT,
    tr_param: opt.TrParam = None,
    series_hysteresis: CollisionSeriesHysteresis = None,
    backend: opt.Backend = Backend.NATIVE,
    json_file: CollisionJsonFile = None,
) -> None:
    """Collision detection (delay, false alarms) and hand guiding from the two encoders."""
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.run_request import check_shaft_options, parse_params
    from fsarm_sim.studies.collision import run_battery

    OutputPlan().file("--json", json_file).check()
    check_shaft_options(
        str(transmission), [] if series_hysteresis is None else ["--[no-]series-hysteresis"]
    )
    cfg = SimConfig(
        shaft=load_catalogue().shaft(series_hysteresis=series_hysteresis),
        transmission=str(transmission),
        transmission_params=parse_params(tr_param or []),
    )
    cfg.validate()
    bat = run_battery(cfg, str(backend))  # type: ignore[arg-type]
    console = make_console()
    _print_detection(console, bat, str(transmission))
    if bat.guiding is None:
        console.print(f"hand-guide skipped: {bat.guiding_skipped}", markup=False)
    else:
        _print_guiding(console, bat)
    _write_json(json_file, bat.as_dict(), console)


def _print_detection(console: Console, bat: Battery, transmission: str) -> None:
    """The observer's threshold, the detection table, Algorithm 1's and the skipped runs."""
    cal = bat.calibration
    console.print(
        f"joint-3 external-torque observer (K_O = {bat.gain_rad_s:g} rad/s) on "
        f"{transmission}: threshold delta_a = {cal.threshold_nm:.4g} N·m = "
        f"{cal.margin:g} x {cal.max_abs_residual_nm:.4g} N·m (largest |r| of "
        f"{', '.join(cal.runs)})",
        markup=False,
    )
    table = Table(title="collision detection (momentum observer, Algorithm 1's delta rule on r)")
    for col in (
        "run",
        "contact [s]",
        "peak tau_ext [N·m]",
        "peak |r| [N·m]",
        "detected [s]",
        "delay [ms]",
        "false alarms",
    ):
        table.add_column(escape(col), justify="left" if col == "run" else "right")
    for d in bat.detection:
        contact = "-" if d.contact_s is None else f"{d.contact_s[0]:g}-{d.contact_s[1]:g}"
        if d.skipped is not None:
            table.add_row(escape(d.run), contact, "skipped", "", "", "", "")
            continue
        table.add_row(
            escape(d.run),
            contact,
            f"{d.peak_external_nm:.3g}",
            f"{d.peak_estimate_nm:.3g}",
            _fmt(d.detected_s, digits=4),
            _fmt(d.delay_s, 1e3),
            str(d.false_alarms),
        )
    console.print(table)
    _print_algorithm1(console, bat)
    for d in bat.detection:
        if d.skipped is not None:
            console.print(f"{d.run} skipped: {d.skipped}", markup=False)


def _print_guiding(console: Console, bat: Battery) -> None:
    """Hand guiding by the observer + admittance, and by seed 004's Algorithm 2."""
    g = bat.guiding
    assert g is not None
    console.print(_guiding_table("hand guiding (observer + admittance on joint 3)", g))
    console.print(
        f"{_holds_line(g)}; work of the hand on joint 3: {g.human_work_j:.3g} J; final "
        f"joint-3 speed {math.degrees(g.final_speed_rad_s):.3g} deg/s",
        markup=False,
    )
    if bat.guiding_alg2_failed is not None:
        console.print(
            f"hand guiding by Algorithm 2 failed: {bat.guiding_alg2_failed}", markup=False
        )
    g2 = bat.guiding_alg2
    if g2 is not None:
        console.print(
            _guiding_table("hand guiding (seed 004 Algorithm 2: the motor follows the joint)", g2)
        )
        line = _holds_line(g2)
        if not (g2.holds() and g2.stays()):
            line += (
                " - Algorithm 2 has no position to return to (the joint's reference is its "
                "own reading), so whatever the transmission's torque estimate does not see "
                "(hysteresis, friction) acts on after release as a push would"
            )
        console.print(line, markup=False)


def register(app: typer.Typer) -> None:
    app.command("collision")(collision_cmd)


def _guiding_table(title: str, g: GuidingReport) -> Table:
    """One hand-guiding run: per push its travel and the motor's share of it, then the drift and
    speed after release."""
    t = number_table(
        title,
        (
            "push [s]",
            "mean tau_ext [N·m]",
            "travel [deg]",
            "motor's share",
            "drift after release [deg]",
            "max speed after release [deg/s]",
        ),
    )
    for p in g.pushes:
        t.add_row(
            f"{p['start_s']:g}-{p['end_s']:g}",
            f"{p['mean_push_nm']:.3g}",
            f"{math.degrees(p['travel_rad']):.3g}",
            f"{p['motor_share']:.3g}",
            f"{math.degrees(p['drift_after_release_rad']):.3g}",
            f"{math.degrees(p['speed_after_release_rad_s']):.3g}",
        )
    return t


def _holds_line(g: GuidingReport) -> str:
    """Whether the joint followed the hand and stayed where it was left (the hand-guiding
    claim's criterion, :data:`fsarm_sim.studies.collision.HOLD_SPEED_RAD_S` / ``HOLD_DRIFT_RAD``)."""
    from fsarm_sim.studies.collision import HOLD_DRIFT_RAD, HOLD_SPEED_RAD_S

    if not g.follows():
        return "the joint did not follow every push"
    if g.holds() and g.stays():
        return (
            f"the joint follows the hand and holds after release (< "
            f"{math.degrees(HOLD_SPEED_RAD_S):.3g} deg/s, drift < "
            f"{math.degrees(HOLD_DRIFT_RAD):.3g} deg)"
        )
    return (
        f"the joint does NOT hold after release (limits {math.degrees(HOLD_SPEED_RAD_S):.3g} "
        f"deg/s, drift {math.degrees(HOLD_DRIFT_RAD):.3g} deg)"
    )


def _print_algorithm1(console: Console, bat: Any) -> None:
    """Seed 004's Algorithm 1 (eq. 19 branches, delta rule) beside the observer, same runs."""
    pm = bat.position_model
    if pm is None:
        console.print(f"Algorithm 1 not run: {bat.position_model_skipped}", markup=False)
        return
    console.print(
        f"seed 004 Algorithm 1 on the same runs: eq. 19 fitted on {', '.join(pm.runs)}; "
        f"M.E. {pm.max_error_rad:.4g} rad, delta_a = {pm.threshold_rad:.4g} rad",
        markup=False,
    )
    table = Table(title="collision detection: observer vs seed 004 Algorithm 1 (same runs)")
    for col in (
        "run",
        "observer delay [ms]",
        "observer false alarms",
        "Alg. 1 peak |delta| [rad]",
        "Alg. 1 delay [ms]",
        "Alg. 1 false alarms",
    ):
        table.add_column(escape(col), justify="left" if col == "run" else "right")
    for obs, alg in zip(bat.detection, bat.detection_alg1, strict=True):
        if obs.skipped is not None:
            table.add_row(escape(obs.run), "skipped", "", "", "", "")
            continue
        table.add_row(
            escape(obs.run),
            _fmt(obs.delay_s, 1e3),
            str(obs.false_alarms),
            f"{alg.peak_estimate_nm:.3g}",
            _fmt(alg.delay_s, 1e3) if alg.contact_s else "-",
            str(alg.false_alarms),
        )
    console.print(table)


def _write_json(path: Path | None, data: dict[str, object], console: Console) -> None:
    if path is not None:
        text = json.dumps(data, indent=2)
        where = safe_write(path, lambda p: write_text(p, text), "the results (--json)")
        console.print(f"results: {where}", markup=False)
