"""The arm's candidate effects and the steps that screen them: every candidate solved jointly
with the model's present parameters on one secant Jacobian per step (:func:`step_jacobian`,
bounded linear least squares), re-simulated, the most promising refined on the simulation
(:func:`step_candidates`); the nominal refit first (:func:`nominal_fit`). The replay, the model
context and the refinement are :mod:`.arm_fit`'s.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import variants
from fsarm_sim.discrepancy.arm_fit import (
    N_REFINE,
    N_SLIP_GRID,
    NOMINAL_ITER,
    ArmContext,
    ArmFit,
    bounds_of,
    evaluate,
    jacobian_column,
    linear_solve,
    nominal_keys,
    refine,
    refine_many,
    secant_model,
)
from fsarm_sim.discrepancy.arm_model import BOUNDS, NOMINAL_DEFAULTS, NOMINAL_KEYS, ArmModel
from fsarm_sim.discrepancy.arm_run import ArmReplayError

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


# ----------------------------------------------------------------------------- candidates

PLANT_CANDIDATES = tuple(
    (name, v.key)
    for name, vs in variants.ARM.items()
    if name not in variants.ARM_RECORDING
    for v in vs
)
MEASUREMENT_CANDIDATES = tuple(
    (name, v.key) for name, vs in variants.ARM.items() if name in variants.ARM_RECORDING for v in vs
)


def candidate_pairs(ctx: ArmContext) -> list[tuple[str, str]]:
    skip = set()
    if ctx.run.payload_tolerance_kg > 0.0:  # the payload is already refit as a nominal parameter
        skip.add(variants.PAYLOAD)
    if not ctx.run.flexible_shaft:  # slip elements are the flexible shaft's states
        skip.add(variants.HYSTERESIS)
    return [(e, v) for e, v in PLANT_CANDIDATES + MEASUREMENT_CANDIDATES if e not in skip]


def candidate_keys(ctx: ArmContext, effect: str, variant: str) -> list[str]:
    if effect == variants.HYSTERESIS:
        return [f"{effect}.k{i}" for i in range(N_SLIP_GRID)]
    if effect in variants.ARM_RECORDING:
        return [f"{effect}.{variant}"]
    params = [p.name for p in variants.ARM[effect][0].params]
    if effect == variants.BACKLASH and not ctx.two_sided:
        # a one-sided twist sees only one flank: the centre is not defined
        params = params[:1]
    return [f"{effect}.{p}" for p in params]


def add_candidate(ctx: ArmContext, m: ArmModel, effect: str, variant: str) -> ArmModel:
    out = m.copy()
    out.labels.append(f"{effect}[{variant}]")
    for k in candidate_keys(ctx, effect, variant):
        out.values[k] = 0.0
    if effect == variants.HYSTERESIS:
        out.set_slip([0.0] * len(ctx.slip_grid), [float(d) for d in ctx.slip_grid])
    return out


def prune_slip(ctx: ArmContext, m: ArmModel) -> tuple[ArmModel, list[int]]:
    """Drop hysteresis elements with (almost) no stiffness: below 1 % of the shaft's K.
    Returns the model and the grid indices of the elements kept (renumbered 0, 1, ...)."""
    k_ref = 0.01 * max(ctx.run.shaft.k_pos, ctx.run.shaft.k_neg)
    deltas = m.slip_delta
    keep = [i for i in range(len(deltas)) if m.v(f"hysteresis.k{i}") > k_ref]
    out = m.copy()
    out.set_slip([m.v(f"hysteresis.k{i}") for i in keep], [deltas[i] for i in keep])
    return out, keep


@dataclass
class StepJacobian:
    """One linearisation per step: columns for present and candidate parameters."""

    cols: dict[str, FloatArray]
    r0: FloatArray


def jacobian_runs(
    ctx: ArmContext, model: ArmModel, free: Sequence[str], pairs: Sequence[tuple[str, str]]
) -> list[ArmModel | None]:
    """The secant runs :func:`step_jacobian` needs at ``model`` with the free parameters
    ``free`` (to simulate several linearisations' runs side by side)."""
    runs = [secant_model(ctx, model, k) for k in free]
    for e, v in pairs:
        trial = add_candidate(ctx, model, e, v)
        runs += [secant_model(ctx, trial, k) for k in candidate_keys(ctx, e, v)]
    return runs


def step_jacobian(ctx: ArmContext, cur: ArmFit, pairs: list[tuple[str, str]]) -> StepJacobian:
    """Secant columns at the current model for its free parameters and every candidate's
    (candidates enter at zero, so the current prediction is their base point)."""
    cols: dict[str, FloatArray] = {}
    ctx.prefetch(jacobian_runs(ctx, cur.model, cur.free, pairs))
    for k in cur.free:
        col = jacobian_column(ctx, cur.model, cur.pred, cur.raw, k)
        if col is not None:
            cols[k] = col
    for e, v in pairs:
        trial = add_candidate(ctx, cur.model, e, v)
        for k in candidate_keys(ctx, e, v):
            if k not in cols:
                col = jacobian_column(ctx, trial, cur.pred, cur.raw, k)
                if col is not None:
                    cols[k] = col
    return StepJacobian(cols, ctx.wresid(cur.pred, ctx.teach))


def screen_solve(
    ctx: ArmContext, sj: StepJacobian, cur: ArmFit, effect: str, variant: str
) -> tuple[ArmModel, list[str], FloatArray] | None:
    """The linearised joint solve of the present parameters plus one candidate: (model, free
    parameters, linearised residual), not yet re-simulated."""
    new = candidate_keys(ctx, effect, variant)
    keys = list(cur.free) + new
    if any(k not in sj.cols for k in keys):
        return None
    jac = np.column_stack([sj.cols[k] for k in keys])
    m0 = add_candidate(ctx, cur.model, effect, variant)
    m = linear_solve(ctx, m0, keys, jac, sj.r0)
    units = np.array([bounds_of(ctx, k)[2] for k in keys])
    du = np.array([m.v(k) - m0.v(k) for k in keys]) / units
    r_lin = sj.r0 + jac @ du
    free = keys
    if effect == variants.HYSTERESIS:
        m, keep = prune_slip(ctx, m)
        if not keep:
            return None
        free = list(cur.free) + [f"hysteresis.k{j}" for j in range(len(keep))]
    return m, free, r_lin


def screen(
    ctx: ArmContext, sj: StepJacobian, cur: ArmFit, effect: str, variant: str
) -> ArmFit | None:
    """Linearised joint solve of the present parameters plus one candidate, re-simulated."""
    solved = screen_solve(ctx, sj, cur, effect, variant)
    if solved is None:
        return None
    m, free, r_lin = solved
    f = evaluate(ctx, m, free, f"{effect}[{variant}]")
    if f is None:
        return None
    f.effect, f.variant = effect, variant
    f.predicted = float(r_lin @ r_lin)
    return f


# ----------------------------------------------------------------------------- nominal and steps


def nominal_fit(ctx: ArmContext) -> tuple[ArmFit, ArmFit]:
    """(catalogue, refit nominal): the stated model, then its own parameters refit."""
    keys = nominal_keys(ctx)
    m = ArmModel()
    for k in keys:
        m.values.setdefault(k, NOMINAL_DEFAULTS.get(k, 0.0))
    ctx.prefetch([ArmModel(), m])  # the catalogue and the refit's start (often the same run)
    cat = evaluate(ctx, ArmModel(), [], "nominal (catalogue)")
    if cat is None:
        raise ArmReplayError(
            f"{ctx.ds.path}: the nominal replay of the run fails (diverges or MuJoCo warns); "
            "check the sidecar's shaft, payload, gains and ctrl_dt_s"
        )
    if not keys:
        return cat, replace(cat, label="nominal (refit)")
    start = evaluate(ctx, m, keys, "nominal (refit)")
    assert start is not None
    ctx.prefetch([secant_model(ctx, m, k) for k in keys])
    cols = [jacobian_column(ctx, m, start.pred, start.raw, k) for k in keys]
    if any(c is None for c in cols):
        return cat, replace(cat, label="nominal (refit)")
    jac = np.column_stack([c for c in cols if c is not None])
    lin = evaluate(ctx, linear_solve(ctx, m, keys, jac, ctx.wresid(start.pred, ctx.teach)), keys)
    best = start if lin is None or lin.cost >= start.cost else lin
    best.label = "nominal (refit)"
    best = refine(ctx, best, NOMINAL_ITER)
    best.label = "nominal (refit)"
    return cat, best


def stated_nominal_model(fit: ArmFit) -> ArmModel | None:
    """The fit's model with the nominal parameters back at their stated values (None when they
    are there already, within 2 %)."""
    m = fit.model.copy()
    moved = False
    for k in NOMINAL_KEYS:
        if k in m.values:
            ref = NOMINAL_DEFAULTS.get(k, 0.0)
            unit = BOUNDS[k][2]
            moved = moved or abs(m.values[k] - ref) > 0.2 * unit
            m.values[k] = ref
    return m if moved else None


def stated_nominal(ctx: ArmContext, fit: ArmFit) -> ArmFit | None:
    """:func:`stated_nominal_model` simulated (None when the nominal parameters are at their
    stated values already, within 2 %, or the run fails)."""
    m = stated_nominal_model(fit)
    return None if m is None else evaluate(ctx, m, fit.free, fit.label)


def start_runs(
    ctx: ArmContext,
    cur: ArmFit,
    pairs: Sequence[tuple[str, str]],
    alt_pairs: Sequence[tuple[str, str]],
) -> list[ArmModel | None]:
    """The runs of the linearisations from ``cur`` (``pairs``) and from its stated nominal
    (:func:`stated_nominal_model`, ``alt_pairs``): the stated nominal itself and both
    :func:`jacobian_runs`, to be simulated side by side. (Should the stated nominal's own run
    fail, its secant runs were in vain: a failure path, not worth a step of its own.)"""
    runs = jacobian_runs(ctx, cur.model, cur.free, pairs)
    alt = stated_nominal_model(cur)
    if alt is not None:
        runs += [alt, *jacobian_runs(ctx, alt, cur.free, alt_pairs)]
    return runs


def screen_all(ctx: ArmContext, cur: ArmFit, pairs: list[tuple[str, str]]) -> list[ArmFit]:
    """Every candidate linearised and solved from the current model and - when the nominal refit
    moved away from the stated values - also from the stated nominal (a refit nominal can mimic
    an effect, e.g. a softer shaft a heavier payload: the two valleys are not joined by a
    straight line); the better start per candidate is kept."""
    plant = {e for e, _ in PLANT_CANDIDATES}
    alt_pairs = [(e, v) for e, v in pairs if e in plant]
    # both starts' runs side by side, then both starts' candidates' re-simulations
    # (stated_nominal(), step_jacobian() and screen() then find them run)
    ctx.prefetch(start_runs(ctx, cur, pairs, alt_pairs))
    starts = [cur]
    alt = stated_nominal(ctx, cur)
    if alt is not None:
        starts.append(alt)
    subs = [pairs, alt_pairs][: len(starts)]
    sjs = [step_jacobian(ctx, st, sub) for st, sub in zip(starts, subs, strict=True)]
    ctx.prefetch(
        [
            s[0]
            for st, sub, sj in zip(starts, subs, sjs, strict=True)
            for s in (screen_solve(ctx, sj, st, e, v) for e, v in sub)
            if s is not None
        ]
    )
    best: dict[tuple[str, str], ArmFit] = {}
    for start, sub, sj in zip(starts, subs, sjs, strict=True):
        for e, v in sub:
            s = screen(ctx, sj, start, e, v)
            if s is not None and ((e, v) not in best or s.cost < best[(e, v)].cost):
                best[(e, v)] = s
    return list(best.values())


def step_candidates(ctx: ArmContext, cur: ArmFit, named: Sequence[str]) -> list[ArmFit]:
    """Every candidate effect not in ``named`` fitted on top of ``cur`` (:func:`screen_all`);
    the best variant of the N_REFINE most promising effects then refined on the simulation
    itself (promise: the lower of the re-simulated and the linearly predicted cost - a
    candidate that the linearisation rates well but the re-simulation not is a nonlinear one)."""
    pairs = [(e, v) for e, v in candidate_pairs(ctx) if e not in named]
    screened = screen_all(ctx, cur, pairs)

    def promise(f: ArmFit) -> float:
        return min(f.cost, f.predicted)

    best_of: dict[str, ArmFit] = {}
    for f in screened:
        if f.effect not in best_of or promise(f) < promise(best_of[f.effect or ""]):
            best_of[f.effect or ""] = f
    lead = sorted(best_of.values(), key=promise)[:N_REFINE]
    fits = list(screened)
    starts = []
    for f in lead:
        g = f
        if f.effect == variants.HYSTERESIS:  # the slip deflections leave their grid values
            n_el = len(f.model.slip_delta)
            g = replace(f, free=f.free + [f"hysteresis.d{i}" for i in range(n_el)])
        starts.append(g)
    for f, r in zip(lead, refine_many(ctx, starts), strict=True):
        fits = [r if x is f else x for x in fits]
    return fits
