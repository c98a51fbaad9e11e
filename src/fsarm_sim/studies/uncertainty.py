"""Propagate the catalogue's declared coefficient ranges (``[uncertainty]`` of the coefficient
file) to any metric: quasi-random samples of the group factors, the metric evaluated for each
(in parallel through :func:`fsarm_sim.executors.run_tasks`), and the 5-95 % band of every number.

``propagate(metric, catalogue, n)`` calls the module-level ``metric(catalogue) -> dict`` once per
sample with a :meth:`Catalogue.perturbed` copy; the samples are a scrambled, seeded Sobol sequence
(``scipy.stats.qmc``) mapped uniformly onto each group's ``relative`` range, so the same ``n`` and
``seed`` give the same band. The nominal value is not one of the samples: callers report it beside
the band.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from fsarm_sim.errors import FsarmError, whole_number
from fsarm_sim.executors import Outcome, run_tasks
from fsarm_sim.plant.shaft import Catalogue

MAX_SAMPLES = 4096
DEFAULT_SEED = 32
BAND = (5.0, 95.0)  # percent
# what the controller knows of a sampled shaft: "nominal" - the catalogue's eq. 8 (the plant
# differs from what the controller was given); "matched" - the sample's own (identified first)
CONTROLLER_MODES = ("nominal", "matched")


class UncertaintyError(FsarmError, ValueError):
    """Bad --uncertainty settings, or a coefficient file that declares no ranges."""


@dataclass(frozen=True)
class Band:
    low: float  # 5th percentile
    median: float
    high: float  # 95th percentile
    n: int  # samples that gave a finite value

    def as_dict(self) -> dict[str, float | int]:
        return {"p05": self.low, "p50": self.median, "p95": self.high, "n": self.n}


@dataclass(frozen=True)
class Propagation:
    bands: dict[str, Band]
    samples: int
    failed: int  # samples whose metric raised (named in errors)
    errors: tuple[str, ...]
    groups: tuple[str, ...]
    seed: int
    wall_s: float


def check_controller(mode: str) -> str:
    if mode not in CONTROLLER_MODES:
        raise UncertaintyError(
            f"the controller under uncertainty must be one of {', '.join(CONTROLLER_MODES)}, "
            f"got {mode!r}"
        )
    return mode


def check_samples(n: int, what: str = "--uncertainty") -> int:
    """The number of samples: a whole number in 2 .. MAX_SAMPLES."""
    return whole_number(n, f"{what} (samples)", 2, MAX_SAMPLES, UncertaintyError)


def factor_samples(
    catalogue: Catalogue, n: int, seed: int = DEFAULT_SEED
) -> list[dict[str, float]]:
    """``n`` factor sets, one per sample: scrambled Sobol points in the unit cube mapped onto each
    declared group's [low, high]."""
    from scipy.stats import qmc

    n = check_samples(n)
    ranges = catalogue.uncertainty
    if not ranges:
        raise UncertaintyError(
            f"{catalogue.source} declares no [uncertainty] ranges, so there is nothing to "
            "sample; add [uncertainty.<group>] relative = [low, high] and reason (see the default "
            "shafts.toml)"
        )
    sampler = qmc.Sobol(d=len(ranges), scramble=True, seed=seed)
    # Sobol's balance needs a power of two; take the first n of the next one
    unit = sampler.random(2 ** math.ceil(math.log2(n)))[:n]
    lo = np.array([r.low for r in ranges])
    hi = np.array([r.high for r in ranges])
    values = qmc.scale(unit, lo, hi) if np.all(hi > lo) else lo + unit * (hi - lo)
    return [{r.group: float(v) for r, v in zip(ranges, row, strict=True)} for row in values]


def flatten(metrics: Mapping[str, Any], prefix: str = "") -> dict[str, float]:
    """The finite-or-NaN numbers of a (nested) metrics dict, keys joined with '.'."""
    out: dict[str, float] = {}
    for key, value in metrics.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten(value, f"{name}."))
        elif isinstance(value, int | float) and not isinstance(value, bool):
            out[name] = float(value)
    return out


def _evaluate(task: Mapping[str, Any]) -> dict[str, Any]:
    cat: Catalogue = task["catalogue"]
    metric: Callable[[Catalogue], Mapping[str, Any]] = task["metric"]
    return flatten(metric(cat.perturbed(task["factors"])))


def bands(rows: list[dict[str, float]]) -> dict[str, Band]:
    """5-50-95 % percentiles of every key over the rows (NaNs left out)."""
    keys = sorted({k for r in rows for k in r})
    out = {}
    for k in keys:
        v = np.array([r.get(k, math.nan) for r in rows], dtype=np.float64)
        v = v[np.isfinite(v)]
        if v.size == 0:
            out[k] = Band(math.nan, math.nan, math.nan, 0)
            continue
        lo, med, hi = np.percentile(v, [BAND[0], 50.0, BAND[1]])
        out[k] = Band(float(lo), float(med), float(hi), int(v.size))
    return out


def propagate(
    metric: Callable[[Catalogue], Mapping[str, Any]],
    catalogue: Catalogue,
    n: int,
    *,
    seed: int = DEFAULT_SEED,
    executor: str = "threads",
    workers: int | None = 2,
    scheduler: str | None = None,
    on_done: Callable[[Outcome], None] | None = None,
) -> Propagation:
    """Evaluate ``metric`` on ``n`` perturbed catalogues and return the band of every number.

    ``metric`` must be picklable (a module-level function or a ``functools.partial`` of one) for
    the process executors; the default ``threads`` executor suits native simulations (they step
    with the GIL released)."""
    import time

    start = time.perf_counter()
    samples = factor_samples(catalogue, n, seed)
    tasks = [{"catalogue": catalogue, "metric": metric, "factors": f} for f in samples]
    outcomes = run_tasks(
        _evaluate,
        tasks,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        on_done=on_done,
    )
    rows = [o.result for o in outcomes if o.result is not None]
    errors = tuple(f"sample {o.index} {o.task['factors']}: {o.error}" for o in outcomes if o.error)
    return Propagation(
        bands=bands(rows),
        samples=len(samples),
        failed=len(errors),
        errors=errors,
        groups=tuple(r.group for r in catalogue.uncertainty),
        seed=seed,
        wall_s=time.perf_counter() - start,
    )


def run_metrics(
    catalogue: Catalogue,
    *,
    scenario: str,
    config: Any,
    diameter_mm: float,
    length_mm: float,
    extrapolate: bool = False,
    series_hysteresis: bool | None = None,
    duration_s: float | None = None,
    payload_kg: float | None = None,
    backend: str = "native",
    controller: str = "nominal",
) -> dict[str, Any]:
    """The metrics of ``fsarm run`` (:func:`run_scenario`) with the shaft of ``catalogue`` as the
    plant: the metric :func:`propagate` samples for ``fsarm run --uncertainty``. ``controller``
    (:data:`CONTROLLER_MODES`): "nominal" keeps ``config``'s shaft as the controller's model."""
    from fsarm_sim.sim.simulation import run_scenario

    shaft = catalogue.shaft(
        diameter_mm, length_mm, extrapolate=extrapolate, series_hysteresis=series_hysteresis
    )
    known = config.controller_shaft or config.shaft
    res = run_scenario(
        scenario,
        config.with_(shaft=shaft, controller_shaft=known if controller == "nominal" else None),
        duration_s=duration_s,
        payload_kg=payload_kg,
        backend=backend,  # type: ignore[arg-type]
        log_every_ticks=1,
    )
    return res.metrics


# the metrics `fsarm run --uncertainty` prints (all are in the JSON)
RUN_KEYS: tuple[tuple[str, str], ...] = (
    ("rmse_deg.q3", "q3 RMSE [deg]"),
    ("max_abs_err_deg.q3", "q3 max |error| [deg]"),
    ("rmse_deg.q2", "q2 RMSE [deg]"),
    ("tau_estimate_rmse_nm", "joint-3 torque estimate error, RMSE [N*m]"),
    ("peak_shaft_torque_nm", "peak shaft torque [N*m]"),
    ("peak_motor_torque_nm", "peak joint-3 motor torque [N*m]"),
    ("motor_energy_j", "joint-3 motor work [J]"),
    ("peak_shaft_torque_over_rating", "peak shaft torque / rating"),
)


def to_json(
    prop: Propagation, nominal: Mapping[str, Any] | None = None, controller: str | None = None
) -> dict[str, Any]:
    """A JSON-ready report: settings, the band (and nominal value) of every metric."""
    nom = flatten(nominal) if nominal is not None else {}
    return {
        "controller": controller,
        "samples": prop.samples,
        "failed": prop.failed,
        "errors": list(prop.errors),
        "groups": list(prop.groups),
        "sampler": "scrambled Sobol (scipy.stats.qmc), uniform factor per group",
        "seed": prop.seed,
        "band_percent": list(BAND),
        "wall_s": prop.wall_s,
        "metrics": {
            k: {**b.as_dict(), **({"nominal": nom[k]} if k in nom else {})}
            for k, b in prop.bands.items()
        },
    }


def point_metric(
    catalogue: Catalogue, *, task: Mapping[str, Any], controller_catalogue: Catalogue | None
) -> dict[str, float]:
    """The numeric outputs of one sweep point (:func:`fsarm_sim.studies.sweep.evaluate_point`)
    with ``catalogue`` as the plant: the metric ``fsarm sweep --uncertainty`` samples."""
    from fsarm_sim.studies.sweep import evaluate_point

    out = evaluate_point(
        {**task, "catalogue": catalogue, "controller_catalogue": controller_catalogue}
    )
    return {k: float(v) for k, v in out.items() if isinstance(v, int | float)}


def sweep_bands(
    spec: Any, n: int, *, controller: str = "nominal", seed: int = DEFAULT_SEED
) -> tuple[list[dict[str, Any]], float]:
    """The 5-95 % band of every output of every point of a sweep spec (``n`` samples each, 2
    threads); returns one row per (point, output) and the wall time. Not stored: the bands are
    a table beside the sweep's store."""
    import functools
    import time

    from fsarm_sim.studies import sweep

    check_samples(n)
    check_controller(controller)
    start = time.perf_counter()
    cat, text, _ = sweep.spec_catalogue(spec)
    rows: list[dict[str, Any]] = []
    varied = list(spec.grid)
    for p in sweep.points(spec):
        task = {"point": p, "catalogue_toml": text, "backend": spec.backend}
        metric = functools.partial(
            point_metric,
            task=task,
            controller_catalogue=cat if controller == "nominal" else None,
        )
        prop = propagate(metric, cat, n, seed=seed)
        for key, band in prop.bands.items():
            rows.append(
                {
                    **{f: p[f] for f in varied},
                    "output": key,
                    **band.as_dict(),
                    "failed": prop.failed,
                    "controller": controller,
                }
            )
    return rows, time.perf_counter() - start
