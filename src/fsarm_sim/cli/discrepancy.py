"""``fsarm diagnose`` and ``fsarm synth``: the discrepancy workflow on the command line.

Thin wrappers: argument parsing here, the work in :mod:`fsarm_sim.discrepancy` and
:mod:`fsarm_sim.discrepancy.synth`. The library is imported inside the commands so that ``fsarm`` stays quick
to start.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from fsarm_sim.choices import BenchLoad, BenchTrajectory, Scenario, Setup
from fsarm_sim.cli.console import make_console
from fsarm_sim.outputs import OutputPlan, SafeWriter, write_text

# the options of `fsarm synth` (SynthRequest's fields)
SynthOut = Annotated[Path, typer.Argument(help="output NAME(.csv|.parquet); NAME.json beside it")]
SynthSetup = Annotated[Setup, typer.Option(help="the record's setup", case_sensitive=False)]
SynthScenario = Annotated[
    Scenario,
    typer.Option(help="arm: the scenario run (see `fsarm scenarios`)", case_sensitive=False),
]
SynthNoiseRad = Annotated[
    float, typer.Option(help="arm: angle noise std, rad (plus 17-bit quantisation)")
]
SynthEffect = Annotated[
    list[str] | None,
    typer.Option(
        "--effect",
        help="hidden effect NAME[:VARIANT]=VALUES (repeatable), e.g. "
        "coulomb_friction:shaft=0.2, backlash=0.03,0.0, delay=0.01, "
        "hysteresis:maxwell_slip=12,0.008,6,0.025",
    ),
]
SynthModel = Annotated[
    Path | None, typer.Option("--model", help="truth model file (instead of --effect)")
]
SynthLoad = Annotated[
    BenchLoad | None,
    typer.Option(help="series bench's load [default: blocked]", case_sensitive=False),
]
SynthInertia = Annotated[
    float | None, typer.Option(help="stated load inertia, kg*m^2 [default: 0.01]")
]
SynthTrueInertia = Annotated[
    float | None, typer.Option(help="acting load inertia (default: the stated one)")
]
SynthStiffnessScale = Annotated[float, typer.Option(help="true stiffness / catalogue stiffness")]
SynthDiameterMm = Annotated[
    float,
    typer.Option(
        "--diameter-mm",
        "--diameter",
        help="shaft D, mm (--diameter: the name before 0.5.2)",
    ),
]
SynthLengthMm = Annotated[
    float,
    typer.Option("--length-mm", "--length", help="shaft L, mm (--length: the name before 0.5.2)"),
]
SynthNoise = Annotated[
    float | None,
    typer.Option(help="benches: torque noise std / torque range [default: 0.003]"),
]
SynthDuration = Annotated[float | None, typer.Option(help="s (default: 30; arm: the scenario's)")]
SynthRate = Annotated[
    float | None,
    typer.Option(
        help="sample rate, Hz [default: 1000]; arm: 1000 / k (every k-th control "
        "tick) or faster (the controller runs at it)"
    ),
]
SynthTrajectory = Annotated[
    BenchTrajectory | None,
    typer.Option(help="benches: the input [default: chirp]", case_sensitive=False),
]
SynthAmplitude = Annotated[float | None, typer.Option(help="benches: input amplitude, rad")]
SynthBendDeg = Annotated[
    float | None, typer.Option(help="series bench: held bend angle, deg [default: 0]")
]
SynthSeed = Annotated[int, typer.Option(help="random seed")]
SynthInputFile = Annotated[
    Path | None,
    typer.Option(
        "--input-file",
        help="benches: drive the bench with this trajectory file (t and theta_m / "
        "phi_b, as fsarm design-experiment writes) instead of --trajectory; the "
        "duration defaults to the file's",
    ),
]


# the options of `diagnose_cmd`
DiagnoseData = Annotated[
    Path, typer.Argument(help="dataset: NAME.csv / NAME.parquet (+ NAME.json)")
]
DiagnoseJsonFile = Annotated[
    Path | None, typer.Option("--json", help="write the machine-readable result here")
]
DiagnoseReport = Annotated[
    Path | None,
    typer.Option("--report", help="folder for result.json, model.json and plots"),
]
DiagnoseModelFile = Annotated[
    Path | None, typer.Option("--model", help="write the final model (JSON) here")
]
DiagnoseMaxEffects = Annotated[int, typer.Option(help="most effects to add")]
DiagnoseRrd = Annotated[
    Path | None,
    typer.Option(help="write a Rerun recording: measured vs models, residuals, loops"),
]


def diagnose_cmd(
    data: DiagnoseData,
    json_file: DiagnoseJsonFile = None,
    report: DiagnoseReport = None,
    model_file: DiagnoseModelFile = None,
    max_effects: DiagnoseMaxEffects = 4,
    rrd: DiagnoseRrd = None,
) -> None:
    """Replay the nominal model on a record, name the missing effects, fit them.

    Bench records and arm records (measured, synthetic, or written by `fsarm run` as they
    are); columns the diagnosis does not read are listed, not refused."""
    from fsarm_sim.discrepancy import diagnose_record
    from fsarm_sim.discrepancy import report as rep
    from fsarm_sim.errors import InvalidParameterError
    from fsarm_sim.records.measured import dataset_files, load_dataset

    if max_effects < 0:
        raise InvalidParameterError(
            f"--max-effects must be >= 0 (0: refit the nominal model only), got {max_effects}"
        )
    table, side = dataset_files(data)
    OutputPlan().input(f"the dataset {table}", table).input(
        f"the sidecar of the dataset {table}", side
    ).file("--json", json_file).file("--model", model_file).file("--rrd", rrd).folder(
        "--report", report, rep.REPORT_FILES
    ).check()
    console = make_console()
    err = make_console(stderr=True)
    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    ds = load_dataset(data)
    diag = diagnose_record(ds, max_effects=max_effects)
    rep.emit(
        diag,
        console,
        json_file=json_file,
        report=report,
        model_file=model_file,
        writes=writes,
    )
    if rrd is not None:
        from fsarm_sim.cli.diagnose_rrd import diagnosis_recording

        where = writes.write(rrd, lambda p: diagnosis_recording(diag, p), "the recording (--rrd)")
        if where is not None:
            console.print(f"rerun recording: {where}", markup=False)
    writes.finish()


# the options of `design_cmd`
DesignExperimentData = Annotated[
    Path, typer.Argument(help="bench dataset: NAME.csv / NAME.parquet (+ NAME.json)")
]
DesignExperimentOut = Annotated[
    Path,
    typer.Option("--out", help="the trajectory file to write (CSV: t and the input angle)"),
]
DesignExperimentJsonFile = Annotated[
    Path | None, typer.Option("--json", help="write every design's expected margins here")
]


def _print_design(res: dict[str, Any]) -> None:
    """The near-tie the design separates and the designed input's expected margins."""
    best = res["best"]
    own = res["own_input_expected_margin"]
    own_txt = f"{own:.1f}" if math.isfinite(own) else "an effect below the noise variance there"
    typer.echo(
        f"near-tie at step {res['step']}: {res['A']} vs {res['B']}, held-out BIC margin "
        f"{res['record_margin']:.1f} on this record (expected on its own input: {own_txt})"
    )
    typer.echo(
        f"designed input: {best['design']}; expected margin {best['expected_margin']:.1f} "
        f"(if {res['A']}: {best['expected_margin_if_A']:.1f}, if {res['B']}: "
        f"{best['expected_margin_if_B']:.1f})"
    )


def design_cmd(
    data: DesignExperimentData,
    out: DesignExperimentOut = Path("designed_input.csv"),
    json_file: DesignExperimentJsonFile = None,
) -> None:
    """Propose the bench input that best separates the diagnosis' closest two candidates.

    Diagnoses DATA, takes the named effect with the smallest held-out BIC margin over its
    runner-up, replays both fitted models on a family of inputs (shape, amplitude, bias)
    and writes the input with the largest expected margin as a trajectory file the bench
    plays (`fsarm synth --input-file` reads it too)."""
    import json

    from fsarm_sim.cli.progress import steps

    with steps("design-experiment") as progress:
        progress("loading the models", 0, 1)
        from fsarm_sim.discrepancy import design, synth
        from fsarm_sim.discrepancy.report import json_clean
        from fsarm_sim.records.measured import dataset_files, load_dataset

        table, side = dataset_files(data)
        OutputPlan().input(f"the dataset {table}", table).input(
            f"the sidecar of the dataset {table}", side
        ).file("--out", out).file("--json", json_file).check()
        ds = load_dataset(data)
        res = design.design(ds, progress=progress)
    # both files saved before anything is printed
    writes = SafeWriter(lambda msg: typer.echo(f"warning: {msg}", err=True))
    written = writes.write(
        out, lambda p: synth.write_input_file(p, res["t"], res["u"], ds.setup), "--out"
    )
    where = None
    if json_file is not None:
        body = {k: v for k, v in res.items() if k not in ("t", "u")}
        text = json.dumps(json_clean(body), indent=2) + "\n"
        where = writes.write(json_file, lambda p: write_text(p, text), "the result (--json)")
    _print_design(res)
    if written is not None:
        typer.echo(f"wrote {written} (columns t, {res['input_column']})")
    if where is not None:
        typer.echo(f"result: {where}")
    writes.finish()


def synth_cmd(
    out: SynthOut,
    setup: SynthSetup = Setup.SERIES_BENCH,
    scenario: SynthScenario = Scenario.FIG14_SINE,
    noise_rad: SynthNoiseRad = 2e-5,
    effect: SynthEffect = None,
    model: SynthModel = None,
    load: SynthLoad = None,
    inertia: SynthInertia = None,
    true_inertia: SynthTrueInertia = None,
    stiffness_scale: SynthStiffnessScale = 1.0,
    diameter_mm: SynthDiameterMm = 9.0,
    length_mm: SynthLengthMm = 450.0,
    noise: SynthNoise = None,
    duration: SynthDuration = None,
    rate: SynthRate = None,
    trajectory: SynthTrajectory = None,
    amplitude: SynthAmplitude = None,
    bend_deg: SynthBendDeg = None,
    seed: SynthSeed = 0,
    input_file: SynthInputFile = None,
) -> None:
    """Write a SYNTHETIC measured-format dataset with chosen hidden effects and noise."""
    options = dict(locals())
    from fsarm_sim.cli.progress import steps

    with steps("synth") as progress:
        progress("loading the models", 0, 3)
        from fsarm_sim.discrepancy.synth_request import SynthRequest
        from fsarm_sim.records.measured import write_dataset

        request = SynthRequest.from_options(options)
        request.check()
        request.output_plan().check()
        err = make_console(stderr=True)
        writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
        cols, side, hidden = request.synthesize(
            lambda step, done, total: progress(step, done + 1, total + 1)
        )
    written = writes.write(out, lambda p: write_dataset(p, cols, side), "the dataset (OUT)")
    if written is not None:
        typer.echo(f"wrote {written[0]} and {written[1]} (SYNTHETIC; hidden: {hidden or 'none'})")
    writes.finish()


def register(app: typer.Typer) -> None:
    app.command("diagnose")(diagnose_cmd)
    app.command("design-experiment")(design_cmd)
    app.command("synth")(synth_cmd)
