"""Speed benchmark (issue 4): raw MuJoCo vs the Python and native callback paths, real-time
factor, and batch throughput over cores. ``fsarm bench-speed`` (:mod:`fsarm_sim.cli.speed`)
and ``scripts/bench_step.py`` both call :func:`measure_speed` and print :func:`format_report`.

Protocol (wall-clock, ``time.perf_counter``; every figure is a median over repetitions because
the machine may be shared):

* per step - ONE compiled model of the full plant (series shaft with Maxwell-slip hysteresis,
  bending with conduit hysteresis, Fig. 13 joint-3 loop), ``fig14-sine`` reference. Each
  repetition restores the same initial state (``mjSTATE_INTEGRATION``, controller memory included)
  and times one ``mj_step(nstep=block)`` call per path (after 50 untimed warm-up steps from the
  same state), the three paths interleaved in rotating
  order so that load changes hit them alike: *raw* (``mjcb_*`` = None: MuJoCo alone, same model),
  *python* (reference callbacks), *native* (Numba C callbacks). Ratios are medians of the
  per-repetition ratios. Raw MuJoCo without the shaft and controller lets the arm fall; the block is
  short (0.2 s) so it does not reach a joint limit (``raw_nefc`` reports the constraint count at the
  end of the block: 0 means no limit was active).
  A fourth path, *native lean*, steps the lean twin of the same model (no visual geoms or
  sensors: :mod:`fsarm_sim.engine.lean`, what ``Simulation`` steps by default) from the same state;
  its ratio is taken against raw MuJoCo on the FULL model (the shipped scene).
  The native paths stop MuJoCo's stage timers (``mjcb_time`` returns 0, see
  :mod:`fsarm_sim.engine.native`); *raw* keeps them, as anyone stepping the shipped scene does, and
  a fifth path, *raw untimed*, steps the full model without callbacks and with the timers stopped,
  so the report shows what the timers cost and what the callbacks cost on a timer-free step.
* real-time factor - ``Simulation.run`` of 10 s ``fig14-sine`` on the native path, with the
  default full logging (one row per control tick, recorded by the control kernel) and without
  logging (``log_every_ticks=0``): simulated time / stepping wall time.
* whole process - ``fsarm run fig14-sine --duration 10 --out TMP`` as a subprocess (wall time
  from start to exit), and the same steps timed inside one fresh interpreter: imports of the CLI
  and of what ``fsarm run`` imports, loading the native kernels, building and stepping the run,
  writing the output (the rest of the process's wall time: interpreter start and exit, parsing
  the command line, printing).
* sweep - ``fsarm_sim.studies.sweep.run_sweep`` of 12 tracking points of 10 s (four diameters x
  three lengths) into a new store, with 1 and 2 workers, by the default executor (``auto``:
  threads for these points, :func:`fsarm_sim.studies.sweep.pick_executor`) and by process workers
  (``local``: forked where that is safe), three repetitions: throughput per core as a real-time
  factor, against the single-run one (one worker runs the points inline either way).
* batch - differently configured runs (every catalogue shaft D/L, series hysteresis on), each in
  its own thread through ``mujoco.rollout`` (:mod:`fsarm_sim.sim.batch`), with 1..N workers.
"""

from __future__ import annotations

import json
import math
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError, real_number, whole_number
from fsarm_sim.executors import check_workers
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim import batch, scenarios
from fsarm_sim.sim.simulation import Simulation

SCENARIO = "fig14-sine"
# caps of the sizes that scale the benchmark's work (its defaults: 15 reps, 200 steps, 10 s runs)
MAX_REPS = 1000
MAX_BLOCK_STEPS = 100_000
MAX_RUN_S = 3600.0
MAX_BATCH_RUNS = 10_000
WARMUP_STEPS = 50  # untimed steps of the same path before each timed block
GOAL_NATIVE_OVER_RAW = 1.3
GOAL_LEAN_OVER_RAW = 1.0  # the default stepping (lean twin + callbacks) vs the shipped scene raw
GOAL_REALTIME_FACTOR = 400.0  # default run: native, full logging
GOAL_PROCESS_S = 0.5  # whole `fsarm run fig14-sine --duration 10`
GOAL_SWEEP_PER_CORE = 0.8  # sweep throughput per core / single-run real-time factor
GOAL_SCALING_2_CORES = 1.8


@dataclass(frozen=True)
class SpeedReport:
    reps: int
    block_steps: int
    raw_us: float  # median wall time per mj_step
    python_us: float
    native_us: float
    raw_us_best: float  # fastest repetition (least disturbed by other work on the machine)
    python_us_best: float
    native_us_best: float
    native_over_raw: float  # median of per-repetition ratios
    python_over_raw: float
    raw_nefc: int  # constraints active at the end of the raw block (0: no joint limit hit)
    timestep_s: float
    rtf_duration_s: float
    rtf_native: float  # simulated s per wall s, median over rtf repetitions
    rtf_native_best: float
    batch_runs: int
    batch_duration_s: float
    batch_steps_per_s: dict[int, float]  # workers -> median throughput (steps of all runs / s)
    batch_scaling: dict[int, float]  # workers -> median of per-repetition throughput / 1 worker
    batch_steps_per_s_best: dict[int, float]  # workers -> best repetition
    cores: int
    compile_s: float  # import of fsarm_sim.engine.native: compile, or load from cache
    compile_cache_hits: int  # == compile_callbacks: all the callbacks came from the cache
    machine_note: str
    lean_us: float = float("nan")  # native callbacks on the lean twin, median per step
    lean_us_best: float = float("nan")
    lean_over_raw: float = float("nan")  # median of per-repetition lean / raw (full model)
    raw_untimed_us: float = float("nan")  # raw, MuJoCo's stage timers stopped, median per step
    raw_untimed_us_best: float = float("nan")
    lean_over_raw_untimed: float = float("nan")  # median of per-repetition lean / raw untimed
    rtf_logged: float = float("nan")  # real-time factor with full logging (the default run)
    rtf_logged_best: float = float("nan")
    process_s: float = float("nan")  # whole `fsarm run` process, median
    process_phases: dict[str, float] = field(default_factory=dict)  # phase -> median s
    kernel_source: str = ""  # where a fresh process took the native callbacks from
    sweep_points: int = 0
    sweep_duration_s: float = 0.0
    sweep_rtf_per_core: dict[int, float] = field(default_factory=dict)  # workers -> median
    sweep_scaling: dict[int, float] = field(default_factory=dict)  # workers -> vs 1 worker
    # the default executor (sweep.pick_executor, "auto": threads for these points, inline at 1)
    sweep_default_rtf_per_core: dict[int, float] = field(default_factory=dict)
    sweep_default_scaling: dict[int, float] = field(default_factory=dict)
    sweep_cpu_s: dict[int, float] = field(default_factory=dict)  # workers -> median CPU s
    sweep_default_cpu_s: dict[int, float] = field(default_factory=dict)
    sweep_start_method: str = ""  # how the process workers started: fork or spawn
    compile_callbacks: int = 4  # compiled callbacks (passive, act_dyn, control, stopped clock)


def _full_config() -> SimConfig:
    """Full plant: series shaft + Maxwell slip, bending + conduit hysteresis, joint-3 loop."""
    return SimConfig(shaft=load_catalogue().shaft(series_hysteresis=True))


def _table(duration_s: float, ctrl_dt_s: float) -> Any:
    n = round(duration_s / ctrl_dt_s) + 1
    return scenarios.get(SCENARIO).reference(np.arange(n, dtype=np.float64) * ctrl_dt_s)


def _time_block(m: mujoco.MjModel, d: mujoco.MjData, s0: Any, n: int) -> float:
    # warm caches and branch predictors for this path (the previous block may have run Python)
    mujoco.mj_setState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    mujoco.mj_step(m, d, nstep=WARMUP_STEPS)
    mujoco.mj_setState(m, d, s0, mujoco.mjtState.mjSTATE_INTEGRATION)
    start = time.perf_counter()
    mujoco.mj_step(m, d, nstep=n)
    return (time.perf_counter() - start) / n


def _per_step(reps: int, block_steps: int) -> tuple[dict[str, list[float]], int, float]:
    INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
    cfg = _full_config()
    table = _table(block_steps * 0.001 + 1.0, cfg.gains.ctrl_dt_s)
    sim = Simulation(cfg, table, "native", lean=False)
    m, d = sim.model, sim.data
    twin = Simulation(cfg, table, "native")  # the lean twin: same state layout (checked)
    s0 = np.empty(mujoco.mj_stateSize(m, INTEGRATION))
    mujoco.mj_getState(m, d, s0, INTEGRATION)
    if mujoco.mj_stateSize(twin.model, INTEGRATION) != s0.size:
        raise InvalidParameterError("the lean twin's state differs in size from the full model's")
    order = ["raw", "python", "native", "lean", "raw_untimed"]
    times: dict[str, list[float]] = {p: [] for p in order}
    native = callbacks.load_native()
    nefc = 0
    for rep in range(reps + 1):  # repetition 0 warms caches up and is dropped
        for path in order[rep % len(order) :] + order[: rep % len(order)]:
            if path == "raw":
                with callbacks.suspended():
                    dt = _time_block(m, d, s0, block_steps)
                    nefc = int(d.nefc)
            elif path == "raw_untimed":
                with callbacks.suspended():
                    if native is not None:  # (else the row repeats raw: the timers run)
                        mujoco.set_mjcb_time(native.TIME)
                    try:
                        dt = _time_block(m, d, s0, block_steps)
                    finally:
                        mujoco.set_mjcb_time(None)
            elif path == "lean":
                with callbacks.active("native"):
                    dt = _time_block(twin.model, twin.data, s0, block_steps)
            else:
                with callbacks.active(path):
                    dt = _time_block(m, d, s0, block_steps)
            if rep > 0:
                times[path].append(dt)
    return times, nefc, float(m.opt.timestep)


def _realtime(reps: int, duration_s: float, log_every_ticks: int = 0) -> list[float]:
    cfg = _full_config()
    table = _table(duration_s, cfg.gains.ctrl_dt_s)
    walls = []
    for _ in range(reps):
        sim = Simulation(cfg, table, "native")
        _, wall = sim.run(duration_s, log_every_ticks=log_every_ticks)
        walls.append(wall)
    return walls


# the phases of `fsarm run fig14-sine`, timed inside one fresh interpreter
_PHASES = """
import json, sys, tempfile, time
from pathlib import Path
t = [time.perf_counter()]
import fsarm_sim.cli  # the command and what `fsarm run` imports
import fsarm_sim.engine.callbacks, fsarm_sim.records.timeseries, fsarm_sim.sim.simulation
t.append(time.perf_counter())
from fsarm_sim.engine import callbacks  # loading the compiled kernels
source = callbacks.native_source()
t.append(time.perf_counter())
from fsarm_sim.sim.simulation import run_scenario
r = run_scenario("fig14-sine", duration_s=float(sys.argv[1]))
t.append(time.perf_counter())
from fsarm_sim.records.timeseries import write_timeseries
with tempfile.TemporaryDirectory() as tmp:
    write_timeseries(r, Path(tmp))
t.append(time.perf_counter())
names = ["imports", "kernel load", "build + step", "output"]
out = {n: t[i + 1] - t[i] for i, n in enumerate(names)}
out["stepping (of build + step)"] = float(r.metrics["wall_time_s"])
print(json.dumps({"phases": out, "source": source}))
"""


def _process(reps: int, duration_s: float) -> tuple[list[float], dict[str, list[float]], str]:
    """Whole `fsarm run` processes (wall from spawn to exit) and the phases of fresh runs."""
    fsarm = Path(sys.executable).with_name("fsarm")
    cmd = [str(fsarm)] if fsarm.exists() else [sys.executable, "-m", "fsarm_sim.cli"]
    walls: list[float] = []
    phases: dict[str, list[float]] = {}
    source = ""
    with tempfile.TemporaryDirectory(prefix="fsarm-bench-") as tmp:
        for _ in range(reps):
            start = time.perf_counter()
            subprocess.run(
                [*cmd, "run", SCENARIO, "--duration", f"{duration_s:g}", "--out", tmp],
                check=True,
                capture_output=True,
            )
            walls.append(time.perf_counter() - start)
            got = subprocess.run(
                [sys.executable, "-c", _PHASES, f"{duration_s:g}"],
                check=True,
                capture_output=True,
                text=True,
            )
            res = json.loads(got.stdout.strip().splitlines()[-1])
            source = str(res["source"])
            for k, v in res["phases"].items():
                phases.setdefault(k, []).append(float(v))
    return walls, phases, source


def _sweep(
    reps: int, duration_s: float, max_workers: int, executor: str = "local"
) -> tuple[int, dict[int, list[float]], dict[int, list[float]]]:
    """Real-time factor per core of a 12-point tracking sweep, per number of workers, and the
    CPU seconds each sweep took (this process and its workers: what the workers cost beyond
    the points, whatever else the machine runs)."""
    import os

    from fsarm_sim.studies import sweep

    def cpu() -> float:
        t = os.times()
        return t.user + t.system + t.children_user + t.children_system

    spec = sweep.build_spec(
        grid=["diameter_mm=6,8,10,12", "length_mm=335,435,535"],
        fixed=["scenario=fig14-sine", f"duration_s={duration_s:g}"],
        outputs=["tracking"],
        name="bench",
    )
    n_points = len(sweep.points(spec))
    out: dict[int, list[float]] = {}
    cpus: dict[int, list[float]] = {}
    for _ in range(reps):
        for w in range(1, max_workers + 1):
            with tempfile.TemporaryDirectory(prefix="fsarm-bench-") as tmp:
                c0 = cpu()
                rep = sweep.run_sweep(spec, Path(tmp) / "s.sqlite", executor=executor, workers=w)
                cpus.setdefault(w, []).append(cpu() - c0)  # (the pool's workers were joined)
            if rep.failed:
                raise InvalidParameterError(f"benchmark sweep points failed: {rep.errors[:2]}")
            out.setdefault(w, []).append(n_points * duration_s / rep.wall_s / w)
    return n_points, out, cpus


def _batch(
    reps: int, n_runs: int, duration_s: float, max_workers: int
) -> tuple[dict[int, float], dict[int, float], dict[int, float]]:
    INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
    cat = load_catalogue()
    base = _full_config()
    table = _table(duration_s, base.gains.ctrl_dt_s)
    shafts = [
        cat.shaft(s.diameter_mm, s.length_mm, series_hysteresis=True)
        for s in cat.shafts[: max(n_runs, 1)]
    ]
    sims = [
        Simulation(base.with_(shaft=shafts[i % len(shafts)]), table, "native")
        for i in range(n_runs)
    ]
    starts = []
    for s in sims:
        s0 = np.empty(mujoco.mj_stateSize(s.model, INTEGRATION))
        mujoco.mj_getState(s.model, s.data, s0, INTEGRATION)
        starts.append(s0)
    n_steps = round(duration_s / sims[0].model.opt.timestep)
    workers = list(range(1, max_workers + 1))
    thr: dict[int, list[float]] = {w: [] for w in workers}
    scale: dict[int, list[float]] = {w: [] for w in workers}
    for rep in range(reps + 1):
        this: dict[int, float] = {}
        for w in workers if rep % 2 == 0 else workers[::-1]:
            for s, s0 in zip(sims, starts, strict=True):
                mujoco.mj_setState(s.model, s.data, s0, INTEGRATION)
            this[w] = batch.run_batch(sims, n_steps, workers=w).steps_per_s
        if rep > 0:
            for w in workers:
                thr[w].append(this[w])
                scale[w].append(this[w] / this[1])
    return (
        {w: statistics.median(v) for w, v in thr.items()},
        {w: statistics.median(v) for w, v in scale.items()},
        {w: max(v) for w, v in thr.items()},
    )


def _per_step_fields(times: dict[str, list[float]]) -> dict[str, float]:
    """The report's per-step times (median and best, us) and their ratios to raw MuJoCo's."""

    def ratio(path: str, base: str = "raw") -> float:
        return statistics.median(n / r for n, r in zip(times[path], times[base], strict=True))

    out: dict[str, float] = {}
    for path in ("raw", "python", "native", "lean", "raw_untimed"):
        out[f"{path}_us"] = statistics.median(times[path]) * 1e6
        out[f"{path}_us_best"] = min(times[path]) * 1e6
    out |= {
        "native_over_raw": ratio("native"),
        "python_over_raw": ratio("python"),
        "lean_over_raw": ratio("lean"),
        "lean_over_raw_untimed": ratio("lean", "raw_untimed"),
    }
    return out


def _batch_size(max_workers: int | None, batch_runs: int | None) -> tuple[int, int, int]:
    """(cores, workers, runs) of the batch part: all cores and 4 runs a worker by default."""
    cores = batch.available_cores()
    n_workers = cores if max_workers is None else max_workers
    check_workers(n_workers, "max_workers (--max-workers)")
    n_runs = 4 * n_workers if batch_runs is None else batch_runs
    whole_number(n_runs, "batch_runs", 1, MAX_BATCH_RUNS)
    return cores, n_workers, n_runs


def measure_speed(
    reps: int = 15,
    block_steps: int = 200,
    rtf_reps: int = 5,
    rtf_duration_s: float = 10.0,
    batch_reps: int = 7,
    batch_runs: int | None = None,
    batch_duration_s: float = 2.0,
    max_workers: int | None = None,
    process_reps: int = 3,
    sweep_reps: int = 3,
) -> SpeedReport:
    """Run the whole benchmark (about a minute on 2 cores) and return its medians."""
    for name, v, low in (
        ("reps (--reps)", reps, 1),
        ("rtf_reps", rtf_reps, 1),
        ("batch_reps", batch_reps, 1),
        ("process_reps", process_reps, 1),
        ("sweep_reps", sweep_reps, 0),
    ):
        whole_number(v, name, low, MAX_REPS)
    whole_number(block_steps, "block_steps", 1, MAX_BLOCK_STEPS)
    for name, d in (("rtf_duration_s", rtf_duration_s), ("batch_duration_s", batch_duration_s)):
        if not 0.0 < real_number(d, name) <= MAX_RUN_S:
            raise InvalidParameterError(f"{name} must be > 0 and <= {MAX_RUN_S:g} s, got {d!r}")
    cores, n_workers, n_runs = _batch_size(max_workers, batch_runs)
    from fsarm_sim.engine import native

    times, nefc, timestep = _per_step(reps, block_steps)
    walls = _realtime(rtf_reps, rtf_duration_s)
    walls_logged = _realtime(rtf_reps, rtf_duration_s, log_every_ticks=1)
    proc, phases, source = _process(process_reps, rtf_duration_s)
    from fsarm_sim.executors import start_method

    pool_start = start_method()
    sweep_n, sweep, sweep_cpu = (
        _sweep(sweep_reps, rtf_duration_s, min(n_workers, 2)) if sweep_reps > 0 else (0, {}, {})
    )
    _, sweep_t, sweep_t_cpu = (
        _sweep(sweep_reps, rtf_duration_s, min(n_workers, 2), "auto")
        if sweep_reps > 0
        else (0, {}, {})
    )
    thr, scale, thr_best = _batch(batch_reps, n_runs, batch_duration_s, n_workers)
    return SpeedReport(
        reps=reps,
        block_steps=block_steps,
        **_per_step_fields(times),
        raw_nefc=nefc,
        timestep_s=timestep,
        rtf_duration_s=rtf_duration_s,
        rtf_native=rtf_duration_s / statistics.median(walls),
        rtf_native_best=rtf_duration_s / min(walls),
        batch_runs=n_runs,
        batch_duration_s=batch_duration_s,
        batch_steps_per_s=thr,
        batch_scaling=scale,
        batch_steps_per_s_best=thr_best,
        cores=cores,
        compile_s=native.COMPILE_INFO.seconds,
        compile_cache_hits=native.COMPILE_INFO.cache_hits,
        compile_callbacks=len(native.CFUNCS),
        machine_note=_load_note(cores),
        rtf_logged=rtf_duration_s / statistics.median(walls_logged),
        rtf_logged_best=rtf_duration_s / min(walls_logged),
        process_s=statistics.median(proc),
        process_phases={k: statistics.median(v) for k, v in phases.items()},
        kernel_source=source,
        sweep_points=sweep_n,
        sweep_duration_s=rtf_duration_s,
        sweep_rtf_per_core=_medians(sweep),
        sweep_scaling=_scaling(sweep),
        sweep_default_rtf_per_core=_medians(sweep_t),
        sweep_default_scaling=_scaling(sweep_t),
        sweep_cpu_s=_medians(sweep_cpu),
        sweep_default_cpu_s=_medians(sweep_t_cpu),
        sweep_start_method=pool_start,
    )


def _medians(by_workers: dict[int, list[float]]) -> dict[int, float]:
    return {w: statistics.median(v) for w, v in by_workers.items()}


def _scaling(rtf_per_core: dict[int, list[float]]) -> dict[int, float]:
    """Per number of workers: the median over repetitions of its throughput against one
    worker's in the same repetition (side by side)."""
    if not rtf_per_core:
        return {}  # no sweep measured (--quick)
    one = rtf_per_core[1]
    return {
        w: statistics.median(a * w / b for a, b in zip(v, one, strict=True))
        for w, v in rtf_per_core.items()
    }


def _load_note(cores: int) -> str:
    try:
        load1 = float(Path("/proc/loadavg").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return f"{cores} cores"
    return (
        f"{cores} cores, 1-min load average {load1:.2f} at the end (other work competes for them)"
    )


def sweep_point_ms(r: SpeedReport) -> tuple[float, float]:
    """(wall time of one inline sweep point, its stepping at the no-logging run's rate), ms: the
    benchmark's points (fig14-sine at a set bend) record no rows, so what the inline sweep spends
    beyond that rate is per-point overhead (both measured in the same bench-speed run)."""
    point = 1000.0 * r.sweep_duration_s / r.sweep_rtf_per_core[1]
    return point, 1000.0 * r.sweep_duration_s / r.rtf_native


def _goal(ok: bool) -> str:
    return "met" if ok else "NOT met"


def _step_lines(r: SpeedReport) -> list[str]:
    """Compile time, time per step, real-time factors and the whole process."""
    return [
        f"fsarm speed benchmark ({r.machine_note}); medians of {r.reps} repetitions",
        f"native callbacks: import {r.compile_s:.2f} s "
        + (
            "(loaded from cache)"
            if r.compile_cache_hits == r.compile_callbacks
            else "(compiled now; cached)"
        ),
        f"per mj_step, full model, blocks of {r.block_steps} steps from the {SCENARIO} start "
        "(median, best):",
        f"  raw MuJoCo (callbacks off)  {r.raw_us:8.3f} us {r.raw_us_best:8.3f} us"
        f"   (constraints at block end: {r.raw_nefc})",
        f"  raw, MuJoCo timers stopped   {r.raw_untimed_us:8.3f} us {r.raw_untimed_us_best:8.3f} us"
        f"   (the native paths stop them too; lean/raw untimed = {r.lean_over_raw_untimed:.3f})",
        f"  python callbacks            {r.python_us:8.3f} us {r.python_us_best:8.3f} us"
        f"   python/raw = {r.python_over_raw:6.2f}",
        f"  native callbacks            {r.native_us:8.3f} us {r.native_us_best:8.3f} us"
        f"   native/raw = {r.native_over_raw:6.3f}"
        f"   goal <= {GOAL_NATIVE_OVER_RAW}: {_goal(r.native_over_raw <= GOAL_NATIVE_OVER_RAW)}",
        f"  native, lean twin (default)  {r.lean_us:8.3f} us {r.lean_us_best:8.3f} us"
        f"   lean/raw = {r.lean_over_raw:6.3f}"
        f"   goal <= {GOAL_LEAN_OVER_RAW}: {_goal(r.lean_over_raw <= GOAL_LEAN_OVER_RAW)}",
        f"real-time factor, {r.rtf_duration_s:g} s {SCENARIO}, native (the default run):",
        f"  full logging (default)  {r.rtf_logged:6.0f}x (best {r.rtf_logged_best:.0f}x)"
        f"   goal >= {GOAL_REALTIME_FACTOR:g}x: {_goal(r.rtf_logged >= GOAL_REALTIME_FACTOR)}",
        f"  no logging              {r.rtf_native:6.0f}x (best {r.rtf_native_best:.0f}x)",
        f"  (ceiling set by raw MuJoCo's best step alone, full model: "
        f"{r.timestep_s / (r.raw_us_best * 1e-6):.0f}x with its stage timers, "
        f"{r.timestep_s / (r.raw_untimed_us_best * 1e-6):.0f}x without)",
        f"whole process `fsarm run {SCENARIO} --duration {r.rtf_duration_s:g} --out DIR`: "
        f"{r.process_s:.2f} s   goal <= {GOAL_PROCESS_S:g} s: {_goal(r.process_s <= GOAL_PROCESS_S)}",
        f"  phases in a fresh interpreter (native callbacks from the {r.kernel_source}): "
        + ", ".join(f"{k} {v:.3f} s" for k, v in r.process_phases.items())
        + (
            f"; the rest (interpreter start and exit, CLI parsing, printing): "
            f"{r.process_s - sum(v for k, v in r.process_phases.items() if '(' not in k):.3f} s"
            if r.process_phases
            else ""
        ),
    ]


def _sweep_lines(r: SpeedReport) -> list[str]:
    """The sweep's throughput per worker count and its goals (none without a sweep)."""
    if not r.sweep_points:
        return []
    lines: list[str] = []
    single = r.rtf_logged
    lines.append(
        f"sweep: {r.sweep_points} tracking points x {r.sweep_duration_s:g} s (run_sweep; "
        f"--executor local: process workers started by {r.sweep_start_method or '?'}; CPU: "
        "of the sweep's process and workers):"
    )
    for rtf, scaling, cpus, how, many in (
        (r.sweep_rtf_per_core, r.sweep_scaling, r.sweep_cpu_s, "--executor local", "processes"),
        (
            r.sweep_default_rtf_per_core,
            r.sweep_default_scaling,
            r.sweep_default_cpu_s,
            "the default, --executor auto",
            "threads",
        ),
    ):
        for w, v in rtf.items():
            lines.append(
                f"  {w} worker{'s' if w > 1 else ' '}  {v:6.0f}x real time per core"
                f" ({v / single:.2f} of the single run), scaling {scaling[w]:.2f}x,"
                f" CPU {cpus.get(w, math.nan):.2f} s  ({how}: {many if w > 1 else 'inline'})"
            )
    if 1 in r.sweep_rtf_per_core:
        point_ms, step_ms = sweep_point_ms(r)
        lines.append(
            f"  per point (inline): {point_ms:.1f} ms, of which stepping ~{step_ms:.1f} ms "
            f"(at the no-logging run's rate); the rest, {point_ms - step_ms:.1f} ms, builds "
            "the model, computes the metrics and stores the point"
        )
        per = r.sweep_rtf_per_core[1] / single
        default2 = r.sweep_default_scaling.get(2, 0.0)  # sweep.pick_executor: threads
        lines.append(
            f"  goal per core >= {GOAL_SWEEP_PER_CORE} x single run: "
            f"{_goal(per >= GOAL_SWEEP_PER_CORE)}"
            + (
                f"; goal 2 workers >= {GOAL_SCALING_2_CORES}x (the default executor): "
                f"{_goal(default2 >= GOAL_SCALING_2_CORES)}"
                if 2 in r.sweep_default_scaling
                else ""
            )
        )
    return lines


def _batch_lines(r: SpeedReport) -> list[str]:
    """The batch's throughput per worker count and its goal."""
    lines = [
        f"batch: {r.batch_runs} runs x {r.batch_duration_s:g} s, different shafts (D/L), "
        "mujoco.rollout in worker threads:",
    ]
    best1 = r.batch_steps_per_s_best[1]
    for w, thr in r.batch_steps_per_s.items():
        best = r.batch_steps_per_s_best[w]
        lines.append(
            f"  {w} worker{'s' if w > 1 else ' '}  median {thr:10,.0f} steps/s"
            f" ({thr * 0.001:6.1f} x real time), scaling {r.batch_scaling[w]:.2f}x;"
            f"  best {best:10,.0f} steps/s, scaling {best / best1:.2f}x"
        )
    if 2 in r.batch_scaling:
        lines.append(
            f"  goal 2 workers >= {GOAL_SCALING_2_CORES}x one: "
            f"{_goal(r.batch_scaling[2] >= GOAL_SCALING_2_CORES)}"
        )
    return lines


def format_report(r: SpeedReport) -> str:
    return "\n".join([*_step_lines(r), *_sweep_lines(r), *_batch_lines(r)])
