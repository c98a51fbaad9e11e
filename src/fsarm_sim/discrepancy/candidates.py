"""Candidate models: the current model plus one (effect, variant), fitted grey-box.

Every candidate's parameters act *inside the replay* (the kernels of :mod:`.replay`), not in a
regression on residuals: the fitted model is replayed on the whole record and scored on the
held-out samples. For the blocked series bench and the parallel bench the replay is a sum of
operator outputs of the recorded input (stop operators for Maxwell-slip and Coulomb elements,
visco-elastic branch deflections, dead zone, per-sign polynomial spring), so all *amplitude*
parameters enter linearly: they are fitted jointly with the nominal parameters by bounded linear
least squares on a data matrix (seed 002 eq. 17-18). Parameters that enter nonlinearly (delay,
input offset, backlash width and centre) are found by a grid then a bounded local search around
that inner solve (variable projection). Maxwell-slip and visco-elastic hysteresis use a fixed
grid of slip deflections / time constants with non-negative stiffnesses (a Prandtl-Ishlinskii /
Prony fit); each element kept counts as two parameters.

With an inertia load the load angle is simulated, so the candidate is first fitted on the
equation error (shaft law on the measured twist, load law on the measured load motion: both
linear, same data matrices) and then refined on the output error of the full replay
(``scipy.optimize.least_squares``) - the simulation, not a regression, has the last word.

The structure, its data matrix and linear fit are :mod:`.candidate_structure`'s, the inertia
load's fit :mod:`.candidate_inertia`'s; the candidates, their refinement, backfitting and
pruning are here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection
from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import minimize, minimize_scalar

from fsarm_sim.discrepancy import replay, variants
from fsarm_sim.discrepancy.candidate_inertia import solve
from fsarm_sim.discrepancy.candidate_structure import (
    BACKLASH_C,
    BACKLASH_W,
    DELAY_BOUNDS,
    IN_OFFSET,
    Context,
    Fit,
    Structure,
    coulomb_delta_max,
    solve_static,
    split_mse,
)
from fsarm_sim.discrepancy.fit_label import labelled_as
from fsarm_sim.discrepancy.residuals import bic, effective_n

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

# ----------------------------------------------------------------------------- candidates


def _search_1d(ctx: Context, make: Any, grid: FloatArray, lo: float, hi: float) -> Fit:
    """Grid then bounded scalar refinement of one nonlinear parameter (teaching MSE); with an
    inertia load the search runs on the equation error and the winner is refined once."""
    quick = ctx.inp.inertia_load
    fits = {float(g): solve(ctx, make(float(g)), quick) for g in grid}
    g0 = min(fits, key=lambda g: fits[g].mse_teach)
    gs = sorted(fits)
    i = gs.index(g0)
    a = gs[i - 1] if i > 0 else max(lo, g0 - abs(g0))
    b = gs[i + 1] if i + 1 < len(gs) else min(hi, g0 + abs(g0))
    cache: dict[float, Fit] = dict(fits)

    def f(v: float) -> float:
        if v not in cache:
            cache[v] = solve(ctx, make(v), quick)
        return cache[v].mse_teach

    if a < b:
        minimize_scalar(
            f,
            bounds=(a, b),
            method="bounded",
            options={"xatol": 1e-3 * (b - a) + 1e-9, "maxiter": 20},
        )
    best = min(cache.values(), key=lambda fit: fit.mse_teach)
    return solve(ctx, best.structure) if quick else best


def _setting(base: Structure, name: str, to: Callable[[float], Any] | None = None) -> Any:
    """A function of v: a copy of ``base`` with its setting ``name`` = v (or ``to(v)``), the
    nonlinear parameter a 1-D search varies."""

    def make(v: float) -> Structure:
        s2 = base.copy()
        setattr(s2, name, v if to is None else to(v))
        return s2

    return make


def _switched_on(ctx: Context, base: Structure, flag: str) -> Fit | None:
    """``base`` with the term ``flag`` switched on, fitted; None if it is on already."""
    if getattr(base, flag):
        return None
    st = base.copy()
    setattr(st, flag, True)
    return solve(ctx, st)


def _coulomb(ctx: Context, base: Structure, variant: str) -> Fit | None:
    if variant != "shaft":
        return _switched_on(ctx, base, "load_coulomb")
    if base.coulomb is not None:
        return None
    lo, hi = ctx.delta_c, max(2.0 * ctx.delta_c, coulomb_delta_max(ctx.x_ref))
    grid = np.linspace(math.log(lo), math.log(hi), 5)
    make = _setting(base, "coulomb", lambda v: float(math.exp(v)))
    return _search_1d(ctx, make, grid, math.log(lo), math.log(hi))


def _viscous(ctx: Context, base: Structure, variant: str) -> Fit | None:
    return _switched_on(ctx, base, "viscous" if variant == "shaft" else "load_viscous")


def _offset(ctx: Context, base: Structure, variant: str) -> Fit | None:
    if variant == "output":
        return _switched_on(ctx, base, "out_offset")
    if variant != "input" or base.in_offset is not None:
        return None
    mags = np.array([0.003, 0.01, 0.03, 0.1, 0.3]) * ctx.x_ref
    grid = np.r_[-mags[::-1], mags]
    return _search_1d(ctx, _setting(base, "in_offset"), grid, IN_OFFSET.lower, IN_OFFSET.upper)


def _nonlinear(ctx: Context, base: Structure, variant: str) -> Fit | None:
    if base.poly is not None:
        return None
    st = base.copy()
    st.poly = variant
    return solve(ctx, st)


def _hysteresis(ctx: Context, base: Structure, variant: str) -> Fit | None:
    st = base.copy()
    if variant == "maxwell_slip":
        if base.slip is not None:
            return None
        st.slip = ctx.slip_grid.copy()
    else:
        if base.ve is not None:
            return None
        st.ve = ctx.ve_grid.copy()
    fit = solve(ctx, st)
    if (variant == "maxwell_slip" and fit.structure.slip is None) or (
        variant == "viscoelastic" and fit.structure.ve is None
    ):
        return None
    return fit


def _delay(ctx: Context, base: Structure, variant: str) -> Fit | None:
    if base.delay_s is not None:
        return None
    steps = np.array([1, 2, 3, 5, 8, 12, 20, 30, 50, 80], dtype=float) * ctx.inp.h
    steps = steps[steps <= DELAY_BOUNDS.upper]
    grid = np.r_[-steps[::-1], steps]
    make = _setting(base, "delay_s")
    return _search_1d(ctx, make, grid, DELAY_BOUNDS.lower, DELAY_BOUNDS.upper)


def _backlash(ctx: Context, base: Structure, variant: str) -> Fit | None:
    return None if base.backlash is not None else _fit_backlash(ctx, base)


# how each library effect is added to a structure (None: it does not apply or is present)
_ADD: dict[str, Callable[[Context, Structure, str], Fit | None]] = {
    variants.COULOMB: _coulomb,
    variants.VISCOUS: _viscous,
    variants.OFFSET: _offset,
    variants.NONLINEAR: _nonlinear,
    variants.HYSTERESIS: _hysteresis,
    variants.DELAY: _delay,
    variants.BACKLASH: _backlash,
}


def candidate(ctx: Context, cur: Fit, effect: str, variant: str) -> Fit | None:
    """Fit the current structure plus one effect; None if it does not apply / is present."""
    add = _ADD.get(effect)
    fit = add(ctx, cur.structure, variant) if add is not None else None
    if fit is None:
        return None
    fit.label = f"{effect}[{variant}]"
    fit.effect, fit.variant = effect, variant
    return fit


def _fit_backlash(ctx: Context, base: Structure) -> Fit:
    ws = np.geomspace(
        max(2 * ctx.sigma_u, 0.003 * ctx.x_ref), min(0.5 * ctx.x_ref, BACKLASH_W.upper), 10
    )
    cache: dict[tuple[float, float], Fit] = {}

    def fit_at(w: float, c: float) -> Fit:
        w = float(np.clip(w, 1e-6, BACKLASH_W.upper))
        c = float(np.clip(c, BACKLASH_C.lower, BACKLASH_C.upper))
        key = (round(w, 12), round(c, 12))
        if key not in cache:
            s2 = base.copy()
            s2.backlash = (w, c)
            cache[key] = solve(ctx, s2, ctx.inp.inertia_load)
        return cache[key]

    for w in ws:
        for fr in (-0.4, 0.0, 0.4):
            fit_at(w, fr * w)
    best = min(cache.values(), key=lambda f: f.mse_teach)
    assert best.structure.backlash is not None
    w0, c0 = best.structure.backlash
    minimize(
        lambda v: fit_at(v[0], v[1]).mse_teach,
        np.array([w0, c0]),
        method="Nelder-Mead",
        options={
            "initial_simplex": np.array([[w0, c0], [1.3 * w0, c0], [w0, c0 + 0.2 * w0]]),
            "xatol": 1e-3 * w0,
            "fatol": 0.0,
            "maxfev": 40,
        },
    )
    best = min(cache.values(), key=lambda f: f.mse_teach)
    return solve(ctx, best.structure) if ctx.inp.inertia_load else best


def nominal(ctx: Context) -> Fit:
    """The nominal model with its own parameters refit (no effects)."""
    fit = solve(ctx, Structure())
    fit.label = "nominal (refit)"
    return fit


def stated(ctx: Context) -> Fit:
    """The nominal model with the catalogue's parameters, as stated (no refit)."""
    yhat = replay.replay(ctx.stated, ctx.inp)["y"]
    mt, mh = split_mse(ctx, yhat)
    return Fit(Structure(), ctx.stated, yhat, None, 0, mt, mh, label="nominal (catalogue)")


ELEMENT_NFEV = 25  # element refinement: Nelder-Mead evaluations per element


def refine_elements(ctx: Context, fit: Fit) -> Fit:
    """Move the kept hysteresis elements off the fixed grid: a bounded Nelder-Mead search of the
    log slip deflections / log time constants (the amplitudes stay an inner linear solve), on the
    teaching MSE. A grid of fixed elements approximates an element between two grid points by a
    pair, and the rest of the misfit would otherwise be left for another effect to absorb. Each
    element already counts two parameters (k), so the BIC charge does not change. Blocked series
    and parallel bench (an inner solve is one linear least squares); an inertia load keeps its
    grid (each evaluation would be an output-error fit)."""
    st = fit.structure
    if ctx.inp.inertia_load or (st.slip is None and st.ve is None):
        return fit
    n_s = 0 if st.slip is None else st.slip.size
    x0 = np.log(np.r_[st.slip if st.slip is not None else [], st.ve if st.ve is not None else []])
    lo = np.r_[np.full(n_s, ctx.slip_grid[0]), np.full(x0.size - n_s, ctx.ve_grid[0])]
    hi = np.r_[np.full(n_s, ctx.slip_grid[-1]), np.full(x0.size - n_s, ctx.ve_grid[-1])]
    best = [fit]

    def f(v: FloatArray) -> float:
        s2 = st.copy()
        vals = np.exp(np.clip(v, np.log(lo), np.log(hi)))
        if n_s:
            s2.slip = np.sort(vals[:n_s])
        if vals.size > n_s:
            s2.ve = np.sort(vals[n_s:])
        fi = solve_static(ctx, s2, prune=False)
        if fi.mse_teach < best[0].mse_teach:
            best[0] = fi
        return fi.mse_teach

    minimize(
        f,
        x0,
        method="Nelder-Mead",
        bounds=list(zip(np.log(lo), np.log(hi), strict=True)),
        options={"maxfev": ELEMENT_NFEV * x0.size, "xatol": 1e-3, "fatol": 0.0},
    )
    out = best[0]
    out.label, out.effect, out.variant, out.note = fit.label, fit.effect, fit.variant, fit.note
    return out


def refine(ctx: Context, fit: Fit) -> Fit:
    """Joint refinement of the nonlinear parameters (delay, input offset, backlash, the Coulomb
    element's presliding deflection in log) of the final structure, each around its value
    (Nelder-Mead on the teaching MSE)."""
    st = fit.structure
    keys: list[str] = []
    x0: list[float] = []
    if st.delay_s is not None:
        keys.append("d")
        x0.append(st.delay_s)
    if st.in_offset is not None:
        keys.append("o")
        x0.append(st.in_offset)
    if st.backlash is not None:
        keys += ["w", "c"]
        x0 += list(st.backlash)
    if st.coulomb is not None:
        keys.append("cd")
        x0.append(math.log(st.coulomb))
    if len(keys) < 2 and not (keys and len(fit.model.effects) > 1):
        return fit
    quick = ctx.inp.inertia_load  # inertia load: search on the equation error, refine once
    best = [solve(ctx, st, True) if quick else fit]

    def f(v: FloatArray) -> float:
        s2 = st.copy()
        vals = dict(zip(keys, (float(a) for a in v), strict=True))
        if "d" in vals:
            s2.delay_s = float(np.clip(vals["d"], DELAY_BOUNDS.lower, DELAY_BOUNDS.upper))
        if "o" in vals:
            s2.in_offset = float(np.clip(vals["o"], IN_OFFSET.lower, IN_OFFSET.upper))
        if "w" in vals:
            s2.backlash = (
                float(np.clip(vals["w"], 1e-6, BACKLASH_W.upper)),
                float(np.clip(vals["c"], BACKLASH_C.lower, BACKLASH_C.upper)),
            )
        if "cd" in vals:
            hi = max(2.0 * ctx.delta_c, coulomb_delta_max(ctx.x_ref))
            s2.coulomb = float(np.clip(math.exp(vals["cd"]), ctx.delta_c, hi))
        fi = solve(ctx, s2, quick)
        if fi.mse_teach < best[0].mse_teach:
            best[0] = fi
        return fi.mse_teach

    minimize(
        f,
        np.array(x0),
        method="Nelder-Mead",
        options={"maxfev": 30 * len(keys), "xatol": 1e-6, "fatol": 0.0},
    )
    out = best[0]
    if quick:
        out = solve(ctx, out.structure)
        if out.mse_teach > fit.mse_teach:
            out = fit
    out.label, out.effect, out.variant = fit.label, fit.effect, fit.variant
    return out


# ----------------------------------------------------------------------------- backfitting

# the effects whose nonlinear setting :func:`candidate` searches, and the structure field it sits in
SEARCHED = ((variants.DELAY, "input", "delay_s"), (variants.OFFSET, "input", "in_offset"))
SEARCHED_2 = ((variants.BACKLASH, "coupling", "backlash"), (variants.COULOMB, "shaft", "coulomb"))


def backfit(ctx: Context, fit: Fit, added: str | None) -> Fit:
    """Re-search the nonlinear setting of every effect of ``fit`` other than the one just
    ``added`` (input delay, input offset, backlash width and centre, Coulomb presliding
    deflection) on top of all the others, one at a time (backfitting). Each was searched when it
    was named, with the effects named after it missing: a delay found before a Coulomb element
    absorbs part of the friction's lag, a backlash found before an output offset is off-centre.
    A re-search is kept when it lowers the teaching MSE; with two or more such settings they are
    then refined together (:func:`refine`: correlated settings, e.g. a delay and a Coulomb
    element's presliding deflection, do not reach their joint optimum one at a time). Blocked
    series and parallel bench (an inertia load's searches are output-error fits: kept as they
    are)."""
    if ctx.inp.inertia_load:
        return fit
    best = fit
    for effect, variant, attr in (*SEARCHED, *SEARCHED_2):
        if effect == added or getattr(best.structure, attr) is None:
            continue
        base = best.structure.copy()
        setattr(base, attr, None)
        f = candidate(ctx, replace(best, structure=base), effect, variant)
        if f is not None and f.mse_teach < best.mse_teach:
            best = f
    if sum(getattr(best.structure, a) is not None for _, _, a in (*SEARCHED, *SEARCHED_2)) >= 2:
        best = refine(ctx, best)  # the settings together, around the values found one at a time
    return labelled_as(best, fit)


# ----------------------------------------------------------------------------- pruning

# (effect, variant) -> (the structure field it sits in, the field's value when absent)
_FIELDS: dict[tuple[str, str], tuple[str, Any]] = {
    (variants.DELAY, "input"): ("delay_s", None),
    (variants.OFFSET, "input"): ("in_offset", None),
    (variants.OFFSET, "output"): ("out_offset", False),
    (variants.BACKLASH, "coupling"): ("backlash", None),
    (variants.COULOMB, "shaft"): ("coulomb", None),
    (variants.COULOMB, "load"): ("load_coulomb", False),
    (variants.VISCOUS, "shaft"): ("viscous", False),
    (variants.VISCOUS, "load"): ("load_viscous", False),
    (variants.NONLINEAR, "poly"): ("poly", None),
    (variants.NONLINEAR, "poly_per_sign"): ("poly", None),
    (variants.HYSTERESIS, "maxwell_slip"): ("slip", None),
    (variants.HYSTERESIS, "viscoelastic"): ("ve", None),
}


def present(st: Structure) -> list[tuple[str, str]]:
    """The (effect, variant) pairs a structure holds."""
    out = []
    for (e, v), (attr, absent) in _FIELDS.items():
        val = getattr(st, attr)
        if attr == "poly":
            if val == v:
                out.append((e, v))
        elif val is not absent and val is not False:
            out.append((e, v))
    return out


def strip(st: Structure, effect: str) -> Structure:
    """A copy of ``st`` without ``effect`` (whichever variant)."""
    s2 = st.copy()
    for (e, _v), (attr, absent) in _FIELDS.items():
        if e == effect:
            setattr(s2, attr, absent)
    return s2


def without(ctx: Context, fit: Fit, effect: str) -> Fit | None:
    """``fit``'s structure without ``effect``, refit (the other effects' nonlinear settings
    searched again: :func:`backfit`); None when it does not hold the effect."""
    if not any(e == effect for e, _ in present(fit.structure)):
        return None
    f = solve(ctx, strip(fit.structure, effect))
    f = backfit(ctx, f, None)
    f.label = f"without {effect}"
    return f


def refit_hysteresis(ctx: Context, fit: Fit, added: str | None) -> Fit:
    """The hysteresis elements of ``fit`` fitted again from their grid (and moved off it:
    :func:`refine_elements`) on top of the rest, unless hysteresis is what was just ``added``;
    kept when the teaching MSE falls. The grid fit prunes the elements that contribute little
    next to what was named before - next to an input offset standing in for an output offset
    a visco-elastic spectrum collapses to one branch - and the pruned elements do not come
    back by themselves when that stand-in is replaced."""
    best = fit
    for e, v in present(fit.structure):
        if e != variants.HYSTERESIS or added == variants.HYSTERESIS:
            continue
        g = candidate(ctx, replace(best, structure=strip(best.structure, e)), e, v)
        if g is not None:
            g = refine_elements(ctx, g)
            if g.mse_teach < best.mse_teach:
                best = g
    return labelled_as(best, fit)


SWAP_BIC = 10.0  # BIC fall (teaching and held-out) for a look-alike to replace a named effect


def _beats(ctx: Context, new: Fit, old: Fit) -> bool:
    """Does ``new`` lower the BIC by more than :data:`SWAP_BIC` against ``old`` on the teaching and
    on the held-out samples (effective counts from ``new``'s residual)?"""
    r = ctx.inp.y - new.yhat
    n_t, n_h = effective_n(r, ctx.teach), effective_n(r, ctx.held)
    d_t = bic(new.mse_teach, n_t, new.k) - bic(old.mse_teach, n_t, old.k)
    d_h = bic(new.mse_held, n_h, new.k) - bic(old.mse_held, n_h, old.k)
    return d_t < -SWAP_BIC and d_h < -SWAP_BIC


def swap_variants(
    ctx: Context,
    fit: Fit,
    pairs: list[tuple[str, str]],
    look_alikes: Collection[frozenset[str]] = (),
) -> tuple[Fit, dict[str, str]]:
    """Each effect of ``fit`` refit as each of its other applicable variants (``pairs``) on top of
    the rest - kept when it lowers the teaching *and* the held-out MSE - and as each of its
    ``look_alikes`` (an effect not in ``fit``) - kept when it lowers the BIC by more than
    :data:`SWAP_BIC` on both sample sets. What was chosen when the effect was named, with the
    effects named after it missing, can be a stand-in: an input offset for an output offset
    next to a per-sign stiffness, a visco-elastic branch at its shortest time constant for a
    damper until a Coulomb element is named. Returns (the fit, {replaced effect: its
    replacement})."""
    best = fit
    replaced: dict[str, str] = {}
    for e, v in present(fit.structure):
        if e in replaced:
            continue
        held = {x for x, _ in present(best.structure)}
        for e2, v2 in pairs:
            same = e2 == e and v2 != v
            alike = e2 != e and e2 not in held and frozenset({e, e2}) in look_alikes
            if not (same or alike):
                continue
            base = replace(best, structure=strip(best.structure, e))
            f = candidate(ctx, base, e2, v2)
            if f is None:
                continue
            f = refit_hysteresis(ctx, backfit(ctx, f, e2), e2)
            if same and f.mse_teach < best.mse_teach and f.mse_held < best.mse_held:
                best = f
            elif alike and _beats(ctx, f, best):
                best = f
                replaced[e] = e2
                break
    return labelled_as(best, fit), replaced
