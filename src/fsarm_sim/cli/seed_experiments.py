"""``fsarm model-selection`` (seed 003, Tables 3-5), ``fsarm qa-throws`` (seed 002, Sec. VI-VII)
and ``fsarm rtca-fig12`` (seed 001, Fig. 12).

Thin: options in, the studies of :mod:`fsarm_sim.studies.magnetic_spring_selection` and
:mod:`fsarm_sim.studies.qa_joint_experiments` run, their tables printed (and written as JSON).
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Annotated, Any

import typer

from fsarm_sim.choices import StiffnessAdjust

# the studies are imported inside the commands, so that registering them keeps `fsarm` quick


def _write_json(json_file: Path | None, data: Any, printout: str = "") -> None:
    """Write ``data`` as JSON (saved before ``printout`` is printed), then print both."""
    from fsarm_sim.outputs import SafeWriter, write_text

    writes = SafeWriter(lambda msg: typer.echo(f"warning: {msg}", err=True))
    where = None
    if json_file is not None:
        text = json.dumps(data, indent=2, default=float)
        where = writes.write(json_file, lambda p: write_text(p, text), "the numbers (--json)")
    if printout:
        typer.echo(printout)
    if where is not None:
        typer.echo(f"numbers: {where}")
    writes.finish()


def _floats(option: str, text: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise typer.BadParameter(f"{option} takes comma-separated numbers, got {text!r}") from None


def model_selection_cmd(
    unbalance: Annotated[
        float, typer.Option(help="bench flywheel unbalance w [N·m] (estimate; not in seed 003)")
    ] = 9.81e-3,
    output_damping: Annotated[
        float, typer.Option(help="bench bearing damping y [N·m·s/rad] (estimate)")
    ] = 2e-4,
    trial_s: Annotated[float, typer.Option(help="length of each experiment-C trial [s]")] = 6.0,
    seed: Annotated[int, typer.Option(help="noise seed of experiment A")] = 0,
    free_run: Annotated[
        bool, typer.Option(help="also the long-term simulations (eq. 7, Fig. 13-15)")
    ] = False,
    json_file: Annotated[
        Path | None, typer.Option("--json", help="also write the numbers as JSON here")
    ] = None,
) -> None:
    """Seed 003's model selection (experiments A, B, C; models A-F, A_L, F_L) as Table 4."""
    from fsarm_sim.outputs import OutputPlan
    from fsarm_sim.studies import magnetic_spring_selection as sel

    OutputPlan().file("--json", json_file).check()
    cfg = sel.BenchConfig(
        unbalance_nm=unbalance, output_damping_nms=output_damping, trial_s=trial_s, seed=seed
    )
    st = sel.run_study(cfg, free_run=free_run)
    _write_json(
        json_file,
        {
            "config": {k: v for k, v in asdict(cfg).items()},
            "inertia_kgm2": st.inertia_kgm2,
            "spring_law": asdict(st.law),
            "rows": {m: asdict(r) for m, r in st.rows.items()},
            "free_run_rms_deg": st.free_run_deg,
        },
        st.table(),
    )


# the options of `qa_throws_cmd`
QaThrowsPresets = Annotated[str, typer.Option(help="Table IV presets σ [deg], comma-separated")]
QaThrowsSpeeds = Annotated[str, typer.Option(help="motor speeds θ'_d [deg/s], comma-separated")]
QaThrowsAdjust = Annotated[
    StiffnessAdjust,
    typer.Option(help="stiffness adjustment, eq. 20", case_sensitive=False),
]
QaThrowsLeverArms = Annotated[
    str, typer.Option(help="impact lever arms r [m] for the Sec. VII impact (empty: none)")
]
QaThrowsJsonFile = Annotated[
    Path | None, typer.Option("--json", help="also write the numbers as JSON here")
]


def qa_throws_cmd(
    presets: QaThrowsPresets = "3,7,11,15",
    speeds: QaThrowsSpeeds = "60,75,90,100,120",
    adjust: QaThrowsAdjust = StiffnessAdjust.NONE,
    lever_arms: QaThrowsLeverArms = "",
    json_file: QaThrowsJsonFile = None,
) -> None:
    """Seed 002's strike-out throws (ε = q'/θ'_d, Fig. 10) and impacts on the Table V bench."""
    from fsarm_sim.outputs import OutputPlan
    from fsarm_sim.studies import qa_joint_experiments as qx

    OutputPlan().file("--json", json_file).check()
    sig = _floats("--presets", presets)
    vel = _floats("--speeds", speeds)
    arms = _floats("--lever-arms", lever_arms)
    # every input checked before the table starts (an error is then the only output)
    if not sig or not vel:
        raise qx.QaExperimentError("--presets and --speeds need at least one number each")
    for v in vel:
        qx.check_speed_deg_s(v, "--speeds")
    mode = str(adjust)
    qx.check_adjust(mode, "--adjust")
    for r in arms:
        qx.check_lever_arm(r, "--lever-arms")
    benches = [(s, qx.bench(s)) for s in sig]  # a preset outside Table IV's range fails here
    rows = []
    typer.echo(
        f"{'σ [°]':>6} {'θd [°/s]':>9} {'ε':>6} {'q_f [°/s]':>10} {'t_s [s]':>8} "
        f"{'φmax [°]':>9} {'|τJ| [N·m]':>11}"
    )
    for s, b in benches:
        for v in vel:
            t = qx.best_throw(b, v, adjust=mode)
            rows.append(asdict(t))
            if not t.feasible:
                typer.echo(f"{s:>6g} {v:>9g}   infeasible (no switch time meets the constraints)")
                continue
            typer.echo(
                f"{s:>6g} {v:>9g} {t.epsilon:>6.3f} {t.link_velocity_deg_s:>10.1f} "
                f"{t.t_switch_s:>8.3f} {t.phi_max_deg:>9.2f} {t.tau_j_max_nm:>11.1f}"
            )
    impacts = _print_impacts(sig, arms)
    _write_json(json_file, {"adjust": mode, "throws": rows, "impacts": impacts})


def _print_impacts(presets: list[float], arms: list[float]) -> list[dict[str, Any]]:
    """Sec. VII's impact at each lever arm on each preset, printed one line per arm."""
    from fsarm_sim.studies import qa_joint_experiments as qx

    impacts = []
    if arms:
        typer.echo("impact 4.2 kg at 1.07 m/s (Sec. VII): peak |τ_J| [N·m]")
        for r in arms:
            line = []
            for s in presets:
                imp = qx.impact(s, r)
                impacts.append(asdict(imp))
                line.append(f"σ {s:g}°: {imp.peak_joint_torque_nm:.1f}")
            typer.echo(f"  r = {r:g} m: " + ", ".join(line))
    return impacts


# the options of `rtca_fig12_cmd`
RtcaFig12RadiiMm = Annotated[
    str, typer.Option("--radii-mm", help="bend radii [mm], comma-separated; inf = straight")
]
RtcaFig12DurationS = Annotated[
    float, typer.Option(help="length of the 20° chirp 0.1-10 Hz [s] (>= 20)")
]
RtcaFig12IdealLoad = Annotated[
    bool,
    typer.Option(help="the load motor as an ideal position source (no speed limit)"),
]
RtcaFig12JsonFile = Annotated[
    Path | None, typer.Option("--json", help="also write the numbers as JSON here")
]


def rtca_fig12_cmd(
    radii_mm: RtcaFig12RadiiMm = "inf,450,200",
    duration_s: RtcaFig12DurationS = 60.0,
    ideal_load: RtcaFig12IdealLoad = False,
    json_file: RtcaFig12JsonFile = None,
) -> None:
    """Seed 001's Fig. 12 on its bench: |T̂_s/θ̇_s| per band at each bend, P and ZN PID."""
    import math

    from fsarm_sim.outputs import OutputPlan
    from fsarm_sim.studies import rtca_bench as rb

    OutputPlan().file("--json", json_file).check()
    radii = [math.inf if r == math.inf else r / 1000.0 for r in _floats("--radii-mm", radii_mm)]
    if not radii or any(not (r > 0.0) for r in radii):
        raise rb.BenchError("--radii-mm takes bend radii > 0 mm (inf = straight)")
    if not (math.isfinite(duration_s) and 20.0 <= duration_s <= 600.0):
        raise rb.BenchError(f"--duration-s must be in [20, 600] s, got {duration_s!r}")
    act, controllers = rb.paper_controllers()
    fig = rb.fig12(
        act,
        controllers,
        tuple(radii),
        load=None if ideal_load else rb.LoadServo(),
        duration_s=duration_s,
    )
    typer.echo("|T̂_s/θ̇_s| [N·m·s/rad] per fifth-of-a-decade band (seed 001 Fig. 12)")
    typer.echo(fig.table())
    _write_json(
        json_file,
        {
            "pid": {k: asdict(v) for k, v in controllers.items()},
            "reference_delay_s": act.reference_delay_s,
            "rows": [
                {
                    "controller": r.controller,
                    "radius_mm": 1000.0 * r.radius_m,
                    "freq_hz": r.freq_hz.tolist(),
                    "magnitude": r.magnitude.tolist(),
                    "peak_hz": r.peak_hz,
                }
                for r in fig.rows
            ],
        },
    )


def register(app: typer.Typer) -> None:
    app.command("model-selection")(model_selection_cmd)
    app.command("qa-throws")(qa_throws_cmd)
    app.command("rtca-fig12")(rtca_fig12_cmd)
