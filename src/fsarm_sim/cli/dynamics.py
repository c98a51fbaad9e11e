"""``fsarm check-dynamics``: Pinocchio referees MuJoCo (issue 3). Thin: options in, tables out.

Runs :func:`fsarm_sim.studies.dynamics_check.run_checks`, prints one row per check (tolerance, measured,
pass/fail), the eq. 5-7 structure and the trajectory convergence table, optionally writes JSON,
and exits with code 1 when any check fails.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim.cli.console import make_console, number_table
from fsarm_sim.outputs import OutputPlan, SafeWriter, write_text

if TYPE_CHECKING:  # the simulator is imported inside the command: `fsarm` starts quickly
    from fsarm_sim.studies.dynamics_check import DynamicsReport

console = make_console()


def _json_safe(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json_safe(v) for v in x]
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if hasattr(x, "item"):  # numpy scalars
        return _json_safe(x.item())
    return x


def checks_table(report: DynamicsReport) -> Table:
    table = Table(title="Pinocchio vs MuJoCo (fsarm check-dynamics)")
    for col in ("check", "tolerance", "measured", "result"):
        table.add_column(col, justify="left" if col == "check" else "right")
    for c in report.checks:
        sign = ">=" if c.at_least else "<="
        verdict = "[green]pass[/]" if c.passed else "[bold red]FAIL[/]"
        table.add_row(
            escape(c.name),
            f"{sign} {c.tolerance:.1e} {escape(c.unit)}",
            f"{c.measured:.3e}",
            verdict,
        )
    return table


def structure_table(report: DynamicsReport) -> Table:
    table = Table(
        title="seed 000 eq. 5-7 in (q1, q2, q3, theta_m): measured vs implied by the MJCF"
    )
    for col in ("entry", "measured", "expected", "rel. error"):
        table.add_column(col, justify="left" if col == "entry" else "right")
    for e in report.structure.entries:
        table.add_row(escape(e.name), f"{e.measured:.10g}", f"{e.expected:.10g}", f"{e.error:.1e}")
    return table


def convergence_table(report: DynamicsReport) -> Table | None:
    study = report.trajectory
    if study is None:
        return None
    table = number_table(
        f"{study.scenario}, {study.duration_s:g} s: max |q error| (rad, q1-q3) vs "
        f"Pinocchio RK4 reference at dt = {study.reference_dt_s:g} s",
        ("dt [s]", "MuJoCo RK4", "order", "Pinocchio RK4", "order", "MuJoCo vs Pinocchio, same dt"),
    )

    def order(v: float | None) -> str:
        return "" if v is None else f"{v:.2f}"

    for r in study.rows:
        table.add_row(
            f"{r.dt_s:g}",
            f"{r.mujoco_vs_reference_rad:.3e}",
            order(r.order_mujoco),
            f"{r.pinocchio_vs_reference_rad:.3e}",
            order(r.order_pinocchio),
            f"{r.mujoco_vs_pinocchio_same_dt_rad:.3e}",
        )
    return table


# the options of `check_dynamics_cmd`
CheckDynamicsJsonFile = Annotated[
    Path | None, typer.Option("--json", help="write all measured numbers here (JSON)")
]
CheckDynamicsSamples = Annotated[
    int, typer.Option(help="random states per model for the mass/bias/qacc checks")
]
CheckDynamicsDuration = Annotated[
    float, typer.Option(help="simulated seconds of fig14-sine for the trajectory check")
]
CheckDynamicsShaftInertia = Annotated[
    float,
    typer.Option(help="also check a model with this eq. 1 shaft inertia J, kg m^2 (0: skip)"),
]
CheckDynamicsTrajectory = Annotated[
    bool, typer.Option(help="run the closed-loop trajectory comparison")
]


def check_dynamics_cmd(
    json_file: CheckDynamicsJsonFile = None,
    samples: CheckDynamicsSamples = 200,
    duration: CheckDynamicsDuration = 4.0,
    shaft_inertia: CheckDynamicsShaftInertia = 0.0,
    trajectory: CheckDynamicsTrajectory = True,
) -> None:
    """Check MuJoCo's dynamics against Pinocchio; exit 1 if any check fails."""
    from fsarm_sim.cli.progress import steps
    from fsarm_sim.studies.dynamics_check import run_checks

    OutputPlan().file("--json", json_file).check()
    with steps("check-dynamics") as progress:
        report = run_checks(
            samples=samples,
            duration_s=duration,
            shaft_inertia_kgm2=shaft_inertia,
            trajectory=trajectory,
            progress=progress,
        )
    console.print(checks_table(report))
    console.print(structure_table(report))
    conv = convergence_table(report)
    if conv is not None:
        console.print(conv)
    if report.trajectory is not None:
        console.print(
            "MuJoCo Euler at the default 1 ms step (implicit joint damping) vs the reference: "
            f"{report.trajectory.mujoco_euler_default_rad:.3e} rad",
            markup=False,
        )
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    if json_file is not None:
        text = json.dumps(_json_safe(report.as_dict()), indent=2)
        where = writes.write(json_file, lambda p: write_text(p, text), "the results (--json)")
        if where is not None:
            console.print(f"JSON: {where}", markup=False)
    if not report.passed:
        failed = ", ".join(c.key for c in report.checks if not c.passed)
        console.print(f"[bold red]dynamics check failed:[/] {escape(failed)}")
    writes.finish()
    if not report.passed:
        raise typer.Exit(code=1)
    console.print("[green]all dynamics checks passed[/]")


def register(app: typer.Typer) -> None:
    """Add ``check-dynamics`` to the ``fsarm`` app."""
    app.command("check-dynamics")(check_dynamics_cmd)
