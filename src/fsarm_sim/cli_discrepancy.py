"""``fsarm diagnose`` and ``fsarm synth``: the discrepancy workflow on the command line.

Thin wrappers: argument parsing here, the work in :mod:`fsarm_sim.discrepancy` and
:mod:`fsarm_sim.synth`. The library is imported inside the commands so that ``fsarm`` stays quick
to start.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from fsarm_sim.console import make_console
from fsarm_sim.outputs import OutputPlan, SafeWriter


def register(app: typer.Typer) -> None:
    @app.command("diagnose")
    def diagnose_cmd(
        data: Annotated[
            Path, typer.Argument(help="dataset: NAME.csv / NAME.parquet (+ NAME.json)")
        ],
        json_file: Annotated[
            Path | None, typer.Option("--json", help="write the machine-readable result here")
        ] = None,
        report: Annotated[
            Path | None,
            typer.Option("--report", help="folder for result.json, model.json and plots"),
        ] = None,
        model_file: Annotated[
            Path | None, typer.Option("--model", help="write the final model (JSON) here")
        ] = None,
        max_effects: Annotated[int, typer.Option(help="most effects to add")] = 4,
    ) -> None:
        """Replay the nominal model on a record, name the missing effects, fit them.

        Bench records and arm records (measured, synthetic, or written by `fsarm run` as they
        are); columns the diagnosis does not read are listed, not refused."""
        from rich.table import Table

        from fsarm_sim.discrepancy import diagnose
        from fsarm_sim.discrepancy import report as rep
        from fsarm_sim.measured import dataset_files, load_dataset

        table, side = dataset_files(data)
        OutputPlan().input(f"the dataset {table}", table).input(
            f"the sidecar of the dataset {table}", side
        ).file("--json", json_file).file("--model", model_file).folder(
            "--report", report, rep.REPORT_FILES
        ).check()
        console = make_console()
        err = make_console(stderr=True)
        writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
        ds = load_dataset(data)
        if ds.setup == "arm":  # closed-loop replay of the run (fsarm_sim.discrepancy.arm)
            from fsarm_sim.discrepancy import arm_report

            arm_report.run_cli(
                ds,
                console,
                json_file=json_file,
                report=report,
                model_file=model_file,
                max_effects=min(max_effects, 3),
                writes=writes,
            )
            writes.finish()
            return
        diag = diagnose(ds, max_effects=max_effects)
        for st in diag.steps:
            t = Table(title=f"step {st.index}: {st.reason}", title_justify="left")
            for col in (
                "candidate",
                "k",
                "held-out NRMSE %",
                "ΔBIC teach",
                "ΔBIC held-out",
                "gain %",
                "earns place",
            ):
                t.add_column(col, justify="right" if col != "candidate" else "left")
            for sc in st.scores:
                t.add_row(
                    sc.label,
                    str(sc.k),
                    f"{100 * sc.nrmse_held:.3f}",
                    f"{sc.d_bic_teach:+.1f}",
                    f"{sc.d_bic_held:+.1f}",
                    f"{100 * sc.gain_held:.1f}",
                    "yes" if sc.earns_place else "no",
                )
            console.print(t)
            line = rep.confidence_line(st)
            if line:
                console.print(line, markup=False)
        console.print(f"named effects: {diag.named or 'none'}", markup=False)
        console.print(
            f"held-out NRMSE of {ds.output_column}: nominal {100 * diag.gap_before:.3f} % -> "
            f"final {100 * diag.gap_after:.3f} %",
            markup=False,
        )
        console.print(diag.verdict, markup=False)
        for line in ds.column_notes():
            console.print(line, markup=False)
        console.print(f"runtime {diag.runtime_s:.1f} s", markup=False)
        written: Path | None = None
        if model_file is not None:
            written = writes.write(
                model_file, lambda p: rep.write_model(diag, p), "the final model (--model)"
            )
            if written is not None:
                console.print(f"model: {written}", markup=False)
        if report is not None:
            files = writes.write(
                report, lambda d: rep.write_report(diag, d), "the report (--report)", folder=True
            )
            if files is not None:
                written = written or files["model"]
                where = files["result"].parent
                console.print(
                    f"report: {where} ({', '.join(p.name for p in files.values())})", markup=False
                )
        if json_file is not None:
            res = writes.write(
                json_file, lambda p: rep.write_json(diag, p, written), "the result (--json)"
            )
            if res is not None:
                console.print(f"result: {res}", markup=False)
        writes.finish()

    @app.command("synth")
    def synth_cmd(
        out: Annotated[
            Path, typer.Argument(help="output NAME(.csv|.parquet); NAME.json beside it")
        ],
        setup: Annotated[
            str, typer.Option(help="series_bench, parallel_bench or arm")
        ] = "series_bench",
        scenario: Annotated[
            str, typer.Option(help="arm: the scenario run (see `fsarm scenarios`)")
        ] = "fig14-sine",
        noise_rad: Annotated[
            float, typer.Option(help="arm: angle noise std, rad (plus 17-bit quantisation)")
        ] = 2e-5,
        effect: Annotated[
            list[str] | None,
            typer.Option(
                "--effect",
                help="hidden effect NAME[:VARIANT]=VALUES (repeatable), e.g. "
                "coulomb_friction:shaft=0.2, backlash=0.03,0.0, delay=0.01, "
                "hysteresis:maxwell_slip=12,0.008,6,0.025",
            ),
        ] = None,
        model: Annotated[
            Path | None, typer.Option("--model", help="truth model file (instead of --effect)")
        ] = None,
        load: Annotated[str, typer.Option(help="series bench: blocked or inertia")] = "blocked",
        inertia: Annotated[float, typer.Option(help="stated load inertia, kg*m^2")] = 0.01,
        true_inertia: Annotated[
            float | None, typer.Option(help="acting load inertia (default: the stated one)")
        ] = None,
        stiffness_scale: Annotated[
            float, typer.Option(help="true stiffness / catalogue stiffness")
        ] = 1.0,
        diameter_mm: Annotated[float, typer.Option("--diameter", help="shaft D, mm")] = 9.0,
        length_mm: Annotated[float, typer.Option("--length", help="shaft L, mm")] = 450.0,
        noise: Annotated[float, typer.Option(help="torque noise std / torque range")] = 0.003,
        duration: Annotated[
            float | None, typer.Option(help="s (default: 30; arm: the scenario's)")
        ] = None,
        rate: Annotated[float, typer.Option(help="sample rate, Hz")] = 1000.0,
        trajectory: Annotated[
            str, typer.Option(help="chirp, multisine, triangle, random, steps, biased_sine")
        ] = "chirp",
        amplitude: Annotated[float | None, typer.Option(help="input amplitude, rad")] = None,
        bend_deg: Annotated[float, typer.Option(help="series bench: held bend angle, deg")] = 0.0,
        seed: Annotated[int, typer.Option(help="random seed")] = 0,
    ) -> None:
        """Write a SYNTHETIC measured-format dataset with chosen hidden effects and noise."""
        from fsarm_sim import synth
        from fsarm_sim.discrepancy.benchmodel import load_model
        from fsarm_sim.errors import InvalidParameterError
        from fsarm_sim.measured import output_files, write_dataset
        from fsarm_sim.shaft import load_catalogue

        for opt, v in (
            ("--inertia", inertia),
            ("--true-inertia", true_inertia),
            ("--stiffness-scale", stiffness_scale),
            ("--amplitude", amplitude),
        ):
            if v is not None and not (math.isfinite(v) and v > 0):
                raise InvalidParameterError(f"{opt} must be a finite number > 0, got {v!r}")
        for opt, v in (("--noise", noise), ("--noise-rad", noise_rad)):
            if not (math.isfinite(v) and v >= 0):
                raise InvalidParameterError(f"{opt} must be a finite number >= 0, got {v!r}")
        table_out, side_out = output_files(out)
        OutputPlan().file("OUT", table_out).file("the sidecar of OUT", side_out).input(
            "the truth model of --model", model
        ).check()
        err = make_console(stderr=True)
        writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
        if setup == "arm":  # the arm run by the simulator (fsarm_sim.discrepancy.arm)
            from fsarm_sim.discrepancy import arm_modelfile, arm_synth

            if model is not None:
                arm_truth, _ = arm_modelfile.load_arm_model(model)
            else:
                arm_truth = arm_synth.truth_model(effect or [], stiffness_scale=stiffness_scale)
            arm_rec = arm_synth.ArmRecording(
                scenario=scenario, duration_s=duration, noise_rad=noise_rad, seed=seed
            )
            # the stated eq. 8 shaft; series hysteresis is an effect the truth lists
            arm_shaft = load_catalogue().shaft(diameter_mm, length_mm, series_hysteresis=False)
            arm_cols, arm_side = arm_synth.synthesize_arm(arm_truth, arm_rec, arm_shaft)
            arm_written = writes.write(
                out, lambda p: write_dataset(p, arm_cols, arm_side), "the dataset (OUT)"
            )
            if arm_written is not None:
                typer.echo(
                    f"wrote {arm_written[0]} and {arm_written[1]} "
                    f"(SYNTHETIC; hidden: {arm_truth.labels or 'none'})"
                )
            writes.finish()
            return
        if setup not in ("series_bench", "parallel_bench"):
            raise InvalidParameterError(
                f"--setup must be series_bench or parallel_bench, got {setup!r}"
            )
        if load not in ("blocked", "inertia"):
            raise InvalidParameterError(f"--load must be blocked or inertia, got {load!r}")
        shaft = load_catalogue().shaft(diameter_mm, length_mm, series_hysteresis=False)
        rec = synth.Recording(
            duration_s=30.0 if duration is None else duration,
            rate_hz=rate,
            noise=noise,
            trajectory=trajectory,
            amplitude=amplitude,
            bend_rad=math.radians(bend_deg),
            seed=seed,
        )
        if model is not None:
            truth = load_model(model)
        else:
            stated = inertia if (setup == "series_bench" and load == "inertia") else None
            truth = synth.truth_model(
                setup,
                shaft=shaft,
                load_inertia_kgm2=stated,
                stiffness_scale=stiffness_scale,
                true_inertia_kgm2=true_inertia,
            )
            amp = amplitude if amplitude is not None else synth.default_amplitude(truth, shaft)
            for text in effect or []:
                truth.effects.append(synth.parse_effect(text, setup, amp))
        cols, side = synth.synthesize(truth, rec, shaft)
        written = writes.write(out, lambda p: write_dataset(p, cols, side), "the dataset (OUT)")
        if written is not None:
            typer.echo(
                f"wrote {written[0]} and {written[1]} "
                f"(SYNTHETIC; hidden: {[e.label for e in truth.effects] or 'none'})"
            )
        writes.finish()
