"""Task-level shaft selection (issue 32): the D and L, continuous in the coefficient file's
validity box, that minimise a task objective under constraints, found by an optimiser driving
simulations, then the nearest catalogue shafts.

Every candidate is a sweep point (:func:`fsarm_sim.studies.sweep.points` with its diameter and
length set; outputs ``tracking`` and, with a bandwidth floor, ``bandwidth``), evaluated by the
sweep's :func:`~fsarm_sim.studies.sweep.evaluate_point` through
:func:`fsarm_sim.executors.run_tasks` (threads, local pool or Dask) and stored in a
:class:`~fsarm_sim.records.store.ResultStore` as soon as it finishes: a second run with the same
store reads what is there and simulates only what is not (resume), and a grid sweep of the same
points shares it.

The optimiser is SciPy's ``differential_evolution`` (Sobol initial population, vectorized: one
generation is one parallel batch, no polish), on D and L scaled to [0, 1], with candidates rounded
to :data:`RESOLUTION_MM` so that a revisited shaft is a stored point. A constraint violated is a
penalty above every feasible objective. ``pareto`` runs it on weighted sums of two normalised
objectives and keeps the non-dominated shafts of everything evaluated.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.errors import FsarmError
from fsarm_sim.executors import Outcome, run_tasks
from fsarm_sim.plant.shaft import Catalogue
from fsarm_sim.records.store import ResultStore, point_key
from fsarm_sim.studies import trajectory_file as _trajectory_file  # noqa: F401  (file: scenarios)

OBJECTIVES: dict[str, str] = {
    "q3_rmse_deg": "joint-3 tracking RMSE [deg]",
    "motor_energy_j": "joint-3 motor work [J]",
    "peak_motor_torque_nm": "peak joint-3 motor torque [N*m]",
}
RESOLUTION_MM = 0.01  # candidates are rounded to this (store hits for revisited shafts)
PENALTY = 1.0e6  # objective of an infeasible or failed shaft (plus its violation)
SWEEP_NAME = "select"


class SelectionError(FsarmError, ValueError):
    """Bad task, constraints or optimiser settings."""


@dataclass(frozen=True)
class Task:
    scenario: str = "fig14-sine"  # a registered name, or trajectory_file.scenario_name(PATH)
    payload_kg: float | None = None  # None: the scenario's
    duration_s: float | None = None  # None: the scenario's
    bends_deg: tuple[float, ...] = (45.0,)  # joint-2 holds (scenarios holding joint 2) / bandwidth
    rating_margin: float = 1.0  # rating / peak shaft torque must be >= this
    bandwidth_floor_hz: float = 0.0  # torque-loop bandwidth at every bend >= this (0: unchecked)
    shaft_file: str | None = None
    executor: str = "threads"
    workers: int | None = 2


@dataclass(frozen=True)
class Evaluated:
    diameter_mm: float
    length_mm: float
    outputs: dict[str, float]  # worst over the bends
    feasible: bool
    why: str  # the violated constraint, "" when feasible


@dataclass
class Search:
    """What the optimiser found, and every shaft it simulated."""

    objective: str
    best: Evaluated | None
    evaluated: list[Evaluated] = field(default_factory=list)
    simulations: int = 0  # points simulated in this call (not read from the store)
    stored: int = 0  # points read from the store
    nearest: list[Evaluated] = field(default_factory=list)  # nearest catalogue shafts
    nearest_names: list[str] = field(default_factory=list)


def check_objective(name: str) -> str:
    if name not in OBJECTIVES:
        raise SelectionError(f"objective must be one of {', '.join(OBJECTIVES)}, got {name!r}")
    return name


class Evaluator:
    """Evaluates shafts for a task through the sweep store (module docstring)."""

    def __init__(self, task: Task, store_path: str | Path) -> None:
        from fsarm_sim.studies import sweep

        if task.rating_margin <= 0.0 or not math.isfinite(task.rating_margin):
            raise SelectionError(f"rating margin must be > 0, got {task.rating_margin!r}")
        if task.bandwidth_floor_hz < 0.0 or not math.isfinite(task.bandwidth_floor_hz):
            raise SelectionError(
                f"bandwidth floor must be >= 0 Hz, got {task.bandwidth_floor_hz!r}"
            )
        if not task.bends_deg:
            raise SelectionError("give at least one bend angle")
        fixed = [f"scenario={task.scenario}"]
        if task.payload_kg is not None:
            fixed.append(f"payload_kg={task.payload_kg!r}")
        if task.duration_s is not None:
            fixed.append(f"duration_s={task.duration_s!r}")
        outputs = ["tracking"] + (["bandwidth"] if task.bandwidth_floor_hz > 0.0 else [])
        from fsarm_sim.sim import scenarios
        from fsarm_sim.studies.arm_metrics import scenario_holds_joint2

        sc = scenarios.get(task.scenario) if scenarios.known(task.scenario) else None
        holds = sc is not None and scenario_holds_joint2(
            task.scenario, task.duration_s or sc.duration_s
        )
        if task.bandwidth_floor_hz > 0.0 and sc is not None and not holds:
            raise SelectionError(
                f"--bandwidth-floor: scenario {task.scenario!r} moves joint 2, so the bend of the "
                "bandwidth test is not the run's; use it with a scenario that holds joint 2 "
                "(fig14-sine, step-q3)"
            )
        grid = (
            [f"bend_deg={','.join(repr(b) for b in task.bends_deg)}"]
            if holds or len(outputs) > 1
            else []
        )
        try:
            self.spec = sweep.build_spec(
                grid=grid,
                fixed=fixed,
                name=SWEEP_NAME,
                outputs=outputs,
                shaft_file=task.shaft_file,
            )
        except FsarmError as exc:
            raise SelectionError(f"task: {exc}") from exc
        self.templates = sweep.points(self.spec)
        self.catalogue, self.text, _ = sweep.spec_catalogue(self.spec)
        self.task = task
        self.store_path = Path(store_path)
        self.simulations = 0
        self.stored = 0
        self.history: list[Evaluated] = []
        self._cache: dict[tuple[float, float], Evaluated] = {}

    @property
    def box(self) -> tuple[tuple[float, float], tuple[float, float]]:
        return self.catalogue.diameter_range, self.catalogue.length_range

    def _point(self, template: dict[str, Any], d: float, ell: float) -> dict[str, Any]:
        return {**template, "diameter_mm": d, "length_mm": ell}

    def evaluate(self, shafts: Sequence[tuple[float, float]]) -> list[Evaluated]:
        """Evaluate shafts (D, L in mm; rounded to RESOLUTION_MM), simulating only what the store
        lacks, in parallel."""
        from fsarm_sim.studies.sweep import evaluate_point

        rounded = [
            (round(d / RESOLUTION_MM) * RESOLUTION_MM, round(ell / RESOLUTION_MM) * RESOLUTION_MM)
            for d, ell in shafts
        ]
        rounded = [(round(d, 6), round(ell, 6)) for d, ell in rounded]
        new = [s for s in dict.fromkeys(rounded) if s not in self._cache]
        if new:
            with ResultStore(self.store_path) as store:
                have = {r.key: r for r in store.rows(sweep=SWEEP_NAME)}
                pts = [self._point(t, d, ell) for d, ell in new for t in self.templates]
                results: dict[str, dict[str, Any] | None] = {}
                errors: dict[str, str] = {}
                todo = []
                for p in pts:
                    row = have.get(point_key(p))
                    if row is None:
                        todo.append(p)
                    elif row.outputs is not None:
                        results[row.key] = row.outputs
                        self.stored += 1
                    else:
                        errors[row.key] = row.error or "failed"
                        self.stored += 1

                def store_one(o: Outcome) -> None:
                    store.put(
                        o.task["point"],
                        o.result,
                        sweep=SWEEP_NAME,
                        wall_s=o.wall_s,
                        error=o.error,
                        host=o.host,
                    )
                    key = point_key(o.task["point"])
                    if o.result is not None:
                        results[key] = o.result
                    else:
                        errors[key] = o.error or "failed"

                tasks = [
                    {
                        "point": p,
                        "catalogue_toml": self.text,
                        "catalogue_source": self.catalogue.source,
                        "backend": self.spec.backend,
                    }
                    for p in todo
                ]
                run_tasks(
                    evaluate_point,
                    tasks,
                    executor=self.task.executor,
                    workers=self.task.workers,
                    on_done=store_one,
                )
                self.simulations += len(todo)
            for d, ell in new:
                keys = [point_key(self._point(t, d, ell)) for t in self.templates]
                self._cache[(d, ell)] = self._judge(d, ell, [results.get(k) for k in keys], errors)
        out = [self._cache[s] for s in rounded]
        self.history.extend(self._cache[s] for s in new)
        return out

    def _judge(
        self,
        d: float,
        ell: float,
        rows: list[dict[str, Any] | None],
        errors: dict[str, str],
    ) -> Evaluated:
        if any(r is None for r in rows):
            return Evaluated(d, ell, {}, False, "simulation failed")
        ok = [r for r in rows if r is not None]
        worst: dict[str, float] = {}
        for key in (*OBJECTIVES, "peak_shaft_torque_nm"):
            worst[key] = max(float(r[key]) for r in ok)
        worst["rating_nm"] = float(ok[0]["rating_nm"])
        worst["rating_margin"] = worst["rating_nm"] / max(worst["peak_shaft_torque_nm"], 1e-12)
        why = []
        if worst["rating_margin"] < self.task.rating_margin:
            why.append(f"rating margin {worst['rating_margin']:.2f} < {self.task.rating_margin:g}")
        if self.task.bandwidth_floor_hz > 0.0:
            bws = [r.get("torque_bandwidth_hz") for r in ok]
            # NaN / None: no -3 dB point inside the analysed band, i.e. above it
            vals = [math.inf if b is None or not math.isfinite(float(b)) else float(b) for b in bws]
            worst["torque_bandwidth_hz"] = min(vals)
            if min(vals) < self.task.bandwidth_floor_hz:
                why.append(f"bandwidth {min(vals):.1f} Hz < {self.task.bandwidth_floor_hz:g} Hz")
        return Evaluated(d, ell, worst, not why, "; ".join(why))

    def score(self, e: Evaluated, objective: str) -> float:
        if e.feasible:
            return e.outputs[objective]
        if not e.outputs:
            return PENALTY * 2.0
        excess = max(0.0, self.task.rating_margin - e.outputs["rating_margin"])
        return PENALTY * (1.0 + excess)


def _scale(ev: Evaluator, x: np.ndarray) -> list[tuple[float, float]]:
    (d0, d1), (l0, l1) = ev.box
    return [(d0 + (d1 - d0) * a, l0 + (l1 - l0) * b) for a, b in np.atleast_2d(x.T)]


def optimise(
    ev: Evaluator,
    score: Callable[[Evaluated], float],
    *,
    budget: int = 96,
    seed: int = 32,
) -> Evaluated | None:
    """Differential evolution on the unit box within about ``budget`` shaft evaluations."""
    from scipy.optimize import differential_evolution

    if budget < 16:
        raise SelectionError(f"the budget must be at least 16 shaft evaluations, got {budget}")
    popsize = 4  # x 2 dimensions = 8 per generation
    de_budget = int(budget * DE_SHARE)
    maxiter = max(1, de_budget // (popsize * 2) - 1)
    start = len(ev.history)

    def f(x: np.ndarray) -> np.ndarray:  # x: (2, S) - one generation in one batch
        return np.array([score(e) for e in ev.evaluate(_scale(ev, x))])

    differential_evolution(
        f,
        [(0.0, 1.0), (0.0, 1.0)],
        popsize=popsize,
        maxiter=maxiter,
        init="sobol",
        seed=seed,
        polish=False,
        vectorized=True,
        updating="deferred",
        tol=0.0,
        mutation=(0.5, 1.0),
        recombination=0.9,
    )
    _compass(ev, score, budget - (len(ev.history) - start))
    feasible = [e for e in ev.history if e.feasible]
    return min(feasible, key=score) if feasible else None


DE_SHARE = 0.7  # of the budget; the rest polishes the best by a compass search


def _compass(ev: Evaluator, score: Callable[[Evaluated], float], budget: int) -> None:
    """Bounded compass search from the best shaft so far: the four neighbours at +-step on D and
    L (clipped to the box, so an optimum on a bound or a corner is reached), one batch each; move
    on improvement, else halve the step. Replaces SciPy's gradient polish, which the simulated
    objectives (rounded shafts, kinks) do not suit."""
    (d0, d1), (l0, l1) = ev.box
    best = min(ev.history, key=score)
    x = np.array([(best.diameter_mm - d0) / (d1 - d0), (best.length_mm - l0) / (l1 - l0)])
    fx, step, used = score(best), 0.1, 0
    while used < budget and step > 1e-3:
        cand = [
            np.clip(x + sign * step * np.eye(2)[i], 0.0, 1.0) for i in (0, 1) for sign in (1, -1)
        ]
        cand = [c for c in cand if not np.allclose(c, x)]
        if not cand:
            step /= 2.0
            continue
        got = ev.evaluate(_scale(ev, np.array(cand).T))
        used += len(cand)  # store hits count too: a resumed search takes the same path
        scores = [score(e) for e in got]
        i = int(np.argmin(scores))
        if scores[i] < fx:
            x, fx = cand[i], scores[i]
        else:
            step /= 2.0


def nearest_catalogue(
    ev: Evaluator, best: Evaluated, n: int = 3
) -> tuple[list[str], list[Evaluated]]:
    """The ``n`` catalogue shafts nearest the optimum (D and L scaled to the box), evaluated."""
    (d0, d1), (l0, l1) = ev.box
    cat: Catalogue = ev.catalogue

    def dist(s: Any) -> float:
        return math.hypot(
            (s.diameter_mm - best.diameter_mm) / (d1 - d0),
            (s.length_mm - best.length_mm) / (l1 - l0),
        )

    near = sorted(cat.shafts, key=dist)[:n]
    return [s.name for s in near], ev.evaluate([(s.diameter_mm, s.length_mm) for s in near])


def select(
    task: Task,
    store_path: str | Path,
    objective: str = "q3_rmse_deg",
    *,
    budget: int = 96,
    seed: int = 32,
) -> Search:
    """Minimise ``objective`` over D and L (module docstring)."""
    check_objective(objective)
    ev = Evaluator(task, store_path)
    best = optimise(ev, lambda e: ev.score(e, objective), budget=budget, seed=seed)
    out = Search(objective, best)
    if best is not None:
        out.nearest_names, out.nearest = nearest_catalogue(ev, best)
    out.evaluated = list(ev.history)
    out.simulations, out.stored = ev.simulations, ev.stored
    return out


def pareto_front(points: Sequence[Evaluated], a: str, b: str) -> list[Evaluated]:
    """The feasible shafts no other feasible shaft beats on both objectives (sorted by ``a``)."""
    feas = sorted((e for e in points if e.feasible), key=lambda e: (e.outputs[a], e.outputs[b]))
    front: list[Evaluated] = []
    best_b = math.inf
    for e in feas:
        if e.outputs[b] < best_b:
            front.append(e)
            best_b = e.outputs[b]
    return front


def pareto(
    task: Task,
    store_path: str | Path,
    objectives: tuple[str, str] = ("q3_rmse_deg", "motor_energy_j"),
    *,
    weights: int = 5,
    budget_each: int = 48,
    seed: int = 32,
) -> tuple[list[Evaluated], list[Evaluated], int]:
    """Weighted sums of the two objectives (each scaled by its range over the first search's
    shafts), one optimisation per weight; returns (front, every shaft evaluated, simulations)."""
    a, b = (check_objective(o) for o in objectives)
    if a == b:
        raise SelectionError("--pareto needs two different objectives")
    ev = Evaluator(task, store_path)
    optimise(ev, lambda e: ev.score(e, a), budget=budget_each, seed=seed)
    feas = [e for e in ev.history if e.feasible] or ev.history
    lo = {k: min(e.outputs.get(k, math.inf) for e in feas) for k in (a, b)}
    hi = {k: max(e.outputs.get(k, -math.inf) for e in feas) for k in (a, b)}

    def norm(e: Evaluated, k: str) -> float:
        return (e.outputs[k] - lo[k]) / max(hi[k] - lo[k], 1e-12)

    def weighted(w: float) -> Callable[[Evaluated], float]:
        def score(e: Evaluated) -> float:
            return ev.score(e, a) if not e.feasible else (1 - w) * norm(e, a) + w * norm(e, b)

        return score

    for i, w in enumerate(np.linspace(0.0, 1.0, weights)):
        if w == 0.0:
            continue  # the first search
        optimise(ev, weighted(float(w)), budget=budget_each, seed=seed + i)
    return pareto_front(ev.history, a, b), list(ev.history), ev.simulations


def grid(
    task: Task,
    store_path: str | Path,
    objective: str,
    diameters: Sequence[float],
    lengths: Sequence[float],
) -> tuple[Evaluated | None, int]:
    """The exhaustive reference: every (D, L) of the grid; returns (best feasible, points)."""
    ev = Evaluator(task, store_path)
    shafts = [(d, ell) for d in diameters for ell in lengths]
    ev.evaluate(shafts)
    feasible = [e for e in ev.history if e.feasible]
    best = min(feasible, key=lambda e: e.outputs[objective]) if feasible else None
    return best, len(shafts)


def pareto_plot(
    front: Sequence[Evaluated], evaluated: Sequence[Evaluated], a: str, b: str, path: Path
) -> Path:
    """Every feasible shaft evaluated (grey) and the front (joined), ``a`` against ``b``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    feas = [e for e in evaluated if e.feasible]
    fig, ax = plt.subplots(figsize=(6.0, 4.5))
    ax.scatter(
        [e.outputs[a] for e in feas], [e.outputs[b] for e in feas], s=8, c="0.7", label="evaluated"
    )
    ax.plot(
        [e.outputs[a] for e in front], [e.outputs[b] for e in front], "o-", c="C3", label="front"
    )
    for e in front[:: max(1, len(front) // 6)]:
        ax.annotate(
            f"{e.diameter_mm:.1f}x{e.length_mm:.0f}",
            (e.outputs[a], e.outputs[b]),
            fontsize=7,
            xytext=(4, 4),
            textcoords="offset points",
        )
    ax.set_xlabel(OBJECTIVES[a])
    ax.set_ylabel(OBJECTIVES[b])
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Pareto front over D x L (labels: D x L, mm)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def shaft_metrics(
    catalogue: Catalogue,
    *,
    diameter_mm: float,
    length_mm: float,
    scenario: str,
    payload_kg: float | None,
    duration_s: float | None,
    bends_deg: Sequence[float] = (45.0,),
    controller_catalogue: Catalogue | None = None,
) -> dict[str, float]:
    """Tracking metrics of one shaft, the worst over the bends (as the search judges a shaft;
    the bends apply to scenarios that hold joint 2): the metric ``fsarm select --uncertainty``
    bands at the optimum."""
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim import scenarios
    from fsarm_sim.studies.arm_metrics import scenario_holds_joint2, tracking

    known = controller_catalogue  # the controller's eq. 8 (None: the sampled shaft's own)
    cfg = SimConfig(
        shaft=catalogue.shaft(diameter_mm, length_mm),
        controller_shaft=None if known is None else known.shaft(diameter_mm, length_mm),
    )
    sc = scenarios.get(scenario)
    holds = scenario_holds_joint2(scenario, sc.duration_s if duration_s is None else duration_s)
    runs = [
        tracking(
            cfg,
            scenario,
            duration_s=duration_s,
            payload_kg=payload_kg,
            bend_rad=math.radians(b) if holds else None,
        )
        for b in (bends_deg if holds else bends_deg[:1])
    ]
    return {k: max(r[k] for r in runs) for k in runs[0]}
