"""A bench candidate's structure and its linear fit: the fit context of one dataset
(:class:`Context`), the structure of a model (nominal parameters and named effects:
:class:`Structure`), the data matrix of operator outputs its amplitude parameters multiply
(:func:`build_columns`), the model its coefficients give (:func:`to_model`) and the bounded linear
least-squares fit with hysteresis elements pruned (:func:`solve_static`). The candidates
themselves are :mod:`.candidates`'s; the inertia load's fit :mod:`.candidate_inertia`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import lsq, replay, replay_inputs, variants
from fsarm_sim.discrepancy.benchmodel import BenchModel, EffectInstance
from fsarm_sim.discrepancy.residuals import bic, effective_n, noise_floor, split_masks
from fsarm_sim.plant.effects import registry

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


N_GRID = 8  # hysteresis grid size (slip deflections / time constants)
# Coulomb friction = a slip element whose presliding deflection is below 1 % of the deflection
# range or 2 mrad (whichever is larger); slower slip elements are Maxwell-slip hysteresis.
COULOMB_MAX_DELTA = 0.01
COULOMB_MAX_DELTA_RAD = 2e-3


def coulomb_delta_max(x_ref: float) -> float:
    return max(COULOMB_MAX_DELTA * x_ref, COULOMB_MAX_DELTA_RAD)


VE_MIN_TAU_S = 0.02
NOMINAL_RANGE = 4.0  # inertia load: refit stiffness within this factor of the catalogue's
INERTIA_RANGE = 2.0  # ... and the load inertia within this factor of the stated one
PRUNE_FRACTION = 0.002  # hysteresis elements contributing less than this x rms(y) are dropped
K_BOUNDS = registry.get(variants.HYSTERESIS).variant("maxwell_slip").params[0]
DELAY_BOUNDS = registry.get(variants.DELAY).variant("input").params[0]
BACKLASH_W = registry.get(variants.BACKLASH).variant("coupling").params[0]
BACKLASH_C = registry.get(variants.BACKLASH).variant("coupling").params[1]
IN_OFFSET = registry.get(variants.OFFSET).variant("input").params[0]
POLY_C = registry.get(variants.NONLINEAR).variant("poly").params[0]


@dataclass
class Context:
    """Everything the fits share for one dataset."""

    inp: replay_inputs.ReplayInputs
    teach: BoolArray
    held: BoolArray
    sigma_y: float  # noise floor of the main output
    sigma_u: float  # noise floor of the input deflection
    x_ref: float  # reference deflection: 99.5th percentile of |input deflection|
    multi_bend: bool  # series bench: the bend angle varies in the record
    delta_c: float  # smallest presliding deflection of the Coulomb element (above input noise)
    slip_grid: FloatArray
    ve_grid: FloatArray
    stated: BenchModel  # nominal model with the catalogue / sidecar parameters
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def setup(self) -> str:
        return self.inp.setup


def make_context(inp: replay_inputs.ReplayInputs, stated: BenchModel) -> Context:
    teach, held = split_masks(inp.n)
    s_meas = inp.theta_s_smooth if inp.inertia_load and inp.theta_s_smooth is not None else inp.s
    xr = inp.u - s_meas  # the deflection the shaft law sees (input - output angle)
    x_ref = float(np.quantile(np.abs(xr), 0.995)) or 1.0
    sigma_u = noise_floor(inp.u)  # of the (smoothed) input the elements see
    delta_c = replay.presliding_delta(sigma_u)
    span = max(x_ref, 10 * delta_c)
    # slip deflections up to 80 % of the largest deflection in the record: an element that never
    # slips is a linear spring (it only adds to K), one that slips at the extremes is not
    slip_lo = max(3.0 * delta_c, coulomb_delta_max(x_ref))
    x_max = float(np.max(np.abs(xr))) if xr.size else span
    slip_grid = np.geomspace(slip_lo, max(0.8 * x_max, 0.5 * span, 4.0 * slip_lo), N_GRID)
    dur = float(inp.t[-1] - inp.t[0])
    # Visco-elastic branches faster than VE_MIN_TAU_S act as viscous damping plus an inertia
    # correction (k w ~ k tau x' - k tau^2 x''): by the definition of `hysteresis` (a loop *not*
    # explained by viscous damping) they are left to the viscous candidate.
    tau_lo = max(VE_MIN_TAU_S, 20 * inp.h)
    ve_grid = np.geomspace(tau_lo, min(20.0, max(5 * tau_lo, dur / 5.0)), N_GRID)
    multi = inp.setup == "series_bench" and float(np.ptp(inp.phi)) > math.radians(3.0)
    return Context(
        inp=inp,
        teach=teach,
        held=held,
        sigma_y=noise_floor(inp.y, lines=True),
        sigma_u=sigma_u,
        x_ref=x_ref,
        multi_bend=multi,
        delta_c=delta_c,
        slip_grid=slip_grid,
        ve_grid=ve_grid,
        stated=stated,
    )


# ----------------------------------------------------------------------------- structure


@dataclass(eq=False)
class Structure:
    """The terms of a model and its nonlinear settings."""

    delay_s: float | None = None
    in_offset: float | None = None
    backlash: tuple[float, float] | None = None
    coulomb: float | None = None  # presliding deflection of the Coulomb element, rad
    viscous: bool = False
    poly: str | None = None  # "poly" | "poly_per_sign"
    slip: FloatArray | None = None  # slip deflections of the Maxwell-slip elements
    ve: FloatArray | None = None  # time constants of the visco-elastic branches
    out_offset: bool = False
    load_coulomb: bool = False  # inertia load only
    load_viscous: bool = False

    def copy(self) -> Structure:
        return replace(
            self,
            slip=None if self.slip is None else self.slip.copy(),
            ve=None if self.ve is None else self.ve.copy(),
        )


@dataclass(eq=False)
class Fit:
    structure: Structure
    model: BenchModel
    yhat: FloatArray
    theta_hat: FloatArray | None
    k: int
    mse_teach: float
    mse_held: float
    label: str = "nominal"
    effect: str | None = None
    variant: str | None = None
    note: str = ""


def n_params(ctx: Context, st: Structure) -> int:
    """Fitted parameters of a structure (the BIC's k)."""
    if ctx.setup == "series_bench":
        k = 4 if ctx.multi_bend else 2
        if ctx.inp.inertia_load:
            k += 1
    else:
        k = 2
    k += int(st.delay_s is not None) + int(st.in_offset is not None)
    k += 2 * int(st.backlash is not None)
    k += 2 * int(st.coulomb is not None) + int(st.viscous) + int(st.out_offset)
    k += int(st.load_coulomb) + int(st.load_viscous)
    k += {"poly": 2, "poly_per_sign": 4}.get(st.poly or "", 0)
    k += 2 * (0 if st.slip is None else st.slip.size)
    k += 2 * (0 if st.ve is None else st.ve.size)
    return k


# ----------------------------------------------------------------------------- data matrix


@dataclass
class Columns:
    a: FloatArray  # n x m
    names: list[str]
    lower: FloatArray
    upper: FloatArray


def deflections(ctx: Context, st: Structure) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(x, x_dot, input acceleration) the shaft law sees under a structure's input transform."""
    inp = ctx.inp
    x_in = replay.shifted_inputs(inp, st.delay_s or 0.0, -(st.in_offset or 0.0))
    if inp.inertia_load:
        s = inp.theta_s_smooth if inp.theta_s_smooth is not None else inp.theta_s
        assert s is not None
        sdot = replay_inputs.derivative(s, inp.h)
    else:
        s, sdot = inp.s, inp.sdot
    xr = x_in.u - s
    xrd = x_in.udot - sdot
    if st.backlash is not None:
        x, xd = replay.dead_zone(xr, xrd, st.backlash[0], st.backlash[1])
    else:
        x, xd = xr, xrd
    return x, xd, x_in.uacc


def build_columns(
    ctx: Context, st: Structure, x: FloatArray, xd: FloatArray, uacc: FloatArray
) -> Columns:
    cols: list[FloatArray] = []
    names: list[str] = []
    lo: list[float] = []
    hi: list[float] = []

    def add(name: str, col: FloatArray, lower: float, upper: float) -> None:
        cols.append(col)
        names.append(name)
        lo.append(lower)
        hi.append(upper)

    inf = math.inf
    if ctx.setup == "series_bench":
        xp = np.maximum(x, 0.0)
        xn = np.minimum(x, 0.0)
        add("k_pos", xp, 0.0, inf)
        add("k_neg", xn, 0.0, inf)
        if ctx.multi_bend:
            ph = np.abs(ctx.inp.phi)
            add("s_pos", ph * xp, -inf, inf)
            add("s_neg", ph * xn, -inf, inf)
    else:
        add("kb", x, 0.0, inf)
        add("j_link", uacc, 0.0, 10.0)
    if st.poly is not None:
        r = x / ctx.x_ref
        q2, q3 = r * np.abs(r), r * r * r
        lo_c, hi_c = POLY_C.lower, POLY_C.upper
        if st.poly == "poly":
            add("c2_nm", q2, lo_c, hi_c)
            add("c3_nm", q3, lo_c, hi_c)
        else:
            pos = x >= 0.0
            add("c2_pos_nm", np.where(pos, q2, 0.0), lo_c, hi_c)
            add("c3_pos_nm", np.where(pos, q3, 0.0), lo_c, hi_c)
            add("c2_neg_nm", np.where(~pos, q2, 0.0), lo_c, hi_c)
            add("c3_neg_nm", np.where(~pos, q3, 0.0), lo_c, hi_c)
    if st.coulomb is not None:
        z = replay.stop_columns(x, np.array([st.coulomb]))[:, 0] / st.coulomb
        add("f_c_nm", z, 0.0, 20.0)
    if st.viscous:
        add("b_nms", xd, 0.0, 20.0)
    if st.slip is not None and st.slip.size:
        z = replay.stop_columns(x, st.slip)
        for j in range(st.slip.size):
            add(f"slip{j}", z[:, j], 0.0, K_BOUNDS.upper)
    if st.ve is not None and st.ve.size:
        w = replay.branch_columns(x, st.ve, ctx.inp.h)
        for j in range(st.ve.size):
            add(f"ve{j}", w[:, j], 0.0, K_BOUNDS.upper)
    if st.out_offset:
        add("offset_nm", np.ones_like(x), -20.0, 20.0)
    return Columns(np.column_stack(cols), names, np.array(lo), np.array(hi))


def solve_columns(cols: Columns, y: FloatArray, rows: BoolArray) -> FloatArray:
    """Bounded linear least squares on the rows (columns scaled to unit RMS; reduced to k x k
    first, :mod:`fsarm_sim.discrepancy.lsq`)."""
    return _solve_rows(cols.a[rows], y[rows], cols.lower, cols.upper)


def _solve_rows(a: FloatArray, y: FloatArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """:func:`solve_columns` on the rows already taken; ``a`` is a copy, scaled in place."""
    scale = np.sqrt(np.mean(a * a, axis=0))
    scale[scale == 0.0] = 1.0
    np.divide(a, scale, out=a)
    x = lsq.bounded(a, y, lower * scale, upper * scale)
    return np.asarray(x / scale, dtype=np.float64)


# ----------------------------------------------------------------------------- coefficients -> model


def to_model(ctx: Context, st: Structure, coef: dict[str, float]) -> BenchModel:
    """The bench model (nominal + effects) of a structure with fitted coefficients."""
    m = ctx.stated.copy()
    m.effects = []
    _set_nominal(ctx, m, coef)
    m.effects.extend(_coupling_effects(ctx, st, coef))
    m.effects.extend(_hysteresis_effects(st, coef))
    if st.out_offset:
        m.effects.append(
            EffectInstance(variants.OFFSET, "output", {"offset_nm": coef["offset_nm"]})
        )
    return m


def _set_nominal(ctx: Context, m: BenchModel, coef: dict[str, float]) -> None:
    """The fitted nominal parameters into ``m``."""
    if ctx.setup == "series_bench":
        if ctx.multi_bend:
            for k in ("k_pos", "s_pos", "k_neg", "s_neg"):
                m.nominal[k] = coef[k]
        else:  # one bend angle: K(phi0) is fitted; keep the catalogue's slope for other bends
            ph0 = float(np.median(np.abs(ctx.inp.phi)))
            for side in ("pos", "neg"):
                m.nominal[f"k_{side}"] = coef[f"k_{side}"] - m.nominal.get(f"s_{side}", 0.0) * ph0
        if "j_load" in coef:
            m.nominal["j_load"] = coef["j_load"]
    else:
        m.nominal["kb"] = coef["kb"]
        m.nominal["j_link"] = coef["j_link"]


def _coupling_effects(ctx: Context, st: Structure, coef: dict[str, float]) -> list[EffectInstance]:
    """The structure's delay, offset, backlash, nonlinear stiffness and friction, fitted."""
    out: list[EffectInstance] = []
    if st.delay_s is not None:
        out.append(EffectInstance(variants.DELAY, "input", {"delay_s": st.delay_s}))
    if st.in_offset is not None:
        out.append(EffectInstance(variants.OFFSET, "input", {"offset_rad": st.in_offset}))
    if st.backlash is not None:
        out.append(
            EffectInstance(
                variants.BACKLASH,
                "coupling",
                {"width_rad": st.backlash[0], "center_rad": st.backlash[1]},
            )
        )
    if st.poly == "poly":
        out.append(
            EffectInstance(
                variants.NONLINEAR,
                "poly",
                {"c2_nm": coef["c2_nm"], "c3_nm": coef["c3_nm"], "x_ref_rad": ctx.x_ref},
            )
        )
    elif st.poly == "poly_per_sign":
        p = {k: coef[k] for k in ("c2_pos_nm", "c3_pos_nm", "c2_neg_nm", "c3_neg_nm")}
        p["x_ref_rad"] = ctx.x_ref
        out.append(EffectInstance(variants.NONLINEAR, "poly_per_sign", p))
    if st.coulomb is not None:
        out.append(
            EffectInstance(
                variants.COULOMB,
                "shaft",
                {"f_c_nm": coef["f_c_nm"], "delta_rad": st.coulomb},
            )
        )
    if st.viscous:
        out.append(EffectInstance(variants.VISCOUS, "shaft", {"b_nms": coef["b_nms"]}))
    if st.load_coulomb:
        out.append(EffectInstance(variants.COULOMB, "load", {"f_c_nm": coef["f_load_nm"]}))
    if st.load_viscous:
        out.append(EffectInstance(variants.VISCOUS, "load", {"b_nms": coef["b_load_nms"]}))
    return out


def _hysteresis_effects(st: Structure, coef: dict[str, float]) -> list[EffectInstance]:
    """The structure's slip and viscoelastic elements, fitted."""
    out: list[EffectInstance] = []
    for variant, grid, prefix, key in (
        ("maxwell_slip", st.slip, "slip", "delta_rad"),
        ("viscoelastic", st.ve, "ve", "tau_s"),
    ):
        if grid is not None and grid.size:
            k = [coef[f"{prefix}{j}"] for j in range(grid.size)]
            out.append(
                EffectInstance(
                    variants.HYSTERESIS, variant, {"k_nm_per_rad": k, key: [float(g) for g in grid]}
                )
            )
    return out


def split_mse(ctx: Context, yhat: FloatArray) -> tuple[float, float]:
    if not np.all(np.isfinite(yhat)):  # a candidate whose replay diverged fits nothing
        return math.inf, math.inf
    r = ctx.inp.y - yhat
    return float(np.mean(r[ctx.teach] ** 2)), float(np.mean(r[ctx.held] ** 2))


def prune_elements(ctx: Context, st: Structure, coef: dict[str, float], cols: Columns) -> Structure:
    """Drop hysteresis elements that carry (almost) nothing, then - backward elimination - each
    element whose removal lowers the teaching BIC (an element costs two parameters: with strongly
    correlated residuals the effective sample count is small and so is the evidence per element).
    ``coef`` is :func:`solve_columns` of all of ``cols`` on ``ctx.inp.y`` and the teaching rows
    (it is not solved again)."""
    thr = PRUNE_FRACTION * float(np.std(ctx.inp.y))
    active = []
    for key, arr in (("slip", st.slip), ("ve", st.ve)):
        if arr is None:
            continue
        for j in range(arr.size):
            col = cols.a[:, cols.names.index(f"{key}{j}")]
            if coef[f"{key}{j}"] * float(np.std(col)) > thr:
                active.append(f"{key}{j}")
    hyst = {n for n in cols.names if n.startswith(("slip", "ve"))}
    fixed = [i for i, n in enumerate(cols.names) if n not in hyst]
    y, rows = ctx.inp.y, ctx.teach
    a_rows, y_rows = cols.a[rows], y[rows]  # taken once; each fit takes its columns from these

    everything = list(range(len(cols.names)))

    def fit(names: list[str]) -> tuple[float, FloatArray]:
        idx = fixed + [cols.names.index(n) for n in names]
        if idx == everything and len(coef) == len(cols.names):  # the caller's solve: reuse it
            r = y - cols.a @ np.array([coef[n] for n in cols.names])
            return float(np.mean(r[rows] ** 2)), r
        c = _solve_rows(a_rows[:, idx], y_rows, cols.lower[idx], cols.upper[idx])
        r = y - cols.a[:, idx] @ c
        return float(np.mean(r[rows] ** 2)), r

    if len(active) > 1:
        mse, r = fit(active)
        n_eff = effective_n(r, rows)
        best = bic(mse, n_eff, 2 * len(active))
        while len(active) > 1:
            trials = []
            for name in active:
                rest = [a for a in active if a != name]
                trials.append((bic(fit(rest)[0], n_eff, 2 * len(rest)), name))
            b, name = min(trials)
            if b >= best:
                break
            best = b
            active.remove(name)
    out = st.copy()
    for key, arr in (("slip", st.slip), ("ve", st.ve)):
        if arr is None:
            continue
        keep = [j for j in range(arr.size) if f"{key}{j}" in active]
        setattr(out, key, arr[keep] if keep else None)
    return out


def solve_static(ctx: Context, st: Structure, prune: bool = True) -> Fit:
    """Fit all linear parameters of a structure (blocked series / parallel bench); replay it."""
    inp = ctx.inp
    x, xd, uacc = deflections(ctx, st)
    cols = build_columns(ctx, st, x, xd, uacc)
    c = solve_columns(cols, inp.y, ctx.teach)
    coef = dict(zip(cols.names, (float(v) for v in c), strict=True))
    model = to_model(ctx, st, coef)
    if prune and (st.slip is not None or st.ve is not None):
        st2 = prune_elements(ctx, st, coef, cols)
        if (
            (st2.slip is None) != (st.slip is None)
            or (st2.ve is None) != (st.ve is None)
            or (st2.slip is not None and st.slip is not None and st2.slip.size != st.slip.size)
            or (st2.ve is not None and st.ve is not None and st2.ve.size != st.ve.size)
        ):
            return solve_static(ctx, st2, prune=False)
    yhat = replay.replay(model, inp)["y"]
    mt, mh = split_mse(ctx, yhat)
    return Fit(st, model, yhat, None, n_params(ctx, st), mt, mh)
