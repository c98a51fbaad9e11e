"""A synthetic record as ``fsarm synth`` makes it, for Python users too: :class:`SynthRequest`
holds every option of the command, refuses bad or contradictory ones before any work
(:meth:`SynthRequest.check`, :meth:`SynthRequest.output_plan`), and synthesizes the record
(:meth:`SynthRequest.synthesize`; writing it: :func:`fsarm_sim.records.measured.write_dataset`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from fsarm_sim.choices import plain_options
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True)
class SynthRequest:
    """Every option of ``fsarm synth`` (the same names; choices as plain strings; None: the
    recording's default)."""

    out: Path
    setup: str = "series_bench"
    scenario: str = "fig14-sine"
    noise_rad: float = 2e-5
    effect: tuple[str, ...] = ()
    model: Path | None = None
    load: str | None = None
    inertia: float | None = None
    true_inertia: float | None = None
    stiffness_scale: float = 1.0
    diameter_mm: float = 9.0
    length_mm: float = 450.0
    noise: float | None = None
    duration: float | None = None
    rate: float | None = None
    trajectory: str | None = None
    amplitude: float | None = None
    bend_deg: float | None = None
    seed: int = 0
    input_file: Path | None = None

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> SynthRequest:
        """A request from the command's option values (names that are not options ignored)."""
        return cls(**plain_options(options, (f.name for f in fields(cls))))

    def check(self) -> None:
        """Numbers in range; on the arm, none of what only a bench reads (refused rather than
        silently ignored)."""
        for opt, v in (
            ("--inertia", self.inertia),
            ("--true-inertia", self.true_inertia),
            ("--stiffness-scale", self.stiffness_scale),
            ("--amplitude", self.amplitude),
        ):
            if v is not None and not (math.isfinite(v) and v > 0):
                raise InvalidParameterError(f"{opt} must be a finite number > 0, got {v!r}")
        for opt, v in (("--noise", self.noise), ("--noise-rad", self.noise_rad)):
            if v is not None and not (math.isfinite(v) and v >= 0):
                raise InvalidParameterError(f"{opt} must be a finite number >= 0, got {v!r}")
        if self.rate is not None and not (math.isfinite(self.rate) and self.rate > 0):
            raise InvalidParameterError(f"--rate must be a finite number > 0 Hz, got {self.rate!r}")
        if self.setup != "arm":
            return
        bench_only = (
            ("--load", self.load),
            ("--inertia", self.inertia),
            ("--true-inertia", self.true_inertia),
            ("--noise", self.noise),
            ("--trajectory", self.trajectory),
            ("--amplitude", self.amplitude),
            ("--bend-deg", self.bend_deg),
            ("--input-file", self.input_file),
        )
        given = [opt for opt, v in bench_only if v is not None]
        if given:
            raise InvalidParameterError(
                f"{', '.join(given)} set the benches' recordings; an arm record runs a "
                "scenario (--scenario, --duration, --rate, --noise-rad, --seed)"
            )

    def output_plan(self) -> OutputPlan:
        """The table and its sidecar, with the input files (checked before any work)."""
        from fsarm_sim.records.measured import output_files

        table_out, side_out = output_files(self.out)
        plan = OutputPlan().file("OUT", table_out).file("the sidecar of OUT", side_out)
        plan.input("the truth model of --model", self.model)
        return plan.input("the trajectory file of --input-file", self.input_file)

    def recording(self) -> Any:
        """The recording settings: an ``ArmRecording`` or a bench's ``synth.Recording`` (what
        is not given takes its defaults; with ``input_file`` the duration defaults to the
        file's, in whole sample periods)."""
        from fsarm_sim.discrepancy import synth
        from fsarm_sim.discrepancy.arm_synth import ArmRecording

        if self.setup == "arm":
            return ArmRecording(
                scenario=self.scenario,
                duration_s=self.duration,
                noise_rad=self.noise_rad,
                seed=self.seed,
                rate_hz=self.rate,
            )
        duration = self.duration
        if self.input_file is not None and duration is None:
            t_in, _ = synth.read_input_file(self.input_file, self.setup)
            # whole sample periods of the file's span (a rounded-up last sample would lie past
            # the file's end)
            r = self.rate if self.rate is not None else synth.Recording.rate_hz
            duration = math.floor(float(t_in[-1] - t_in[0]) * r + 1e-6) / r
        stated: dict[str, Any] = {
            "duration_s": duration,
            "rate_hz": self.rate,
            "noise": self.noise,
            "trajectory": self.trajectory,
            "bend_rad": None if self.bend_deg is None else math.radians(self.bend_deg),
            "input_file": None if self.input_file is None else str(self.input_file),
        }
        return synth.Recording(
            amplitude=self.amplitude,
            seed=self.seed,
            **{k: v for k, v in stated.items() if v is not None},
        )

    def synthesize(
        self, progress: Progress | None = None
    ) -> tuple[dict[str, Any], dict[str, Any], list[str]]:
        """(columns, sidecar, the hidden effects' labels) of the record."""
        from fsarm_sim.discrepancy import synth
        from fsarm_sim.records.measured import stated_shaft

        shaft = stated_shaft(self.diameter_mm, self.length_mm)
        rec = self.recording()
        inertia = synth.DEFAULT_LOAD_INERTIA_KGM2 if self.inertia is None else self.inertia
        load = self.load or "blocked"
        return synth.synthesize_setup(
            self.setup,
            list(self.effect),
            model_file=self.model,
            shaft=shaft,
            stiffness_scale=self.stiffness_scale,
            load_inertia_kgm2=(
                inertia if (self.setup == "series_bench" and load == "inertia") else None
            ),
            true_inertia_kgm2=self.true_inertia,
            recording=rec,
            progress=progress,
        )
