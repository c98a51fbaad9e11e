"""A run as ``fsarm run`` makes it, for Python users too: :class:`RunRequest` holds every option
of the command, checks them against each other before anything runs (:meth:`RunRequest.check`,
:func:`run_output_plan`), builds the configuration, runs, saves the time series and the summary,
names the run (:meth:`RunRequest.title`) and runs the comparison of ``--rrd-compare``::

    from fsarm_sim import RunRequest

    request = RunRequest("step-q3", payload_kg=5.0, out=Path("runs"), json_file=Path("s.json"))
    result = request.execute()  # checked, run, runs/step-q3.csv + sidecar + s.json written

The command only parses its options into a request and prints what the request returns.
Imports beyond the standard library happen inside the functions: the command registers without
loading the simulator.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fsarm_sim.choices import plain_options
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan, SafeWriter

if TYPE_CHECKING:
    from fsarm_sim.engine.model import Effects, SimConfig
    from fsarm_sim.sim.simulation import RunResult

COMPARE_KEYS = ("series-hysteresis", "diameter-mm", "length-mm", "payload-kg", "backend")
# the catalogue-shaft options of a run (field name -> flag), which some transmissions ignore
SHAFT_OPTIONS = {
    "diameter_mm": "--diameter-mm",
    "length_mm": "--length-mm",
    "shaft_file": "--shaft-file",
    "extrapolate": "--extrapolate",
    "series_hysteresis": "--[no-]series-hysteresis",
}


def parse_params(items: list[str]) -> tuple[tuple[str, float], ...]:
    """``NAME=VALUE`` strings -> ((name, value), ...); InvalidParameterError on a malformed one."""
    out = []
    for item in items:
        name, sep, value = item.partition("=")
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not sep or not name.strip() or not math.isfinite(v):
            raise InvalidParameterError(
                f"--tr-param must be NAME=VALUE with a finite number, got {item!r}"
            )
        out.append((name.strip(), v))
    return tuple(out)


def check_shaft_options(transmission: str, given: list[str]) -> None:
    """Refuse catalogue-shaft options that ``transmission`` would ignore (``given``: the options
    the user set, as typed, e.g. ``["--diameter-mm", "--series-hysteresis"]``).

    The flexible shaft takes all of them. A transmission routed over joint 2 (RTCA,
    tendon-sheath) keeps the catalogue shaft only for the bending moment on joint 2, so D, L and
    the coefficient file count there, but the shaft's series hysteresis does not (the law has
    its own: ``--tr-param``). The others (QA-Joint, magnetic spring) read no shaft at all."""
    from fsarm_sim.plant import transmissions

    tr = transmissions.get(transmission)  # an unknown name is a named error here
    if tr.takes_shaft or not given:
        return
    bending = ("diameter-mm", "length-mm", "shaft-file", "extrapolate")
    ignored = [
        g for g in given if not (tr.routed_over_joint2 and g.split()[-1].lstrip("-") in bending)
    ]
    if not ignored:
        return
    why = (
        "it keeps the catalogue shaft only for the bending moment on joint 2 (D, L and the "
        "coefficient file count there)"
        if tr.routed_over_joint2
        else "it reads no catalogue shaft"
    )
    raise InvalidParameterError(
        f"{', '.join(ignored)} would change nothing with transmission {transmission!r}: {why}; "
        f"its own parameters are set with --tr-param NAME=VALUE (`fsarm transmissions "
        f"{transmission}` lists them)"
    )


def check_review_options(rrd_rate: float | None) -> None:
    """Fail before the run, not after it, on a bad ``--rrd-rate``."""
    if rrd_rate is not None and (not math.isfinite(rrd_rate) or rrd_rate <= 0.0):
        raise InvalidParameterError(
            f"--rrd-rate must be a finite number of Hz > 0, got {rrd_rate!r}"
        )


def parse_compare(items: list[str], rrd: Path | None) -> dict[str, str]:
    """``--rrd-compare KEY=VALUE`` (repeatable): what the second configuration changes. Checked
    before any run: known keys, valid values, and a ``--rrd`` to write the comparison to."""
    changes: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or key not in COMPARE_KEYS:
            raise InvalidParameterError(
                f"--rrd-compare takes KEY=VALUE with KEY among {', '.join(COMPARE_KEYS)}, "
                f"got {item!r}"
            )
        if key == "series-hysteresis" and value not in ("on", "off"):
            raise InvalidParameterError(f"--rrd-compare series-hysteresis=on|off, got {value!r}")
        if key == "backend" and value not in ("python", "native"):
            raise InvalidParameterError(f"--rrd-compare backend=python|native, got {value!r}")
        if key in ("diameter-mm", "length-mm", "payload-kg"):
            try:
                v = float(value)
            except ValueError:
                v = math.nan
            if not math.isfinite(v) or v < 0.0 or (v == 0.0 and key != "payload-kg"):
                raise InvalidParameterError(
                    f"--rrd-compare {key} must be a finite number > 0 (payload >= 0), got {value!r}"
                )
        if key in changes:
            raise InvalidParameterError(f"--rrd-compare gives {key} twice")
        changes[key] = value
    if changes and rrd is None:
        raise InvalidParameterError("--rrd-compare needs --rrd FILE to write the comparison to")
    return changes


def compare_tags(changes: dict[str, str], base: dict[str, str]) -> tuple[str, str]:
    """Names of the two configurations: the changed keys' values, as given and as changed."""
    return (
        "+".join(f"{k}={base[k]}" for k in changes),
        "+".join(f"{k}={v}" for k, v in changes.items()),
    )


def check_run_uncertainty(
    n: int, transmission: str, shaft_file: Path | None, controller: str = "nominal"
) -> None:
    """Refuse bad --uncertainty settings before the run starts."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies.uncertainty import UncertaintyError, check_controller, check_samples

    check_samples(n)
    check_controller(controller)
    if transmission != "flexible-shaft":
        raise UncertaintyError(
            f"--uncertainty samples the shaft coefficient file's ranges, so it needs "
            f"--transmission flexible-shaft, got {transmission!r}"
        )
    cat = load_catalogue(shaft_file)
    if not cat.uncertainty:
        raise UncertaintyError(
            f"--uncertainty: {cat.source} declares no [uncertainty] ranges; add "
            "[uncertainty.<group>] relative = [low, high] and reason (see `fsarm shafts --export`)"
        )


def read_hysteresis_model(path: Path | None) -> tuple[float, ...]:
    """The twelve numbers of a hysteresis-model file, or () (the identified default)."""
    if path is None:
        return ()
    from fsarm_sim.engine.hysteresis_model import load_file

    return load_file(path)


@dataclass(frozen=True)
class RunRequest:
    """Every option of ``fsarm run`` (the same names, plain strings for choices). ``given``:
    which of :data:`SHAFT_OPTIONS` the user set explicitly (a transmission that ignores one
    refuses it rather than silently not using it)."""

    scenario: str
    diameter_mm: float = 9.0
    length_mm: float = 450.0
    payload_kg: float | None = None
    duration: float | None = None
    out: Path = Path("runs")
    json_file: Path | None = None
    fmt: str = "csv"
    shaft_file: Path | None = None
    extrapolate: bool = False
    series_hysteresis: bool | None = None
    integrator: str | None = None
    timestep: float | None = None
    ctrl_dt: float = 0.001
    log_every: int = 1
    backend: str = "native"
    rrd: Path | None = None
    rrd_rate: float | None = None
    spawn: bool = False
    figures: Path | None = None
    rrd_compare: tuple[str, ...] = ()
    transmission: str = "flexible-shaft"
    tr_param: tuple[str, ...] = ()
    controller: str = "default"
    hysteresis_model: Path | None = None
    uncertainty: int = 0
    uncertainty_controller: str = "nominal"
    effect: tuple[str, ...] = ()
    given: tuple[str, ...] = ()

    @classmethod
    def from_options(cls, options: Mapping[str, Any], given: tuple[str, ...] = ()) -> RunRequest:
        """A request from the command's option values (choices as their strings, None lists
        as empty); names that are not options are ignored."""
        return cls(**plain_options(options, (f.name for f in fields(cls))), given=given)

    def compare_changes(self) -> dict[str, str]:
        """What ``rrd_compare`` changes for the second run (:func:`parse_compare`)."""
        return parse_compare(list(self.rrd_compare), self.rrd)

    def check(self) -> None:
        """The options against each other, before the run (the outputs: :func:`run_output_plan`)."""
        check_review_options(self.rrd_rate)
        changes = self.compare_changes()
        flags = [flag for name, flag in SHAFT_OPTIONS.items() if name in self.given]
        compared = {"diameter-mm", "length-mm", "series-hysteresis"} & set(changes)
        check_shaft_options(
            self.transmission, flags + [f"--rrd-compare {k}" for k in sorted(compared)]
        )
        if self.uncertainty:
            check_run_uncertainty(
                self.uncertainty, self.transmission, self.shaft_file, self.uncertainty_controller
            )
        self.effects()

    def effects(self) -> Effects:
        """The registry laws switched on by ``effect`` (``NAME[=V1,...][,KEY=VALUE,...]``)."""
        from fsarm_sim.engine.model import Effects
        from fsarm_sim.plant.effects.registry import parse_laws

        return Effects(laws=parse_laws(list(self.effect)))

    def config(self) -> SimConfig:
        """The simulator's configuration (the shaft read from the coefficient file)."""
        from fsarm_sim.engine.model import Gains, SimConfig
        from fsarm_sim.plant.shaft import load_catalogue

        shaft = load_catalogue(self.shaft_file).shaft(
            self.diameter_mm,
            self.length_mm,
            extrapolate=self.extrapolate,
            series_hysteresis=self.series_hysteresis,
        )
        return SimConfig(
            shaft=shaft,
            gains=Gains(
                ctrl_dt_s=self.ctrl_dt,
                controller=self.controller,
                hysteresis_model=read_hysteresis_model(self.hysteresis_model),
            ),
            timestep_s=self.timestep,
            integrator=self.integrator,
            transmission=self.transmission,
            transmission_params=parse_params(list(self.tr_param)),
            effects=self.effects(),
        )

    def run(self) -> RunResult:
        """Run the scenario; a run cut by Ctrl-C keeps its finished part (``interrupted``)."""
        from fsarm_sim.lazy_commands import preload
        from fsarm_sim.sim.simulation import run_scenario

        cfg = self.config()
        if self.backend == "native":
            # the kernels, which the run would load anyway, now: this thread then imports
            # nothing of its own while the writer is imported beside the run
            from fsarm_sim.engine.callbacks import load_native

            load_native()
        preload("pyarrow.csv" if self.fmt == "csv" else "pyarrow.parquet")  # while the run steps
        return run_scenario(
            self.scenario,
            cfg,
            duration_s=self.duration,
            payload_kg=self.payload_kg,
            backend=self.backend,  # type: ignore[arg-type]
            log_every_ticks=self.log_every,
            keep_partial=True,
        )

    def save(self, result: RunResult, writes: SafeWriter) -> tuple[Path | None, Path | None]:
        """Write the time series into ``out`` and the summary to ``json_file`` (when given)
        through ``writes``; return where each went (None: not written)."""
        from fsarm_sim.records.timeseries import write_summary, write_timeseries

        path = writes.write(
            self.out,
            lambda d: write_timeseries(result, d, self.fmt),
            "the time series (--out)",
            folder=True,
        )

        def summary(p: Path) -> Path:
            write_summary(result, p)
            return p

        if self.json_file is None:
            return path, None
        return path, writes.write(self.json_file, summary, "the summary (--json)")

    def title(self, result: RunResult) -> str:
        """The run's name: scenario, shaft or transmission, controller, payload."""
        tr_model = result.config.transmission_model()
        shaft = f"D={self.diameter_mm:g} mm, L={self.length_mm:g} mm"
        if tr_model.takes_shaft:
            what = shaft
        else:
            bending = f" (bending on joint 2: {shaft} shaft)" if tr_model.routed_over_joint2 else ""
            what = f"transmission {self.transmission}{bending}"
        if self.controller != "default":
            what += f", controller {self.controller}"
        return f"{self.scenario}: {what}, payload={result.config.payload_kg:g} kg"

    def rating_warning(self, result: RunResult) -> str | None:
        """The warning for a peak transmission torque above the nominal rating, or None."""
        over = result.metrics["peak_shaft_torque_over_rating"]
        if not (isinstance(over, float) and over > 1.0):
            return None
        advice = (
            f"for D = {self.diameter_mm:g} mm): choose a thicker shaft"
            if result.config.transmission_model().takes_shaft
            else f"of {self.transmission})"
        )
        return (
            f"peak transmission torque is {over:.1f}x the nominal rating "
            f"({result.config.rating_nm():.2f} N·m {advice}"
        )

    def compare_run(self, result: RunResult) -> tuple[str, str, RunResult] | None:
        """The second run of ``rrd_compare`` (:func:`compare_run`), or None without one."""
        changes = self.compare_changes()
        if not changes:
            return None
        return compare_run(
            changes,
            result,
            shaft_file=self.shaft_file,
            extrapolate=self.extrapolate,
            series_hysteresis=self.series_hysteresis,
            backend=self.backend,
            log_every=self.log_every,
        )

    def execute(self, writes: SafeWriter | None = None) -> RunResult:
        """Check, run and save (time series, summary) as ``fsarm run`` does, printing nothing;
        failed writes go to a rescue folder (:class:`~fsarm_sim.outputs.SafeWriter`)."""
        self.check()
        run_output_plan(self).check()
        result = self.run()
        w = writes if writes is not None else SafeWriter()
        self.save(result, w)
        if writes is None:
            w.finish()
        return result


def run_output_plan(request: RunRequest) -> OutputPlan:
    """The files the request will write, with its input files (checked before the run: paths,
    collisions, an output on an input)."""
    from fsarm_sim.records.timeseries import FORMATS
    from fsarm_sim.sim import scenarios

    if request.fmt not in FORMATS:
        raise InvalidParameterError(
            f"--format must be one of {', '.join(FORMATS)}, got {request.fmt!r}"
        )
    name = scenarios.get(request.scenario).name
    plan = OutputPlan().folder(
        "--out",
        request.out,
        {f"{name}.{request.fmt}": "the time series", f"{name}.json": "the time series' sidecar"},
    )
    plan.file("--json", request.json_file)
    if request.rrd is not None:
        plan.file("--rrd", request.rrd)
    elif request.spawn:
        plan.file("--spawn's recording", request.out / f"{name}.rrd")
    if request.figures is not None:
        from fsarm_sim.review.figures import FIGURE_KINDS

        plan.folder(
            "--figures",
            request.figures,
            {f"{name}_{k}.png": f"the {k} figure" for k in FIGURE_KINDS},
        )
    plan.input("the coefficient file of --shaft-file", request.shaft_file)
    return plan.input("the hysteresis model of --hysteresis-model", request.hysteresis_model)


def compare_run(
    changes: dict[str, str],
    result: RunResult,
    *,
    shaft_file: Path | None,
    extrapolate: bool,
    series_hysteresis: bool | None,
    backend: str,
    log_every: int,
) -> tuple[str, str, RunResult]:
    """Run ``result``'s scenario again with ``changes`` (:func:`parse_compare`); return (this
    run's name, the other's name, the other run) for a comparison recording."""
    from dataclasses import replace

    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.sim.simulation import run_scenario

    cfg = result.config
    sh = cfg.shaft
    base = {
        "series-hysteresis": "on" if any(k > 0.0 for k in sh.slip_k) else "off",
        "diameter-mm": f"{sh.diameter_mm:g}",
        "length-mm": f"{sh.length_mm:g}",
        "payload-kg": f"{cfg.payload_kg:g}",
        "backend": backend,
    }
    same = [f"{k}={v}" for k, v in changes.items() if v == base[k]]
    if same:
        raise InvalidParameterError(
            f"--rrd-compare {', '.join(same)} changes nothing: this run already has it"
        )
    other_cfg = cfg
    if {"series-hysteresis", "diameter-mm", "length-mm"} & set(changes):
        hyst = {"on": True, "off": False}.get(changes.get("series-hysteresis", ""))
        shaft = load_catalogue(shaft_file).shaft(
            float(changes.get("diameter-mm", sh.diameter_mm)),
            float(changes.get("length-mm", sh.length_mm)),
            extrapolate=extrapolate,
            series_hysteresis=series_hysteresis if hyst is None else hyst,
        )
        other_cfg = replace(cfg, shaft=shaft)
    other = run_scenario(
        result.scenario,
        other_cfg,
        duration_s=result.duration_s,
        payload_kg=float(changes.get("payload-kg", cfg.payload_kg)),
        backend=changes.get("backend", backend),  # type: ignore[arg-type]
        log_every_ticks=log_every,
    )
    mine, theirs = compare_tags(changes, base)
    return mine, theirs, other
