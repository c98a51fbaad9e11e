"""Hysteresis on the arm: one more slip element where the record asks for it.

The candidate screen fits the elements' stiffnesses on a fixed grid of slip deflections
(:data:`.arm_fit.N_SLIP_GRID` of them, 0.05-0.5 of the twist's range: ``make_context``), drops
those that take no stiffness (:func:`.arm_screen.prune_slip`), and the refinement then moves the
deflections it kept. A loop made of elements that slip at quite different twists - a
Maxwell-slip model of a real shaft has several - is then often fitted by one element at a
compromise deflection, which leaves the residual at the loop's corners many times the noise
floor and the record flagged ``unexplained`` although the right effects were named (the arm
expert battery: k = 4 N*m/rad slipping at 2 mrad plus 2 N*m/rad at 5 mrad fitted as one element
of 3.9 N*m/rad at 4.3 mrad, q3 left at 21x its noise floor).

:func:`grow` therefore tries, while the final model holds fewer than ``N_SLIP_GRID`` elements,
one more element: below the smallest kept deflection and above the largest, half a grid step and
a whole one away on each side (the screen's own grid ratio, ``GRID_RATIO``: the refinement of a
slip deflection finds its way only from a start near the true one), started at half the
stiffness of its neighbour (**estimate**: a start, the refinement moves it). The four are refined
with every other free parameter (:func:`.arm_fit.refine_many`, side by side); the one that fits
the held-out blocks best is kept only if it earns its place by the rule of an *extra* effect
(:func:`.selection.judge` against the current model: BIC on the teaching and on the held-out
blocks, explained part above the noise) - the bar every effect has to clear - and is then refined
once more. A round costs four refinements; a record whose loop the kept elements describe keeps
its model (the tries are refused), the same fit.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from fsarm_sim.discrepancy.arm_fit import (
    N_SLIP_GRID,
    ArmContext,
    ArmFit,
    evaluate,
    refine,
    refine_many,
)
from fsarm_sim.discrepancy.arm_screen import prune_slip
from fsarm_sim.discrepancy.selection import MIN_EXPLAINED_EXTRA, Judgement

# the slip-deflection grid's step (make_context: N_SLIP_GRID values from 0.05 to 0.5 of the range)
GRID_RATIO = (0.5 / 0.05) ** (1.0 / (N_SLIP_GRID - 1))
# where a new element starts, as factors on the neighbour's deflection: half a grid step and a
# whole one (the refinement of slip deflections finds its way from a start near the true one
# only: two starts per side)
START_STEPS = (math.sqrt(GRID_RATIO), GRID_RATIO)
START_FRACTION = 0.5  # a new element's first stiffness, of its neighbour's (estimate: a start)


@dataclass(frozen=True)
class Added:
    """One slip element :func:`grow` added, as the report gives it."""

    delta_rad: float  # its slip deflection after the refinement
    k_nm_per_rad: float  # its stiffness after the refinement
    d_bic_teach: float  # BIC change of the model with it against the model without it
    d_bic_held: float
    explained_over_noise: float  # held-out MSE it removes, in units of the noise variance
    # True: the tried element took no stiffness and was dropped again, but its refinement moved
    # the kept elements to a better fit (delta_rad, k_nm_per_rad: the element that moved most)
    moved_only: bool = False

    def text(self) -> str:
        """The verdict's words for it."""
        bic = f"BIC {self.d_bic_teach:+.0f} teaching / {self.d_bic_held:+.0f} held-out"
        if self.moved_only:
            return (
                "hysteresis: its slip elements moved (the search for one more element found a "
                f"better fit of the same ones, {bic})"
            )
        return (
            f"hysteresis: a slip element of {self.k_nm_per_rad:.3g} N·m/rad at "
            f"{1000 * self.delta_rad:.3g} mrad added ({bic})"
        )


def _slip(fit: ArmFit) -> tuple[list[float], list[float]]:
    deltas = list(fit.model.slip_delta)
    return [fit.model.v(f"hysteresis.k{i}") for i in range(len(deltas))], deltas


def _free(fit: ArmFit, n: int) -> list[str]:
    """``fit``'s free parameters with the stiffness and deflection of ``n`` elements."""
    free = [p for p in fit.free if not p.startswith("hysteresis.")]
    return free + [f"hysteresis.k{i}" for i in range(n)] + [f"hysteresis.d{i}" for i in range(n)]


def _with_element(ctx: ArmContext, fit: ArmFit, k_new: float, d_new: float) -> ArmFit | None:
    """``fit``'s model with one more element, every element's k and d free (not refined)."""
    ks, ds = _slip(fit)
    m = fit.model.copy()
    m.set_slip([*ks, k_new], [*ds, d_new])
    f = evaluate(ctx, m, _free(fit, len(ds) + 1), fit.label)
    if f is not None:
        f.effect, f.variant = fit.effect, fit.variant
    return f


def grow(
    ctx: ArmContext, fit: ArmFit, judge: Callable[[ArmFit, ArmFit], Judgement]
) -> tuple[ArmFit, list[Added]]:
    """``fit`` with slip elements added while one more earns its place (module docstring);
    ``judge(current, candidate)`` is the diagnosis' rule for an extra effect. Returns the final
    fit and what was added (nothing: ``fit`` itself)."""
    added: list[Added] = []
    cur = fit
    while True:
        ks, ds = _slip(cur)
        if not ds or len(ds) >= N_SLIP_GRID:
            return cur, added
        i_lo = min(range(len(ds)), key=lambda i: ds[i])
        i_hi = max(range(len(ds)), key=lambda i: ds[i])
        starts = [
            _with_element(ctx, cur, START_FRACTION * ks[i], ds[i] * r)
            for i, sign in ((i_lo, -1.0), (i_hi, 1.0))
            for r in (step**sign for step in START_STEPS)
        ]
        tried = refine_many(ctx, [s for s in starts if s is not None])
        # ranked on the held-out blocks, as the diagnosis ranks its candidates
        best = min(tried, key=lambda f: f.w(ctx), default=None)
        if best is None or not math.isfinite(best.w(ctx)):
            return cur, added
        j = judge(cur, best)
        if not (j.earns_place and j.explained_over_noise >= MIN_EXPLAINED_EXTRA):
            return cur, added
        grown = _without_idle(ctx, refine(ctx, best))
        k_new, d_new = _slip(grown)
        if len(d_new) > len(ds):
            added.append(
                Added(d_new[-1], k_new[-1], j.d_bic_teach, j.d_bic_held, j.explained_over_noise)
            )
            cur = grown
            continue
        # no element more, the kept ones moved: report the one furthest from where any element
        # was, then stop
        i = max(range(len(d_new)), key=lambda n: min(abs(math.log(d_new[n] / d)) for d in ds))
        added.append(
            Added(d_new[i], k_new[i], j.d_bic_teach, j.d_bic_held, j.explained_over_noise, True)
        )
        return grown, added


def _without_idle(ctx: ArmContext, fit: ArmFit) -> ArmFit:
    """``fit`` without the elements that took no stiffness (:func:`.arm_screen.prune_slip`),
    re-simulated; ``fit`` itself when every element carries stiffness (or the run fails)."""
    m, keep = prune_slip(ctx, fit.model)
    if len(keep) == len(fit.model.slip_delta) or not keep:
        return fit
    f = evaluate(ctx, m, _free(fit, len(keep)), fit.label)
    if f is None:
        return fit
    f.effect, f.variant = fit.effect, fit.variant
    return f
