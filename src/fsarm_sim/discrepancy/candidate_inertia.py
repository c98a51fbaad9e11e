"""A bench candidate with an inertia load: the load angle is simulated, so the candidate is first
fitted on the equation error (shaft law on the measured twist, load law on the measured load
motion: both linear, same data matrices) and then refined on the output error of the full replay
(``scipy.optimize.least_squares``, :func:`solve_inertia`). :func:`solve` fits a structure either way.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from fsarm_sim.discrepancy import replay, replay_inputs, variants
from fsarm_sim.discrepancy.benchmodel import BenchModel
from fsarm_sim.discrepancy.candidate_structure import (
    INERTIA_RANGE,
    K_BOUNDS,
    NOMINAL_RANGE,
    POLY_C,
    Columns,
    Context,
    Fit,
    Structure,
    build_columns,
    deflections,
    n_params,
    prune_elements,
    solve_columns,
    solve_static,
    split_mse,
    to_model,
)

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

# ----------------------------------------------------------------------------- inertia load


def _load_equation(ctx: Context, st: Structure, offset_nm: float = 0.0) -> dict[str, float]:
    """Load law on the measured load motion: tau_s = J th'' + b th' + F sgn(th') (sliding)."""
    inp = ctx.inp
    assert inp.theta_s is not None
    om = inp.omega_s if inp.omega_s is not None else replay_inputs.derivative(inp.theta_s, inp.h)
    acc = (
        inp.alpha_s if inp.alpha_s is not None else replay_inputs.derivative(inp.theta_s, inp.h, 2)
    )
    thr = 0.05 * float(np.std(om))
    rows = ctx.teach & (np.abs(om) > thr)
    cols = [acc]
    names = ["j_load"]
    lo, hi = [0.0], [math.inf]
    if st.load_viscous:
        cols.append(om)
        names.append("b_load_nms")
        lo.append(0.0)
        hi.append(20.0)
    if st.load_coulomb:
        cols.append(np.sign(om))
        names.append("f_load_nm")
        lo.append(0.0)
        hi.append(20.0)
    c = Columns(np.column_stack(cols), names, np.array(lo), np.array(hi))
    coef = solve_columns(c, inp.y - offset_nm, rows)
    return dict(zip(names, (float(v) for v in coef), strict=True))


# parameters refined on the output error, with their bounds
_OE_BOUNDS: dict[str, tuple[float, float]] = {
    "k_pos": (1e-3, 1e4),
    "k_neg": (1e-3, 1e4),
    "s_pos": (-1e3, 1e3),
    "s_neg": (-1e3, 1e3),
    "j_load": (1e-6, 100.0),
    "f_c_nm": (0.0, 20.0),
    "b_nms": (0.0, 20.0),
    "f_load_nm": (0.0, 20.0),
    "b_load_nms": (0.0, 20.0),
    "offset_nm": (-20.0, 20.0),
    "c2_nm": (POLY_C.lower, POLY_C.upper),
    "c3_nm": (POLY_C.lower, POLY_C.upper),
    "c2_pos_nm": (POLY_C.lower, POLY_C.upper),
    "c3_pos_nm": (POLY_C.lower, POLY_C.upper),
    "c2_neg_nm": (POLY_C.lower, POLY_C.upper),
    "c3_neg_nm": (POLY_C.lower, POLY_C.upper),
}


def _coef_of_model(ctx: Context, st: Structure, m: BenchModel) -> dict[str, float]:
    """Inverse of to_model for the continuous parameters (inertia-load refinement)."""
    c: dict[str, float] = {}
    nom = m.nominal
    ph0 = 0.0 if ctx.multi_bend else float(np.median(np.abs(ctx.inp.phi)))
    for side in ("pos", "neg"):
        c[f"k_{side}"] = nom[f"k_{side}"] + nom.get(f"s_{side}", 0.0) * ph0
        if ctx.multi_bend:
            c[f"s_{side}"] = nom.get(f"s_{side}", 0.0)
    c["j_load"] = nom.get("j_load", m.load_inertia_kgm2 or 0.0)
    for e in m.effects:
        p = e.params
        if e.name == variants.COULOMB:
            c["f_c_nm" if e.variant == "shaft" else "f_load_nm"] = p["f_c_nm"]
        elif e.name == variants.VISCOUS:
            c["b_nms" if e.variant == "shaft" else "b_load_nms"] = p["b_nms"]
        elif e.name == variants.OFFSET and e.variant == "output":
            c["offset_nm"] = p["offset_nm"]
        elif e.name == variants.NONLINEAR:
            for k, v in p.items():
                if k.startswith("c"):
                    c[k] = v
        elif e.name == variants.HYSTERESIS:
            key = "slip" if e.variant == "maxwell_slip" else "ve"
            for j, v in enumerate(p["k_nm_per_rad"]):
                c[f"{key}{j}"] = v
    return c


def _equation_error(ctx: Context, st: Structure) -> tuple[BenchModel, Structure, float]:
    """Inertia load, equation error: shaft law on the measured twist (a linear solve, as for a
    blocked output) and load law on the measured load motion. Returns the model, the (pruned)
    structure and the teaching MSE of the shaft equation."""
    inp = ctx.inp
    shaft_st = replace(st, load_coulomb=False, load_viscous=False)
    x, xd, uacc = deflections(ctx, shaft_st)
    cols = build_columns(ctx, shaft_st, x, xd, uacc)
    c = solve_columns(cols, inp.y, ctx.teach)
    coef = dict(zip(cols.names, (float(v) for v in c), strict=True))
    if st.slip is not None or st.ve is not None:
        st2 = prune_elements(ctx, shaft_st, coef, cols)
        st = replace(st2, load_coulomb=st.load_coulomb, load_viscous=st.load_viscous)
        shaft_st = replace(st, load_coulomb=False, load_viscous=False)
        cols = build_columns(ctx, shaft_st, x, xd, uacc)
        c = solve_columns(cols, inp.y, ctx.teach)
        coef = dict(zip(cols.names, (float(v) for v in c), strict=True))
    pred = cols.a @ np.array([coef[nm] for nm in cols.names])
    mse = float(np.mean((inp.y - pred)[ctx.teach] ** 2))
    coef.update(_load_equation(ctx, st, coef.get("offset_nm", 0.0)))
    return to_model(ctx, st, coef), st, mse


OE_NFEV = 25  # output-error refinement: function evaluations (the Jacobian's not counted)
OE_NFEV_SCREEN = 8  # ... while screening the candidates of a step (the winner is redone)


def solve_inertia(
    ctx: Context, st: Structure, quick: bool = False, max_nfev: int | None = None
) -> Fit:
    """Inertia load: equation-error fit, then (unless ``quick``) output-error refinement of all
    continuous parameters on the segmented replay (:func:`.replay.replay`)."""
    inp = ctx.inp
    model, st, mse_eq = _equation_error(ctx, st)
    if quick:  # searches over nonlinear parameters: rank by the shaft equation's error
        return Fit(st, model, inp.y, None, n_params(ctx, st), mse_eq, mse_eq)
    coef = _coef_of_model(ctx, st, model)
    names = list(coef)
    bounds = dict(_OE_BOUNDS)
    # the nominal refit stays plausible: stiffness within 4x of the catalogue, the stated load
    # inertia "loosely" (within 2x) - an output-error search with an effect still missing can
    # otherwise wander to a shaft that transmits nothing
    cat = _coef_of_model(ctx, Structure(), ctx.stated)
    for k in ("k_pos", "k_neg"):
        bounds[k] = (cat[k] / NOMINAL_RANGE, cat[k] * NOMINAL_RANGE)
    if ctx.stated.load_inertia_kgm2:
        j = ctx.stated.load_inertia_kgm2
        bounds["j_load"] = (j / INERTIA_RANGE, j * INERTIA_RANGE)
    lo = np.array([bounds.get(k, (0.0, K_BOUNDS.upper))[0] for k in names])
    hi = np.array([bounds.get(k, (0.0, K_BOUNDS.upper))[1] for k in names])
    x0 = np.clip(np.array([coef[k] for k in names]), lo, hi)
    floor = {
        "f_c_nm": 0.01,
        "b_nms": 0.001,
        "f_load_nm": 0.01,
        "b_load_nms": 0.001,
        "offset_nm": 0.01,
    }
    scale = np.array(
        [max(abs(v), floor.get(k, 1e-3 * max(1.0, abs(v)))) for k, v in zip(names, x0, strict=True)]
    )
    rows = ctx.teach

    def build(v: FloatArray) -> BenchModel:
        return to_model(ctx, st, dict(zip(names, (float(a) for a in v), strict=True)))

    def resid(v: FloatArray) -> FloatArray:
        r = (inp.y - replay.replay(build(v), inp)["y"])[rows]
        if not np.all(np.isfinite(r)):  # diverged: a large, finite penalty keeps TRF away
            return np.full(r.size, 1e3 * float(np.std(inp.y)) + 1.0)
        return r

    note = ""
    try:
        res = least_squares(
            resid,
            x0,
            bounds=(lo, hi),
            x_scale=scale,
            max_nfev=max_nfev or int(ctx.options.get("oe_nfev", OE_NFEV)),
            method="trf",
            diff_step=1e-3,
        )
        best = res.x if float(np.mean(res.fun**2)) <= float(np.mean(resid(x0) ** 2)) else x0
    except ValueError as exc:  # numerical trouble in a candidate: keep the equation-error fit
        best = x0
        note = f"output-error refinement failed: {exc}"
    model = build(best)
    yhat = replay.replay(model, inp)["y"]
    mt, mh = split_mse(ctx, yhat)
    f = Fit(st, model, yhat, None, n_params(ctx, st), mt, mh)
    f.note = note
    return f


def solve(ctx: Context, st: Structure, quick: bool = False) -> Fit:
    """Fit a structure; ``quick`` (inertia load only): equation error, no output-error refinement."""
    return solve_inertia(ctx, st, quick) if ctx.inp.inertia_load else solve_static(ctx, st)
