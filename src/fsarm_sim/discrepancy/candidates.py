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
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares, minimize, minimize_scalar

from fsarm_sim.discrepancy import lsq
from fsarm_sim.discrepancy import replay as R
from fsarm_sim.discrepancy import variants as V
from fsarm_sim.discrepancy.benchmodel import BenchModel, EffectInstance
from fsarm_sim.discrepancy.fit_label import labelled_as
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
K_BOUNDS = registry.get(V.HYSTERESIS).variant("maxwell_slip").params[0]
DELAY_BOUNDS = registry.get(V.DELAY).variant("input").params[0]
BACKLASH_W = registry.get(V.BACKLASH).variant("coupling").params[0]
BACKLASH_C = registry.get(V.BACKLASH).variant("coupling").params[1]
IN_OFFSET = registry.get(V.OFFSET).variant("input").params[0]
POLY_C = registry.get(V.NONLINEAR).variant("poly").params[0]


@dataclass
class Context:
    """Everything the fits share for one dataset."""

    inp: R.ReplayInputs
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


def make_context(inp: R.ReplayInputs, stated: BenchModel) -> Context:
    teach, held = split_masks(inp.n)
    s_meas = inp.theta_s_smooth if inp.inertia_load and inp.theta_s_smooth is not None else inp.s
    xr = inp.u - s_meas  # the deflection the shaft law sees (input - output angle)
    x_ref = float(np.quantile(np.abs(xr), 0.995)) or 1.0
    sigma_u = noise_floor(inp.u)  # of the (smoothed) input the elements see
    delta_c = R.presliding_delta(sigma_u)
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


def _deflection(ctx: Context, st: Structure) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(x, x_dot, input acceleration) the shaft law sees under a structure's input transform."""
    inp = ctx.inp
    x_in = R.shifted_inputs(inp, st.delay_s or 0.0, -(st.in_offset or 0.0))
    if inp.inertia_load:
        s = inp.theta_s_smooth if inp.theta_s_smooth is not None else inp.theta_s
        assert s is not None
        sdot = R.derivative(s, inp.h)
    else:
        s, sdot = inp.s, inp.sdot
    xr = x_in.u - s
    xrd = x_in.udot - sdot
    if st.backlash is not None:
        x, xd = R.dead_zone(xr, xrd, st.backlash[0], st.backlash[1])
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
        z = R.stop_columns(x, np.array([st.coulomb]))[:, 0] / st.coulomb
        add("f_c_nm", z, 0.0, 20.0)
    if st.viscous:
        add("b_nms", xd, 0.0, 20.0)
    if st.slip is not None and st.slip.size:
        z = R.stop_columns(x, st.slip)
        for j in range(st.slip.size):
            add(f"slip{j}", z[:, j], 0.0, K_BOUNDS.upper)
    if st.ve is not None and st.ve.size:
        w = R.branch_columns(x, st.ve, ctx.inp.h)
        for j in range(st.ve.size):
            add(f"ve{j}", w[:, j], 0.0, K_BOUNDS.upper)
    if st.out_offset:
        add("offset_nm", np.ones_like(x), -20.0, 20.0)
    return Columns(np.column_stack(cols), names, np.array(lo), np.array(hi))


def solve_columns(cols: Columns, y: FloatArray, rows: BoolArray) -> FloatArray:
    """Bounded linear least squares on the rows (columns scaled to unit RMS; reduced to k x k
    first, :mod:`fsarm_sim.discrepancy.lsq`)."""
    a = cols.a[rows]
    scale = np.sqrt(np.mean(a * a, axis=0))
    scale[scale == 0.0] = 1.0
    x = lsq.bounded(a / scale, y[rows], cols.lower * scale, cols.upper * scale)
    return np.asarray(x / scale, dtype=np.float64)


# ----------------------------------------------------------------------------- coefficients -> model


def to_model(ctx: Context, st: Structure, coef: dict[str, float]) -> BenchModel:
    """The bench model (nominal + effects) of a structure with fitted coefficients."""
    m = ctx.stated.copy()
    m.effects = []
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
    if st.delay_s is not None:
        m.effects.append(EffectInstance(V.DELAY, "input", {"delay_s": st.delay_s}))
    if st.in_offset is not None:
        m.effects.append(EffectInstance(V.OFFSET, "input", {"offset_rad": st.in_offset}))
    if st.backlash is not None:
        m.effects.append(
            EffectInstance(
                V.BACKLASH,
                "coupling",
                {"width_rad": st.backlash[0], "center_rad": st.backlash[1]},
            )
        )
    if st.poly == "poly":
        m.effects.append(
            EffectInstance(
                V.NONLINEAR,
                "poly",
                {"c2_nm": coef["c2_nm"], "c3_nm": coef["c3_nm"], "x_ref_rad": ctx.x_ref},
            )
        )
    elif st.poly == "poly_per_sign":
        p = {k: coef[k] for k in ("c2_pos_nm", "c3_pos_nm", "c2_neg_nm", "c3_neg_nm")}
        p["x_ref_rad"] = ctx.x_ref
        m.effects.append(EffectInstance(V.NONLINEAR, "poly_per_sign", p))
    if st.coulomb is not None:
        m.effects.append(
            EffectInstance(
                V.COULOMB,
                "shaft",
                {"f_c_nm": coef["f_c_nm"], "delta_rad": st.coulomb},
            )
        )
    if st.viscous:
        m.effects.append(EffectInstance(V.VISCOUS, "shaft", {"b_nms": coef["b_nms"]}))
    if st.load_coulomb:
        m.effects.append(EffectInstance(V.COULOMB, "load", {"f_c_nm": coef["f_load_nm"]}))
    if st.load_viscous:
        m.effects.append(EffectInstance(V.VISCOUS, "load", {"b_nms": coef["b_load_nms"]}))
    if st.slip is not None and st.slip.size:
        m.effects.append(
            EffectInstance(
                V.HYSTERESIS,
                "maxwell_slip",
                {
                    "k_nm_per_rad": [coef[f"slip{j}"] for j in range(st.slip.size)],
                    "delta_rad": [float(d) for d in st.slip],
                },
            )
        )
    if st.ve is not None and st.ve.size:
        m.effects.append(
            EffectInstance(
                V.HYSTERESIS,
                "viscoelastic",
                {
                    "k_nm_per_rad": [coef[f"ve{j}"] for j in range(st.ve.size)],
                    "tau_s": [float(t) for t in st.ve],
                },
            )
        )
    if st.out_offset:
        m.effects.append(EffectInstance(V.OFFSET, "output", {"offset_nm": coef["offset_nm"]}))
    return m


def _mse(ctx: Context, yhat: FloatArray) -> tuple[float, float]:
    if not np.all(np.isfinite(yhat)):  # a candidate whose replay diverged fits nothing
        return math.inf, math.inf
    r = ctx.inp.y - yhat
    return float(np.mean(r[ctx.teach] ** 2)), float(np.mean(r[ctx.held] ** 2))


def _prune(ctx: Context, st: Structure, coef: dict[str, float], cols: Columns) -> Structure:
    """Drop hysteresis elements that carry (almost) nothing, then - backward elimination - each
    element whose removal lowers the teaching BIC (an element costs two parameters: with strongly
    correlated residuals the effective sample count is small and so is the evidence per element)."""
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

    def fit(names: list[str]) -> tuple[float, FloatArray]:
        idx = fixed + [cols.names.index(n) for n in names]
        sub = Columns(
            cols.a[:, idx], [cols.names[i] for i in idx], cols.lower[idx], cols.upper[idx]
        )
        c = solve_columns(sub, y, rows)
        r = y - sub.a @ c
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
    x, xd, uacc = _deflection(ctx, st)
    cols = build_columns(ctx, st, x, xd, uacc)
    c = solve_columns(cols, inp.y, ctx.teach)
    coef = dict(zip(cols.names, (float(v) for v in c), strict=True))
    model = to_model(ctx, st, coef)
    if prune and (st.slip is not None or st.ve is not None):
        st2 = _prune(ctx, st, coef, cols)
        if (
            (st2.slip is None) != (st.slip is None)
            or (st2.ve is None) != (st.ve is None)
            or (st2.slip is not None and st.slip is not None and st2.slip.size != st.slip.size)
            or (st2.ve is not None and st.ve is not None and st2.ve.size != st.ve.size)
        ):
            return solve_static(ctx, st2, prune=False)
    yhat = R.replay(model, inp)["y"]
    mt, mh = _mse(ctx, yhat)
    return Fit(st, model, yhat, None, n_params(ctx, st), mt, mh)


# ----------------------------------------------------------------------------- inertia load


def _load_equation(ctx: Context, st: Structure, offset_nm: float = 0.0) -> dict[str, float]:
    """Load law on the measured load motion: tau_s = J th'' + b th' + F sgn(th') (sliding)."""
    inp = ctx.inp
    assert inp.theta_s is not None
    om = inp.omega_s if inp.omega_s is not None else R.derivative(inp.theta_s, inp.h)
    acc = inp.alpha_s if inp.alpha_s is not None else R.derivative(inp.theta_s, inp.h, 2)
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
        if e.name == V.COULOMB:
            c["f_c_nm" if e.variant == "shaft" else "f_load_nm"] = p["f_c_nm"]
        elif e.name == V.VISCOUS:
            c["b_nms" if e.variant == "shaft" else "b_load_nms"] = p["b_nms"]
        elif e.name == V.OFFSET and e.variant == "output":
            c["offset_nm"] = p["offset_nm"]
        elif e.name == V.NONLINEAR:
            for k, v in p.items():
                if k.startswith("c"):
                    c[k] = v
        elif e.name == V.HYSTERESIS:
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
    x, xd, uacc = _deflection(ctx, shaft_st)
    cols = build_columns(ctx, shaft_st, x, xd, uacc)
    c = solve_columns(cols, inp.y, ctx.teach)
    coef = dict(zip(cols.names, (float(v) for v in c), strict=True))
    if st.slip is not None or st.ve is not None:
        st2 = _prune(ctx, shaft_st, coef, cols)
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
        r = (inp.y - R.replay(build(v), inp)["y"])[rows]
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
    yhat = R.replay(model, inp)["y"]
    mt, mh = _mse(ctx, yhat)
    f = Fit(st, model, yhat, None, n_params(ctx, st), mt, mh)
    f.note = note
    return f


def solve(ctx: Context, st: Structure, quick: bool = False) -> Fit:
    """Fit a structure; ``quick`` (inertia load only): equation error, no output-error refinement."""
    return solve_inertia(ctx, st, quick) if ctx.inp.inertia_load else solve_static(ctx, st)


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


def candidate(ctx: Context, cur: Fit, effect: str, variant: str) -> Fit | None:
    """Fit the current structure plus one effect; None if it does not apply / is present."""
    base = cur.structure
    st = base.copy()
    h = ctx.inp.h
    if effect == V.COULOMB:
        if variant == "shaft":
            if base.coulomb is not None:
                return None
            lo, hi = ctx.delta_c, max(2.0 * ctx.delta_c, coulomb_delta_max(ctx.x_ref))

            def make_c(v: float) -> Structure:
                s2 = base.copy()
                s2.coulomb = float(math.exp(v))
                return s2

            grid = np.linspace(math.log(lo), math.log(hi), 5)
            fit = _search_1d(ctx, make_c, grid, math.log(lo), math.log(hi))
        else:
            if base.load_coulomb:
                return None
            st.load_coulomb = True
            fit = solve(ctx, st)
    elif effect == V.VISCOUS:
        if variant == "shaft":
            if base.viscous:
                return None
            st.viscous = True
        else:
            if base.load_viscous:
                return None
            st.load_viscous = True
        fit = solve(ctx, st)
    elif effect == V.OFFSET and variant == "output":
        if base.out_offset:
            return None
        st.out_offset = True
        fit = solve(ctx, st)
    elif effect == V.NONLINEAR:
        if base.poly is not None:
            return None
        st.poly = variant
        fit = solve(ctx, st)
    elif effect == V.HYSTERESIS:
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
    elif effect == V.DELAY:
        if base.delay_s is not None:
            return None
        steps = np.array([1, 2, 3, 5, 8, 12, 20, 30, 50, 80], dtype=float) * h
        steps = steps[steps <= DELAY_BOUNDS.upper]
        grid = np.r_[-steps[::-1], steps]

        def make_d(v: float) -> Structure:
            s2 = base.copy()
            s2.delay_s = v
            return s2

        fit = _search_1d(ctx, make_d, grid, DELAY_BOUNDS.lower, DELAY_BOUNDS.upper)
    elif effect == V.OFFSET and variant == "input":
        if base.in_offset is not None:
            return None
        mags = np.array([0.003, 0.01, 0.03, 0.1, 0.3]) * ctx.x_ref
        grid = np.r_[-mags[::-1], mags]

        def make_o(v: float) -> Structure:
            s2 = base.copy()
            s2.in_offset = v
            return s2

        fit = _search_1d(ctx, make_o, grid, IN_OFFSET.lower, IN_OFFSET.upper)
    elif effect == V.BACKLASH:
        if base.backlash is not None:
            return None
        fit = _fit_backlash(ctx, base)
    else:
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
    yhat = R.replay(ctx.stated, ctx.inp)["y"]
    mt, mh = _mse(ctx, yhat)
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
SEARCHED = ((V.DELAY, "input", "delay_s"), (V.OFFSET, "input", "in_offset"))
SEARCHED_2 = ((V.BACKLASH, "coupling", "backlash"), (V.COULOMB, "shaft", "coulomb"))


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
    (V.DELAY, "input"): ("delay_s", None),
    (V.OFFSET, "input"): ("in_offset", None),
    (V.OFFSET, "output"): ("out_offset", False),
    (V.BACKLASH, "coupling"): ("backlash", None),
    (V.COULOMB, "shaft"): ("coulomb", None),
    (V.COULOMB, "load"): ("load_coulomb", False),
    (V.VISCOUS, "shaft"): ("viscous", False),
    (V.VISCOUS, "load"): ("load_viscous", False),
    (V.NONLINEAR, "poly"): ("poly", None),
    (V.NONLINEAR, "poly_per_sign"): ("poly", None),
    (V.HYSTERESIS, "maxwell_slip"): ("slip", None),
    (V.HYSTERESIS, "viscoelastic"): ("ve", None),
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
        if e != V.HYSTERESIS or added == V.HYSTERESIS:
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
