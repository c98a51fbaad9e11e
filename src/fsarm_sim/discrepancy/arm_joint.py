"""The arm's pairs for the core's joint search (:func:`.core_joint.joint_step`, issue 16).

Two arm effects can hide each other so well that neither earns its place alone: a heavier
payload next to Coulomb friction at joint 3 (the payload alone settles at a fraction of its
mass with a far too soft bend, and the nominal refit already ran to a wrong stiffness and K_b),
a damper next to a payload error, Coulomb friction next to a backlash. The core's generic pair
search extends each of the best single fits by a second effect - from those single fits, which
sit in the wrong valley. :func:`pair_candidates` fits every pair *together from the start*:

1. from the current model and - when its nominal parameters moved away from the stated ones -
   from the stated nominal (:func:`.arm_screen.stated_nominal`), one secant Jacobian each
   (:func:`.arm_screen.step_jacobian`: the columns of every candidate, cached runs),
2. each pair (not both on the recording: offsets and delays on recorded channels add up
   linearly, a greedy step finds them) solved linearised with the present parameters
   (bounded least squares) and re-simulated,
3. the :data:`N_REFINE_PAIRS` most promising pairs (lower of re-simulated and linearly
   predicted cost, as :func:`.arm_screen.step_candidates`) refined on the simulation itself
   (:func:`.arm_fit.refine`, :data:`PAIR_ITER` Gauss-Newton iterations: the pair's valley is
   far from where it starts).

Each pair comes back once (the better start) as (members, fit); the core judges it (the
combination and each member on top of the other earn their places).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from fsarm_sim.discrepancy import variants
from fsarm_sim.discrepancy.arm_fit import (
    ArmContext,
    ArmFit,
    bounds_of,
    evaluate,
    linear_solve,
    refine,
    refine_many,
)
from fsarm_sim.discrepancy.arm_model import ArmModel
from fsarm_sim.discrepancy.arm_screen import (
    StepJacobian,
    add_candidate,
    candidate_keys,
    candidate_pairs,
    prune_slip,
    screen,
    screen_solve,
    start_runs,
    stated_nominal,
    step_jacobian,
)
from fsarm_sim.discrepancy.fit_label import labelled_as

N_REFINE_PAIRS = 4  # pairs refined on the simulation (estimate: the runtime budget, issue 16)
PAIR_ITER = 6  # Gauss-Newton iterations of a pair's refinement (two starts measured: 3-5 used)

Member = tuple[str, str]


def pair_solve(
    ctx: ArmContext, sj: StepJacobian, cur: ArmFit, a: Member, b: Member
) -> tuple[ArmModel, list[str], float] | None:
    """The linearised joint solve of the present parameters plus two candidates: (model, free
    parameters, linearly predicted cost), not yet re-simulated."""
    m0 = add_candidate(ctx, add_candidate(ctx, cur.model, *a), *b)
    keys = list(cur.free) + candidate_keys(ctx, *a) + candidate_keys(ctx, *b)
    if any(k not in sj.cols for k in keys):
        return None
    jac = np.column_stack([sj.cols[k] for k in keys])
    m = linear_solve(ctx, m0, keys, jac, sj.r0)
    units = np.array([bounds_of(ctx, k)[2] for k in keys])
    du = np.array([m.v(k) - m0.v(k) for k in keys]) / units
    r_lin = sj.r0 + jac @ du
    free = keys
    if variants.HYSTERESIS in (a[0], b[0]):
        m, keep = prune_slip(ctx, m)
        if not keep:
            return None
        free = [k for k in keys if not k.startswith("hysteresis.")]
        free += [f"hysteresis.k{j}" for j in range(len(keep))]
    return m, free, float(r_lin @ r_lin)


def pair_candidates(
    ctx: ArmContext, cur: ArmFit, named: Sequence[str], effects: Sequence[str] | None = None
) -> list[tuple[list[Member], ArmFit]]:
    """Every pair of candidate effects not in ``named`` (of ``effects`` when given) fitted
    together on top of ``cur`` (module docstring): [(members, fit)], one per pair of effects."""
    pool = [
        (e, v)
        for e, v in candidate_pairs(ctx)
        if e not in named and (effects is None or e in effects)
    ]
    pairs = [
        (a, b)
        for a, b in itertools.combinations(pool, 2)
        if a[0] != b[0] and not (a[0] in variants.ARM_RECORDING and b[0] in variants.ARM_RECORDING)
    ]
    ctx.prefetch(start_runs(ctx, cur, pool, pool))  # both starts' linearisations side by side
    starts = [cur]
    alt = stated_nominal(ctx, cur)
    if alt is not None:
        starts.append(alt)
    solved: list[tuple[Member, Member, ArmModel, list[str], float]] = []
    for start in starts:
        sj = step_jacobian(ctx, start, pool)
        for a, b in pairs:
            s = pair_solve(ctx, sj, start, a, b)
            if s is not None:
                solved.append((a, b, *s))
    ctx.prefetch([s[2] for s in solved])
    best: dict[frozenset[str], tuple[float, list[Member], ArmFit]] = {}
    for a, b, m, free, predicted in solved:
        f = evaluate(ctx, m, free, f"{a[0]}[{a[1]}] + {b[0]}[{b[1]}]")
        if f is None:
            continue
        f.predicted = predicted
        key = frozenset({a[0], b[0]})
        promise = min(f.cost, predicted)
        if key not in best or promise < best[key][0]:
            best[key] = (promise, [a, b], f)
    ranked = sorted(best.values(), key=lambda x: x[0])
    lead: list[ArmFit] = []
    for _, members, f in ranked[:N_REFINE_PAIRS]:
        if any(e == variants.HYSTERESIS for e, _ in members):  # the deflections leave their grid
            n_el = len(f.model.slip_delta)
            f = replace(f, free=f.free + [f"hysteresis.d{j}" for j in range(n_el)])
        lead.append(f)
    refined = refine_many(ctx, lead, PAIR_ITER)  # the pairs' refinements side by side
    out: list[tuple[list[Member], ArmFit]] = []
    for i, (_, members, f) in enumerate(ranked):
        if i < N_REFINE_PAIRS:
            f = refined[i]
        f.effect, f.variant = members[0][0], members[0][1]
        out.append((members, f))
    return out


def without(ctx: ArmContext, fit: ArmFit, effect: str, refit: bool = True) -> ArmFit | None:
    """``fit``'s model without ``effect`` (its parameters and label), the remaining free
    parameters refined on the simulation (:func:`.arm_fit.refine`; ``refit`` False: as they
    are); None when the model does not hold the effect or its run fails."""
    labels = [lab for lab in fit.model.labels if not lab.startswith(effect + "[")]
    if len(labels) == len(fit.model.labels):
        return None
    m = ArmModel(
        {k: v for k, v in fit.model.values.items() if not k.startswith(effect + ".")}, labels
    )
    free = [k for k in fit.free if not k.startswith(effect + ".")]
    f = evaluate(ctx, m, free, f"without {effect}")
    if f is None:
        return None
    if refit:
        f = refine(ctx, f)
    f.label = f"without {effect}"
    return f


def twist_equivalent(ctx: ArmContext, fit: ArmFit) -> list[ArmFit]:
    """Each offset on one of joint 3's two encoders moved to the other with the same twist
    (``twist = theta_m - i_G2 q3``: an offset o on q3 is -i_G2 o on theta_m), the rest of ``fit``
    as it is, re-simulated but not refined: starts for a swap of the offset's channel beside the
    linearised one. Next to hysteresis, whose elements take up a twist bias, the linearised start
    of the other encoder's offset begins from a model that already absorbed the bias and stays
    there (arm expert battery: a theta_m offset of 2 mrad named as a q3 offset of -0.22 mrad);
    from the equivalent start the refinement reaches the true channel. Empty without such an
    offset."""
    pair = {"q3": ("theta_m", -ctx.coef_s), "theta_m": ("q3", -1.0 / ctx.coef_s)}
    out = []
    for lab in fit.model.labels:
        effect, variant = lab[:-1].split("[")
        old_key = f"{effect}.{variant}"
        if effect != variants.OFFSET or variant not in pair or old_key not in fit.model.values:
            continue
        other, factor = pair[variant]
        new_key = f"{effect}.{other}"
        lo, hi, _ = bounds_of(ctx, new_key)
        values = {k: v for k, v in fit.model.values.items() if k != old_key}
        values[new_key] = min(max(factor * fit.model.values[old_key], lo), hi)
        labels = [f"{effect}[{other}]" if x == lab else x for x in fit.model.labels]
        free = [new_key if k == old_key else k for k in fit.free]
        f = evaluate(ctx, ArmModel(values, labels), free, fit.label)
        if f is not None:
            f.effect, f.variant = effect, other
            out.append(f)
    return out


def swap_variants(ctx: ArmContext, fit: ArmFit) -> tuple[ArmFit, dict[str, str]]:
    """Each named effect with other arm variants (an offset or a delay: on which recorded
    channel) refit as each of them on top of the rest: the other variant solved linearised from
    the model without the effect, then refined on the simulation; kept when it lowers the
    teaching *and* the held-out cost. What was chosen when the effect was named can be a
    stand-in: next to hysteresis elements, which hold a twist bias of their own, a motor-encoder
    offset was named as a small joint-3 offset. (The core's pruning; the same effects stay
    named, so nothing is replaced by another effect: the returned map is empty.)"""
    best = fit
    for lab in list(fit.model.labels):
        effect, variant = lab[:-1].split("[")
        others = [(e, v) for e, v in candidate_pairs(ctx) if e == effect and v != variant]
        base = without(ctx, best, effect, refit=False) if others else None
        if base is None:
            continue
        sj = step_jacobian(ctx, base, others)
        ctx.prefetch(
            [s[0] for s in (screen_solve(ctx, sj, base, e, v) for e, v in others) if s is not None]
        )
        screened = [screen(ctx, sj, base, e, v) for e, v in others]
        other_variants = {v for _, v in others}
        screened += [f for f in twist_equivalent(ctx, best) if f.variant in other_variants]
        # the variants' refinements side by side (each from the same model without the effect,
        # or from the other encoder's twist-equivalent offset)
        for f in refine_many(ctx, [f for f in screened if f is not None]):
            if f.cost < best.cost and f.w(ctx) < best.w(ctx):
                best = f
    return labelled_as(best, fit), {}
