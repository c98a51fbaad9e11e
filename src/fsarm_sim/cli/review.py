"""Review outputs of the CLI: Rerun recordings and static figures.

* ``fsarm run SCENARIO --rrd FILE [--rrd-rate HZ] [--spawn] [--figures DIR]`` (options of ``run``,
  handled by :func:`review_outputs` after the run, so they cannot change its results);
* ``fsarm figures --out DIR``: every scenario's static figures in one command.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console

from fsarm_sim.choices import FigureFormat, Scenario
from fsarm_sim.cli import options as opt
from fsarm_sim.cli.console import make_console
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.outputs import OutputPlan, SafeWriter

if TYPE_CHECKING:
    from fsarm_sim.sim.simulation import RunResult


def run_output_plan(
    scenario: str,
    fmt: str,
    *,
    out: Path,
    json_file: Path | None,
    rrd: Path | None,
    spawn: bool,
    figures: Path | None,
) -> OutputPlan:
    """The files ``fsarm run`` will write, checked (paths, collisions) before the run."""
    from fsarm_sim.records.timeseries import FORMATS
    from fsarm_sim.sim import scenarios

    if fmt not in FORMATS:
        raise InvalidParameterError(f"--format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    name = scenarios.get(scenario).name
    plan = OutputPlan().folder(
        "--out",
        out,
        {f"{name}.{fmt}": "the time series", f"{name}.json": "the time series' sidecar"},
    )
    plan.file("--json", json_file)
    if rrd is not None:
        plan.file("--rrd", rrd)
    elif spawn:
        plan.file("--spawn's recording", out / f"{name}.rrd")
    if figures is not None:
        from fsarm_sim.review.figures import FIGURE_KINDS

        plan.folder(
            "--figures", figures, {f"{name}_{k}.png": f"the {k} figure" for k in FIGURE_KINDS}
        )
    return plan


def check_review_options(rrd_rate: float | None) -> None:
    """Fail before the run, not after it, on a bad ``--rrd-rate``."""
    if rrd_rate is not None and (not math.isfinite(rrd_rate) or rrd_rate <= 0.0):
        raise InvalidParameterError(
            f"--rrd-rate must be a finite number of Hz > 0, got {rrd_rate!r}"
        )


COMPARE_KEYS = ("series-hysteresis", "diameter-mm", "length-mm", "payload-kg", "backend")


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


def review_outputs(
    result: RunResult,
    *,
    rrd: Path | None,
    rrd_rate: float | None,
    spawn: bool,
    figures_dir: Path | None,
    out: Path,
    console: Console,
    writes: SafeWriter | None = None,
    compare: tuple[str, str, RunResult] | None = None,
) -> None:
    """Write the recording / figures a ``run`` asked for and report where they are (through
    ``writes``: a failed write goes to a rescue folder instead of being lost). ``compare``:
    (this run's name, the other's name, the other run) - both go into one recording."""
    w = writes if writes is not None else SafeWriter()
    if rrd is not None or spawn:
        from fsarm_sim.review.recording import DEFAULT_RATE_HZ, record_run, spawn_viewer

        rate = DEFAULT_RATE_HZ if rrd_rate is None else rrd_rate

        def write(p: Path) -> Path:
            if compare is None:
                return record_run(result, p, rate)
            from fsarm_sim.review.comparison import record_runs

            return record_runs([(compare[0], result), (compare[1], compare[2])], p, rate)

        path = w.write(
            rrd if rrd is not None else out / f"{result.scenario}.rrd",
            write,
            "the Rerun recording (--rrd)",
        )
        if path is not None:
            console.print(f"rerun recording: {path}")
            if spawn:
                console.print(spawn_viewer(path), markup=False)
    if figures_dir is not None:
        from fsarm_sim.review.figures import run_figures

        skipped: dict[str, str] = {}
        paths = w.write(
            figures_dir,
            lambda d: run_figures(result, d, skipped=skipped),
            "the figures (--figures)",
            folder=True,
        )
        if paths is not None:
            console.print(f"figures: {', '.join(str(p) for p in paths)}", markup=False)
        for kind, why in skipped.items():
            console.print(f"no {kind} figure: {why}", markup=False)
    if writes is None:
        w.finish()


def register(app: typer.Typer) -> None:
    @app.command("figures")
    def figures_cmd(
        out: Annotated[Path, typer.Option(help="folder for the figures")] = Path("figures"),
        scenario: Annotated[
            list[Scenario] | None,
            typer.Option(
                help="scenario to draw (repeatable; default: every registered one)",
                case_sensitive=False,
            ),
        ] = None,
        fmt: Annotated[
            list[FigureFormat] | None,
            typer.Option(
                "--format", help="figure format (repeatable) [default: png]", case_sensitive=False
            ),
        ] = None,
        dpi: Annotated[int, typer.Option(help="resolution of raster formats")] = 110,
        width: Annotated[float, typer.Option(help="figure width, inches")] = 6.4,
        height: Annotated[float, typer.Option(help="figure height, inches")] = 4.0,
        duration: Annotated[
            float | None, typer.Option(help="simulated time per scenario, s (default: its own)")
        ] = None,
        diameter_mm: opt.DiameterMm = 9.0,
        length_mm: opt.LengthMm = 450.0,
    ) -> None:
        """Run every scenario and write its figures: tracking (Fig. 14 style), torque vs twist
        (Fig. 6/7) and bending moment vs bend (Fig. 9), as <out>/<scenario>_<kind>.<format>."""
        from fsarm_sim.cli.progress import steps
        from fsarm_sim.engine.model import SimConfig
        from fsarm_sim.plant.shaft import load_catalogue
        from fsarm_sim.review.figures import FIGURE_KINDS, all_scenario_figures, check_output
        from fsarm_sim.sim import scenarios

        for v, name in ((width, "--width"), (height, "--height")):
            if not math.isfinite(v) or not 0.5 <= v <= 40.0:
                raise InvalidParameterError(f"{name} must be between 0.5 and 40 inches, got {v!r}")
        names = [str(s) for s in scenario] if scenario else list(scenarios.REGISTRY)
        for n in names:
            scenarios.get(n)  # unknown names fail before any run
        formats = [str(f) for f in fmt] if fmt else ["png"]
        check_output(formats, dpi)
        OutputPlan().folder(
            "--out",
            out,
            {
                f"{n}_{k}.{f}": f"the {k} figure of {n} ({f})"
                for n in dict.fromkeys(names)
                for k in FIGURE_KINDS
                for f in formats
            },
        ).check()
        cfg = SimConfig(shaft=load_catalogue().shaft(diameter_mm, length_mm))
        console = make_console()
        err = make_console(stderr=True)
        writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
        skipped: dict[str, str] = {}
        with steps("figures") as progress:
            written = writes.write(
                out,
                lambda d: all_scenario_figures(
                    d,
                    cfg,
                    scenarios=names,
                    duration_s=duration,
                    formats=formats,
                    dpi=dpi,
                    size_in=(width, height),
                    skipped=skipped,
                    progress=progress,
                ),
                "the figures (--out)",
                folder=True,
            )
        for name, paths in (written or {}).items():
            console.print(f"{name}: {', '.join(str(p) for p in paths)}", markup=False)
        for fig, why in skipped.items():
            console.print(f"no {fig} figure: {why}", markup=False)
        writes.finish()


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
