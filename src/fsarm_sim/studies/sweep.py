"""Parameter sweeps: spec parsing and validation, point generation, per-point evaluation, the
resumable runner, and the analysis of a finished sweep (eq. 3/4 re-fits, plots).

A sweep is the Cartesian product of a **grid** (field -> values) merged with **fixed** settings.
Fields (see :func:`fields`): ``diameter_mm``, ``length_mm``, ``bend_deg``, ``payload_kg``,
``scenario``, ``duration_s`` and the controller gains ``gains.<name>`` (``gains.wn1..3`` and
``gains.zeta1..3`` for the position loops). Values on the command line::

    --grid diameter_mm=4:13:4        4 values evenly spaced from 4 to 13, both included
                                     (start:stop:count, like numpy.linspace)
    --grid length_mm=235,335,535     a list
    --set scenario=fig14-sine        a fixed value

or in a TOML file (``examples/sweeps/*.toml``)::

    name = "d-l"
    outputs = ["bench", "tracking", "bandwidth", "relief"]
    [grid]
    diameter_mm = "4:13:4"            # or [4, 7, 10, 13] or {start = 4, stop = 13, num = 4}
    length_mm = [235, 335, 535]
    [fixed]
    duration_s = 4.0
    [bench]                           # BenchSettings of the per-point bench tests
    chirp_s = 4.0
    [bandwidth]                       # arm_metrics.torque_bandwidth settings
    chirp_s = 4.0

Every spec problem - empty or reversed ranges, unknown fields, NaN, out-of-range or invalid
shafts, a bend angle with a scenario that moves joint 2, too many points - raises
:class:`SweepSpecError` before any simulation starts.

Per point (``outputs``):

* ``bench``: K_sp, K_sn at the point's bend from the simulated series bench (chirp into the
  torque controller, eq. 8 fit per sign) and K_b from the simulated parallel bench (eq. 2 linear
  fit; the cubic fit too). Without ``bench`` the catalogue's eq. 3/4 values are reported instead,
  labelled ``stiffness_source = "catalogue eq. 3/4"``; the catalogue values are always kept as
  ``*_catalogue`` for comparison.
* ``tracking``: the scenario (default fig14-sine, joint 2 held at ``bend_deg``): joint RMSE, peak
  motor torque/speed (:func:`fsarm_sim.studies.arm_metrics.tracking`).
* ``bandwidth``: joint-3 torque-control -3 dB bandwidth (:func:`fsarm_sim.studies.arm_metrics.torque_bandwidth`).
* ``relief``: joint-2 static torque relief of the bent shaft at 90 deg.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import itertools
import json
import math
import time
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import FsarmError, ShaftRangeError
from fsarm_sim.executors import EXECUTORS, ExecutorError, Outcome, check_workers, run_tasks
from fsarm_sim.plant.shaft import Catalogue, load_catalogue, parse_catalogue
from fsarm_sim.records.store import ResultStore, canonical_json, point_key
from fsarm_sim.sim import scenarios
from fsarm_sim.studies import sweep_table
from fsarm_sim.studies import trajectory_file as _trajectory_file  # noqa: F401  (file: scenarios)
from fsarm_sim.studies.sweep_spec import (
    BANDWIDTH_KEYS,
    BENCH_DEFAULTS,
    DEFAULT_OUTPUTS,
    GAIN_TUPLES,
    MAX_POINTS,
    OUTPUTS,
    SweepSpec,
    field_info,
    parse_assignment,
    parse_number,
    scalar_value,
)
from fsarm_sim.studies.sweep_spec import POINT_SCHEMA as POINT_SCHEMA
from fsarm_sim.studies.sweep_spec import SweepSpecError as SweepSpecError
from fsarm_sim.studies.sweep_spec import fields as fields
from fsarm_sim.studies.sweep_spec import load_spec_file as load_spec_file
from fsarm_sim.studies.sweep_spec import parse_values as parse_values


def build_spec(
    file_data: Mapping[str, Any] | None = None,
    *,
    grid: Sequence[str] = (),
    fixed: Sequence[str] = (),
    name: str | None = None,
    outputs: Sequence[str] | None = None,
    shaft_file: str | None = None,
    extrapolate: bool | None = None,
    backend: str | None = None,
    bench: Mapping[str, Any] | None = None,
    bandwidth: Mapping[str, Any] | None = None,
) -> SweepSpec:
    """Merge a TOML spec (``load_spec_file``) with command-line ``FIELD=VALUES`` items.

    Command-line grid/fixed items replace the file's for the same field."""
    data = dict(file_data or {})
    g: dict[str, tuple[Any, ...]] = {}
    f: dict[str, Any] = {}
    for key, raw in dict(data.get("grid", {})).items():
        g[key] = parse_values(field_info(key), raw)
    for key, raw in dict(data.get("fixed", {})).items():
        f[key] = scalar_value(field_info(key), raw)
    seen: set[str] = set()
    for items, swept in ((grid, True), (fixed, False)):
        for item in items:
            key, raw = parse_assignment(item)
            if key in seen:
                raise SweepSpecError(f"field {key!r} is given twice on the command line")
            seen.add(key)
            if swept:
                g[key] = parse_values(field_info(key), raw)
                f.pop(key, None)
            else:
                f[key] = scalar_value(field_info(key), raw)
                g.pop(key, None)
    both = set(g) & set(f)
    if both:
        raise SweepSpecError(f"fields {sorted(both)} are both swept and fixed")
    outs = tuple(outputs if outputs is not None else data.get("outputs", DEFAULT_OUTPUTS))
    bad = [o for o in outs if o not in OUTPUTS]
    if bad or not outs:
        raise SweepSpecError(
            f"outputs must be a non-empty subset of {list(OUTPUTS)}, got {list(outs)}"
        )
    spec = SweepSpec(
        name=str(name or data.get("name") or "sweep"),
        grid=g,
        fixed=f,
        outputs=tuple(o for o in OUTPUTS if o in outs),
        shaft_file=shaft_file if shaft_file is not None else data.get("shaft_file"),
        extrapolate=bool(
            extrapolate if extrapolate is not None else data.get("extrapolate", False)
        ),
        backend=str(backend or data.get("backend", "native")),
        bench={**BENCH_DEFAULTS, **dict(data.get("bench", {})), **dict(bench or {})},
        bandwidth={**dict(data.get("bandwidth", {})), **dict(bandwidth or {})},
    )
    validate(spec)
    return spec


# ----------------------------------------------------------------------------------------------
# validation and points


def _catalogue(spec: SweepSpec) -> tuple[Catalogue, str | None, str]:
    """(catalogue, its TOML text or None for the default, sha256 of the text)."""
    from importlib import resources

    if spec.shaft_file is None:
        text = resources.files("fsarm_sim.data").joinpath("shafts.toml").read_text("utf-8")
        return load_catalogue(), None, hashlib.sha256(text.encode()).hexdigest()
    cat = load_catalogue(spec.shaft_file)
    text = Path(spec.shaft_file).read_text("utf-8")
    return cat, text, hashlib.sha256(text.encode()).hexdigest()


def spec_catalogue(spec: SweepSpec) -> tuple[Catalogue, str | None, str]:
    """The spec's coefficient file: (catalogue, its TOML text or None for the default, sha256
    of the text) - what every point's task carries."""
    return _catalogue(spec)


def _validate_bench_tables(spec: SweepSpec) -> None:
    """``[bench]`` (BenchSettings fields) and ``[bandwidth]`` (known keys, values > 0)."""
    from fsarm_sim.studies.campaign import BenchSettings, CampaignError

    try:
        BenchSettings(**spec.bench).validate()
    except TypeError as exc:
        raise SweepSpecError(f"[bench]: {exc} (allowed: BenchSettings fields)") from exc
    except CampaignError as exc:
        raise SweepSpecError(f"[bench]: {exc}") from exc
    bad_bw = set(spec.bandwidth) - set(BANDWIDTH_KEYS)
    if bad_bw:
        raise SweepSpecError(
            f"[bandwidth]: unknown keys {sorted(bad_bw)}; allowed {list(BANDWIDTH_KEYS)}"
        )
    for k, v in spec.bandwidth.items():
        if parse_number(f"bandwidth.{k}", v) <= 0.0 and k != "q3_deg":
            raise SweepSpecError(f"bandwidth.{k} must be > 0, got {v!r}")


def _validate_ranges(values: Mapping[str, Any], known: Mapping[str, Any]) -> None:
    """Every number of the grid within its field's range."""
    for key, vals in values.items():
        info = known[key]
        for v in vals:
            if v is None or info.kind != "float":
                continue
            if info.minimum is not None and v < info.minimum:
                raise SweepSpecError(
                    f"{key} = {v:g} is below its minimum {info.minimum:g} {info.unit}"
                )
            if info.maximum is not None and v > info.maximum:
                raise SweepSpecError(
                    f"{key} = {v:g} is above its maximum {info.maximum:g} {info.unit}"
                )


def _validate_bend_on_arm(spec: SweepSpec, values: Mapping[str, Any]) -> None:
    """A bend angle can be imposed on the arm only for scenarios that hold joint 2."""
    from fsarm_sim.studies.arm_metrics import scenario_holds_joint2

    bend_given = "bend_deg" in spec.grid or "bend_deg" in spec.fixed
    for s in values["scenario"]:
        sc = scenarios.get(s)
        for dur in values["duration_s"]:
            duration = sc.duration_s if dur is None else dur
            if bend_given and not scenario_holds_joint2(s, duration):
                raise SweepSpecError(
                    f"scenario {s!r} moves joint 2, so bend_deg cannot be imposed on the arm; "
                    "sweep bend_deg only with scenarios that hold joint 2 (fig14-sine, "
                    "step-q3), or leave 'tracking' out of the outputs"
                )


def validate(spec: SweepSpec) -> None:
    """Every check that can fail before the first simulation (raises SweepSpecError)."""
    if spec.n_points > MAX_POINTS:
        raise SweepSpecError(
            f"the sweep has {spec.n_points} points, more than the {MAX_POINTS} allowed in one spec"
        )
    if spec.backend not in ("python", "native"):
        raise SweepSpecError(f"backend must be 'python' or 'native', got {spec.backend!r}")
    known = fields()
    for key in list(spec.grid) + list(spec.fixed):
        if key not in known:
            raise SweepSpecError(
                f"unknown sweep field {key!r}; allowed: {', '.join(sorted(known))}"
            )
    _validate_bench_tables(spec)
    try:
        cat, _, _ = _catalogue(spec)
    except FsarmError as exc:
        raise SweepSpecError(f"shaft file: {exc}") from exc
    values = {k: spec.grid.get(k, (spec.fixed.get(k, known[k].default),)) for k in known}
    _validate_ranges(values, known)
    for b in values["bend_deg"]:
        try:  # the same check as the arm runs' (model.build_model) and the bench's
            cat.check_bend(math.radians(b), f"bend_deg = {b:g}")
        except ShaftRangeError as exc:
            raise SweepSpecError(str(exc)) from exc
    for d in values["duration_s"]:
        if d is not None and d <= 0.0:
            raise SweepSpecError(f"duration_s must be > 0 s, got {d:g}")
    for s in values["scenario"]:
        if not scenarios.known(s):
            raise SweepSpecError(
                f"unknown scenario {s!r}; registered: {', '.join(sorted(scenarios.REGISTRY))}"
            )
    # every shaft of the grid must be valid in the catalogue
    for d, ell in itertools.product(values["diameter_mm"], values["length_mm"]):
        try:
            cat.shaft(d, ell, extrapolate=spec.extrapolate)
        except ShaftRangeError as exc:
            raise SweepSpecError(f"shaft D = {d:g} mm, L = {ell:g} mm: {exc}") from exc
    if "tracking" in spec.outputs:
        _validate_bend_on_arm(spec, values)
    for point in points(spec, validate_only=True):
        try:
            _gains(point).validate()
        except FsarmError as exc:
            raise SweepSpecError(f"point {canonical_json(point)}: {exc}") from exc


def _gains(point: Mapping[str, Any]) -> Gains:
    g = Gains()
    changes: dict[str, Any] = {}
    tuples: dict[str, list[float]] = {}
    for key, v in point.items():
        if not key.startswith("gains."):
            continue
        name = key[len("gains.") :]
        for short, attr in GAIN_TUPLES.items():
            if name.startswith(short) and name[len(short) :].isdigit():
                tuples.setdefault(attr, list(getattr(g, attr)))[int(name[len(short) :]) - 1] = v
                break
        else:
            changes[name] = v
    for attr, vals in tuples.items():
        changes[attr] = tuple(vals)
    return dataclasses.replace(g, **changes)


def points(spec: SweepSpec, *, validate_only: bool = False) -> list[dict[str, Any]]:
    """The sweep's points: grid product + fixed + defaults, as canonical dicts.

    A point holds every input that decides its outputs (the store's key is its hash): the field
    values, the outputs asked for, the bench/bandwidth settings, the catalogue's SHA-256, the
    point schema. Gains are listed only when set (defaults come from this version's Gains).
    """
    known = fields()
    base: dict[str, Any] = {}
    for key, info in known.items():
        if key.startswith("gains."):
            continue
        base[key] = spec.fixed.get(key, info.default)
    for key, v in spec.fixed.items():
        if key.startswith("gains."):
            base[key] = v
    sha = "" if validate_only else _catalogue(spec)[2]
    common = {
        "schema": POINT_SCHEMA,
        "outputs": list(spec.outputs),
        "bench": dict(sorted(spec.bench.items())) if "bench" in spec.outputs else {},
        "bandwidth": dict(sorted(spec.bandwidth.items())) if "bandwidth" in spec.outputs else {},
        "catalogue_sha256": sha,
        "extrapolate": spec.extrapolate,
    }
    names = list(spec.grid)
    out = []
    for combo in itertools.product(*(spec.grid[n] for n in names)):
        p = {**base, **dict(zip(names, combo, strict=True)), **common}
        sc = scenarios.get(p["scenario"])
        if p["duration_s"] is None:
            p["duration_s"] = sc.duration_s
        if p["payload_kg"] is None:
            p["payload_kg"] = sc.payload_kg
        out.append(p)
    return out


# ----------------------------------------------------------------------------------------------
# evaluating one point (runs in a worker)


def _bench_fits(cat: Catalogue, p: Mapping[str, Any], backend: str) -> dict[str, Any]:
    """A point's stiffnesses fitted on the simulated benches (series: eq. 8 per sign; parallel:
    eq. 2)."""
    from fsarm_sim.studies.campaign import BenchSettings, fit_series, series_test

    d, ell, bend = p["diameter_mm"], p["length_mm"], math.radians(p["bend_deg"])
    s = BenchSettings(**{**p["bench"], "backend": backend})
    sf = fit_series(
        series_test(
            cat.shaft(d, ell, extrapolate=p["extrapolate"], series_hysteresis=s.series_hysteresis),
            bend,
            s,
        ),
        p["bend_deg"],
    )
    bench_json = json.dumps({**p["bench"], "backend": backend}, sort_keys=True)
    pf = _parallel_fit(cat, d, ell, p["extrapolate"], bench_json)
    return {
        "k_sp": sf.k_pos,
        "k_sn": sf.k_neg,
        "series_rmse_p": sf.rmse_pos,
        "series_rmse_n": sf.rmse_neg,
        "kb": pf.kb_linear,
        "kb_rmse": pf.rmse_linear,
        "kb_cubic": pf.kb_cubic,
        "bend_loop_energy_j": pf.loop_energy_j,
        "stiffness_source": "simulated bench fit (series: eq. 8 per sign; parallel: eq. 2)",
    }


def evaluate_point(task: Mapping[str, Any]) -> dict[str, Any]:
    """All requested outputs of one point. ``task = {"point": ..., "catalogue_toml": ...}``."""
    from fsarm_sim.studies import arm_metrics

    p = task["point"]
    text = task.get("catalogue_toml")
    # a sampled catalogue (studies.uncertainty) comes as an object, the sweep's as its text
    cat = task.get("catalogue") or _task_catalogue(
        text, str(task.get("catalogue_source", "shaft file"))
    )
    d, ell, bend = p["diameter_mm"], p["length_mm"], math.radians(p["bend_deg"])
    shaft = cat.shaft(d, ell, extrapolate=p["extrapolate"])
    backend = task.get("backend", "native")
    known = task.get("controller_catalogue")  # the controller's eq. 8 when not the shaft's own
    cfg = SimConfig(
        shaft=shaft,
        gains=_gains(p),
        controller_shaft=None if known is None else known.shaft(d, ell, extrapolate=True),
    )
    out: dict[str, Any] = {
        "k_sp_catalogue": shaft.k_series(bend, 1),
        "k_sn_catalogue": shaft.k_series(bend, -1),
        "kb_catalogue": shaft.kb_eq4,  # eq. 4: what the bench's eq. 2 fit is compared with
        "rating_nm": shaft.rating_nm,
    }
    outputs = p["outputs"]
    if "bench" in outputs:
        out.update(_bench_fits(cat, p, backend))
    else:
        out.update(
            k_sp=out["k_sp_catalogue"],
            k_sn=out["k_sn_catalogue"],
            kb=out["kb_catalogue"],
            stiffness_source="catalogue eq. 3/4",
        )
    if "tracking" in outputs:
        bend_arm = (
            bend if arm_metrics.scenario_holds_joint2(p["scenario"], p["duration_s"]) else None
        )
        out.update(
            arm_metrics.tracking(
                cfg,
                p["scenario"],
                duration_s=p["duration_s"],
                payload_kg=p["payload_kg"],
                bend_rad=bend_arm,
                backend=backend,
            )
        )
    if "bandwidth" in outputs:
        bw_args = dict(p["bandwidth"])
        q3 = math.radians(bw_args.pop("q3_deg", 45.0))
        bw = arm_metrics.torque_bandwidth(cfg, bend, q3_rad=q3, backend=backend, **bw_args)
        out["torque_bandwidth_hz"] = bw.bandwidth_hz
        out["torque_low_gain"] = bw.low_gain
    if "relief" in outputs:
        out["static_relief_nm"] = arm_metrics.static_relief_nm(cfg)
    return out


@functools.lru_cache(maxsize=8)
def _task_catalogue(text: str | None, source: str) -> Catalogue:
    """The catalogue of a task, parsed once per process (a Catalogue is immutable, so the points
    of a sweep share it; parsing the TOML took ~2 ms of every point)."""
    return load_catalogue() if text is None else parse_catalogue(tomllib.loads(text), source)


@functools.lru_cache(maxsize=64)
def _parallel_fit(cat: Catalogue, d: float, ell: float, extrapolate: bool, bench_json: str) -> Any:
    """The parallel-bench fit of one shaft, cached per process: K_b does not depend on the bend,
    payload, gains or scenario, so points that share a shaft share it (same inputs, same result;
    a Catalogue is immutable and compares by value, so a sampled one is its own entry)."""
    from fsarm_sim.studies.campaign import BenchSettings, fit_parallel, parallel_test

    s = BenchSettings(**json.loads(bench_json))
    return fit_parallel(parallel_test(cat.shaft(d, ell, extrapolate=extrapolate), False, s), False)


# ----------------------------------------------------------------------------------------------
# running a sweep into a store


@dataclass
class SweepReport:
    name: str
    total: int
    already: int
    computed: int
    failed: int
    wall_s: float
    errors: list[str] = field(default_factory=list)
    failed_before: int = 0  # points of this sweep stored as failed by an earlier run (not rerun)
    executor: str = ""  # the executor the points ran on (pick_executor's choice)
    table: Path | None = None  # the store's tidy Parquet table (sweep_table.write_tidy)

    @property
    def points_per_s(self) -> float:
        return self.computed / self.wall_s if self.wall_s > 0 else math.nan


AUTO = "auto"  # the executor run_sweep picks by itself (pick_executor)
# the outputs whose points are native simulations with little Python around them
THREADED_OUTPUTS = frozenset({"tracking", "bandwidth", "relief"})


def pick_executor(spec: SweepSpec, executor: str = AUTO, workers: int | None = None) -> str:
    """The executor for ``executor="auto"`` (any other name is returned as it is): threads of
    this process where every point is a native simulation (outputs tracking, bandwidth,
    relief: the stepping runs with the GIL released, and threads pay no worker start-up; ``fsarm
    bench-speed`` compares the two), the process pool ("local") where points fit benches in Python
    (``bench``) or step through the Python callbacks, and one worker runs the points here one
    after the other (the local executor's inline path)."""
    check_workers(workers)
    if executor != AUTO:
        if executor not in EXECUTORS:
            raise ExecutorError(
                f"executor must be {AUTO}, {', '.join(EXECUTORS[:-1])} or {EXECUTORS[-1]}, "
                f"got {executor!r}"
            )
        return executor
    if workers != 1 and spec.backend == "native" and set(spec.outputs) <= THREADED_OUTPUTS:
        return "threads"
    return "local"


def _count_earlier_failures(
    report: SweepReport, stored_errors: Mapping[str, str], pts: list[dict[str, Any]]
) -> None:
    """The points of the sweep stored as failed by an earlier run (not rerun) into ``report``."""
    for p in pts:
        err = stored_errors.get(point_key(p))
        if err is not None:
            report.failed_before += 1
            report.errors.append(f"{canonical_json(p)}: {err} (stored by an earlier run)")


def run_sweep(
    spec: SweepSpec,
    store_path: str | Path,
    *,
    executor: str = AUTO,
    workers: int | None = None,
    scheduler: str | None = None,
    processes: bool = True,
    retry_failed: bool = False,
    progress: bool = False,
    on_done: Callable[[Outcome], None] | None = None,
) -> SweepReport:
    """Compute the points not yet in the store; store each as soon as it finishes
    (``executor="auto"``: :func:`pick_executor`)."""
    executor = pick_executor(spec, executor, workers)
    pts = points(spec)
    cat, text, sha = _catalogue(spec)
    with ResultStore(store_path) as store:
        if retry_failed:
            store.delete_errors()
        store.set_meta(f"catalogue:{sha}", text if text is not None else "default")
        store.set_meta(f"spec:{spec.name}", json.dumps(dataclasses.asdict(spec), sort_keys=True))
        done = store.keys()
        todo = [p for p in pts if point_key(p) not in done]
        report = SweepReport(
            spec.name, len(pts), len(pts) - len(todo), 0, 0, 0.0, executor=executor
        )
        _count_earlier_failures(report, store.errors(), pts)
        common = {"catalogue_toml": text, "catalogue_source": cat.source, "backend": spec.backend}
        tasks = [{"point": p, **common} for p in todo]
        bar = _progress(progress)
        start = time.perf_counter()

        def store_one(o: Outcome) -> None:
            store.put(
                o.task["point"],
                o.result,
                sweep=spec.name,
                wall_s=o.wall_s,
                error=o.error,
                host=o.host,
            )
            if o.error is None:
                report.computed += 1
            else:
                report.failed += 1
                report.errors.append(f"{canonical_json(o.task['point'])}: {o.error}")
            if bar is not None:
                bar[0].advance(bar[1])
            if on_done is not None:
                on_done(o)

        def start_bar() -> None:  # once the workers run: the bar's thread is not forked
            if bar is not None:
                bar[0].start()
                bar[0].update(bar[1], total=len(tasks))

        try:
            run_tasks(
                evaluate_point,
                tasks,
                executor=executor,
                workers=workers,
                scheduler=scheduler,
                processes=processes,
                on_done=store_one,
                prepare=functools.partial(prepare_workers, spec),
                on_start=start_bar,
            )
        finally:
            if bar is not None:
                bar[0].stop()
            report.wall_s = time.perf_counter() - start
    report.table = sweep_table.write_tidy(store_path)
    return report


def prepare_workers(spec: SweepSpec) -> None:
    """What every point needs, done once in the sweep's process before the local pool forks its
    workers (:func:`fsarm_sim.executors.run_tasks`): the simulation, metrics and bench modules
    (imported, so the workers inherit them) and, on the native backend, the compiled kernels."""
    from fsarm_sim.engine import callbacks
    from fsarm_sim.studies import arm_metrics, campaign

    del arm_metrics, campaign  # imported for the workers to inherit
    if spec.backend == "native":
        callbacks.load_native()


def _progress(enabled: bool) -> tuple[Any, Any] | None:
    if not enabled:
        return None
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    prog = Progress(
        TextColumn("sweep"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("elapsed"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=Console(stderr=True),
    )
    return prog, prog.add_task("sweep", total=None)
