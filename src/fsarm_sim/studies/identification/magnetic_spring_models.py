"""Seed 003's identification: the spring law (eq. 1), inertia (eq. 3) and joint models A-F (Table 3).

Source: /work/shared/seeds/003_4193e96e88679a8c.txt Sec. 6.2, Tables 3-5.

* :func:`fit_spring_law` - eq. 1 fitted to experiment A's static torque-angle data at several
  ring distances d: ``tau_sp = -P(d) (b1 sin(pi/60 phi_r) + b2 sin(pi/30 phi_r) + b3 sin(pi/15
  phi_r))``, ``P = 1 + a1 d + a2 d^2 + a3 d^3 + a4 d^4``, phi_r = phi_out - phi_in in degrees.
  Bilinear in (b, a): a least-squares fit (scipy) started from the linear fit of b at P = 1.
* :func:`fit_inertia` - eq. 3 fitted to experiment B's drops: ``phi'' (m r^2 + J) = m g r -
  tau_fr`` is linear in (J, tau_fr).
* :func:`select_models` - Table 3's acceleration models A-F fitted on the teaching set and scored
  on both sets by Table 4's criteria: MSE, 1 - adjusted R^2, SE and BIC. ``tau_sp`` and J are
  known from the two fits above (Sec. 6.2: "The model of spring torque ... has already been found
  as well as the value of inertia J"); the bold (fitted) parameters are tau_fr (B), tau_fr and v
  (C), + w and x (D), + y (E), + z (F). ``w sin(phi + x)`` is fitted as ``w1 sin phi + w2 cos
  phi``. Model E's damping is on the output velocity (Table 5 and Sec. 7.2; Table 3 prints
  ``y(phi'_in)``, which Table 5 and the text do not support). The partially linearised A_L and
  F_L use ``-k_sp(d) (mod(phi_r + 60 deg, 120 deg) - 60 deg)`` (eq. 2's stiffness, restoring: the
  sign Table 3 omits) in place of eq. 1.

Criteria (n samples, k fitted parameters, residual r of the acceleration, y the measured
acceleration): MSE = mean(r^2); R^2 = 1 - SSE/SST; adjusted R^2 = 1 - (1 - R^2)(n - 1)/(n - k - 1);
SE = sqrt(SSE/(n - k)); BIC = n ln(SSE/n) + k ln(n). (Table 4 is consistent with these: its SE is
sqrt(MSE) to print precision, and its BIC/ln(MSE) gives n ~ 2e4 per set.)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError

FloatArray = npt.NDArray[np.float64]
MODELS: tuple[str, ...] = ("A", "B", "C", "D", "E", "F")
LINEARISED: tuple[str, ...] = ("AL", "FL")  # Table 3's partially linearised A_L, F_L
G_M_S2 = 9.81
V_GRID = np.geomspace(1.0, 3000.0, 36)  # tanh sharpness search (s/rad), refined after


class ModelSelectionError(FsarmError, ValueError):
    """Identification data the seed-003 workflow cannot use (the message says why)."""


def _arr(name: str, x: npt.ArrayLike) -> FloatArray:
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise ModelSelectionError(f"{name} must be a non-empty 1-D array, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ModelSelectionError(f"{name} has NaN/inf samples")
    return a


# ---------------------------------------------------------------------------- eq. 1 (exp. A)


@dataclass(frozen=True)
class SpringLaw:
    """Eq. 1's coefficients (b in N m, a in 1/m^k)."""

    b: tuple[float, float, float]
    a: tuple[float, float, float, float]
    rms_nm: float

    def torque(self, d: npt.ArrayLike, phi_r_deg: npt.ArrayLike) -> FloatArray:
        """Eq. 1: spring torque on the output shaft."""
        dd = np.asarray(d, dtype=float)
        ph = np.asarray(phi_r_deg, dtype=float)
        p = 1.0 + sum(ak * dd ** (k + 1) for k, ak in enumerate(self.a))
        s = sum(bk * np.sin(w * ph) for bk, w in zip(self.b, _HARMONICS, strict=True))
        return np.asarray(-p * s, dtype=float)

    def stiffness_nm_per_rad(self, d: float) -> float:
        """Eq. 2 (per rad)."""
        p = 1.0 + sum(ak * d ** (k + 1) for k, ak in enumerate(self.a))
        return float(
            sum(bk * w for bk, w in zip(self.b, _HARMONICS, strict=True)) * p * 180 / math.pi
        )


_HARMONICS = (math.pi / 60.0, math.pi / 30.0, math.pi / 15.0)  # eq. 1, per degree


def fit_spring_law(
    d_m: npt.ArrayLike, phi_r_deg: npt.ArrayLike, torque_nm: npt.ArrayLike
) -> SpringLaw:
    """Eq. 1 by nonlinear least squares (needs >= 5 distinct d for the quartic P(d))."""
    from scipy.optimize import least_squares

    d, ph, tau = _arr("d_m", d_m), _arr("phi_r_deg", phi_r_deg), _arr("torque_nm", torque_nm)
    if not d.size == ph.size == tau.size:
        raise ModelSelectionError(f"lengths differ: d {d.size}, phi_r {ph.size}, torque {tau.size}")
    if np.unique(d).size < 5:
        raise ModelSelectionError(
            f"eq. 1's quartic P(d) needs data at >= 5 distinct ring distances, got {np.unique(d).size}"
        )
    S = np.column_stack([-np.sin(w * ph) for w in _HARMONICS])
    ref = d == d.min()
    b0, *_ = np.linalg.lstsq(S[ref], tau[ref], rcond=None)
    dscale = max(float(np.max(np.abs(d))), 1e-9)  # fit a in scaled distance (conditioning)

    def resid(p: FloatArray) -> FloatArray:
        u = d / dscale
        poly = 1.0 + p[3] * u + p[4] * u**2 + p[5] * u**3 + p[6] * u**4
        return np.asarray(poly * (S @ p[:3]) - tau, dtype=float)

    sol = least_squares(resid, np.concatenate([b0, np.zeros(4)]), method="lm")
    p = sol.x
    a = tuple(float(p[3 + k] / dscale ** (k + 1)) for k in range(4))
    rms = float(np.sqrt(np.mean(sol.fun**2)))
    return SpringLaw(b=(float(p[0]), float(p[1]), float(p[2])), a=a, rms_nm=rms)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------- eq. 3 (exp. B)


def fit_inertia(
    mass_kg: npt.ArrayLike, radius_m: float, accel_rad_s2: npt.ArrayLike
) -> tuple[float, float]:
    """Eq. 3 -> (J, tau_fr): ``m g r - phi'' m r^2 = J phi'' + tau_fr`` by least squares."""
    m, acc = _arr("mass_kg", mass_kg), _arr("accel_rad_s2", accel_rad_s2)
    if m.size != acc.size or m.size < 2 or np.unique(m).size < 2:
        raise ModelSelectionError("eq. 3 needs drops with at least two different masses")
    if not (math.isfinite(radius_m) and radius_m > 0.0):
        raise ModelSelectionError(f"flywheel radius must be > 0 m, got {radius_m!r}")
    y = m * G_M_S2 * radius_m - acc * m * radius_m**2
    X = np.column_stack([acc, np.ones_like(acc)])
    (j, tau_fr), *_ = np.linalg.lstsq(X, y, rcond=None)
    return float(j), float(tau_fr)


# ---------------------------------------------------------------------- Table 3 (exp. C)


@dataclass(frozen=True)
class Samples:
    """Eq. 5-7 rows: measured output acceleration at n; states at n-1 (velocities by eq. 6)."""

    acc: FloatArray
    phi_out: FloatArray
    v_out: FloatArray
    v_in: FloatArray
    tau_sp: FloatArray  # from the identified eq. 1 at (d, phi_out - phi_in) at n-1
    tau_lin: FloatArray  # A_L / F_L: -k_sp(d) (mod(phi_r + 60 deg, 120 deg) - 60 deg), rad

    @property
    def n(self) -> int:
        return int(self.acc.size)


def samples_from_trial(
    phi_in: FloatArray, phi_out: FloatArray, d_m: float, law: SpringLaw, period_s: float
) -> Samples:
    """Eq. 5-6 on one sampled trial (angles in rad, sampled every ``period_s``)."""
    pi, po = _arr("phi_in", phi_in), _arr("phi_out", phi_out)
    if pi.size != po.size or pi.size < 3:
        raise ModelSelectionError("a trial needs >= 3 samples of both shafts, of equal length")
    T = period_s
    acc = (po[2:] - 2.0 * po[1:-1] + po[:-2]) / T**2
    p1, i1 = po[1:-1], pi[1:-1]
    vo = (po[1:-1] - po[:-2]) / T
    vi = (pi[1:-1] - pi[:-2]) / T
    tau = law.torque(np.full(p1.size, d_m), np.degrees(p1 - i1))
    wrapped = np.radians(np.mod(np.degrees(p1 - i1) + 60.0, 120.0) - 60.0)
    tau_lin = -law.stiffness_nm_per_rad(d_m) * wrapped
    return Samples(acc=acc, phi_out=p1, v_out=vo, v_in=vi, tau_sp=tau, tau_lin=tau_lin)


def concat(parts: list[Samples]) -> Samples:
    if not parts:
        raise ModelSelectionError("no trials in this set")
    return Samples(
        *(
            np.concatenate([getattr(p, f) for p in parts])
            for f in ("acc", "phi_out", "v_out", "v_in", "tau_sp", "tau_lin")
        )
    )


def _base(model: str) -> str:
    return {"AL": "A", "FL": "F"}.get(model, model)


def _spring_torque(model: str, s: Samples) -> FloatArray:
    return s.tau_lin if model in LINEARISED else s.tau_sp


def _columns(model: str, s: Samples, v: float) -> FloatArray:
    model = _base(model)
    cols: list[FloatArray] = []
    if model == "B":
        cols.append(-np.sign(s.v_out))
    elif model != "A":
        cols.append(-np.tanh(v * s.v_out))
    if model in ("D", "E", "F"):
        cols += [np.sin(s.phi_out), np.cos(s.phi_out)]
    if model == "E":
        cols.append(-s.v_out)
    if model == "F":
        cols.append(-(s.v_out - s.v_in))
    if not cols:
        return np.zeros((s.n, 0))
    return np.column_stack(cols)


N_PARAMS = {"A": 0, "B": 1, "C": 2, "D": 4, "E": 5, "F": 5, "AL": 0, "FL": 5}  # Table 3 bold


@dataclass(frozen=True)
class ModelFit:
    model: str
    params: tuple[float, ...]  # torque coefficients in column order (N m, N m s/rad)
    v: float  # tanh sharpness (s/rad); 0 for A, B

    def residual(self, s: Samples, inertia: float) -> FloatArray:
        X = _columns(self.model, s, self.v)
        pred = _spring_torque(self.model, s) + (X @ np.array(self.params) if X.shape[1] else 0.0)
        pred = pred / inertia
        return np.asarray(s.acc - pred, dtype=float)


def named_params(fit: ModelFit) -> dict[str, float]:
    """The fitted terms under Table 5's names: tau_fr [N m], v [s/rad], w [N m], x [rad],
    y, z [N m s/rad]."""
    model, p = _base(fit.model), fit.params
    out: dict[str, float] = {}
    k = 0
    if model != "A":
        out["tau_fr"] = p[0]
        k = 1
        if model != "B":
            out["v"] = fit.v
    if model in ("D", "E", "F"):
        out["w"] = math.hypot(p[k], p[k + 1])
        out["x"] = math.atan2(p[k + 1], p[k])  # w sin(phi + x) = w cos x sin phi + w sin x cos phi
        k += 2
    if model == "E":
        out["y"] = p[k]
    if model == "F":
        out["z"] = p[k]
    return out


@dataclass(frozen=True)
class Scores:
    """Table 4's criteria on one set."""

    n: int
    k: int
    mse: float
    one_minus_r2_adj: float
    se: float
    bic: float


def score(fit: ModelFit, s: Samples, inertia: float) -> Scores:
    r = fit.residual(s, inertia)
    n, k = s.n, N_PARAMS[fit.model]
    if n <= k + 1:
        raise ModelSelectionError(f"{n} samples cannot score a model with {k} parameters")
    sse = float(r @ r)
    sst = float(np.sum((s.acc - s.acc.mean()) ** 2))
    r2 = 1.0 - sse / sst if sst > 0.0 else 0.0
    r2_adj = 1.0 - (1.0 - r2) * (n - 1) / (n - k - 1)
    return Scores(
        n=n,
        k=k,
        mse=sse / n,
        one_minus_r2_adj=1.0 - r2_adj,
        se=math.sqrt(sse / (n - k)),
        bic=n * math.log(sse / n) + k * math.log(n),
    )


def fit_model(model: str, teach: Samples, inertia: float) -> ModelFit:
    """Least squares on the teaching set (v by a log grid + golden-section search)."""
    if model not in MODELS + LINEARISED:
        raise ModelSelectionError(f"model must be one of {MODELS + LINEARISED}, got {model!r}")
    if not (math.isfinite(inertia) and inertia > 0.0):
        raise ModelSelectionError(f"inertia J must be > 0 kg m^2, got {inertia!r}")
    y = inertia * teach.acc - _spring_torque(model, teach)  # what the extra terms must explain

    def solve(v: float) -> tuple[float, FloatArray]:
        X = _columns(model, teach, v)
        if X.shape[1] == 0:
            return float(np.mean(y**2)), np.zeros(0)
        p, *_ = np.linalg.lstsq(X, y, rcond=None)
        return float(np.mean((y - X @ p) ** 2)), np.asarray(p, dtype=float)

    v_best = 0.0
    if _base(model) in ("C", "D", "E", "F"):
        mses = [solve(float(v))[0] for v in V_GRID]
        i = int(np.argmin(mses))
        lo = math.log(V_GRID[max(i - 1, 0)])
        hi = math.log(V_GRID[min(i + 1, V_GRID.size - 1)])
        for _ in range(30):
            a = hi - 0.618 * (hi - lo)
            b = lo + 0.618 * (hi - lo)
            if solve(math.exp(a))[0] < solve(math.exp(b))[0]:
                hi = b
            else:
                lo = a
        v_best = math.exp(0.5 * (lo + hi))
    _, p = solve(v_best)
    return ModelFit(model=model, params=tuple(float(x) for x in p), v=v_best)


@dataclass(frozen=True)
class SelectionRow:
    fit: ModelFit
    teaching: Scores
    verifying: Scores


def select_models(
    teach: Samples, verify: Samples, inertia: float, models: tuple[str, ...] = MODELS
) -> dict[str, SelectionRow]:
    """Table 4: each model fitted on the teaching set, scored on both."""
    out = {}
    for m in models:
        f = fit_model(m, teach, inertia)
        out[m] = SelectionRow(f, score(f, teach, inertia), score(f, verify, inertia))
    return out


def table4(rows: Mapping[str, SelectionRow], unit: str = "(rad/s²)²") -> str:
    """Rows as Table 4 prints them (1 - R²adj in per mille)."""
    head = (
        f"{'Model':<6}| {'Teaching set':^40} | {'Verifying set':^40}\n"
        f"{'ID':<6}| {'MSE':>10} {'1-R²adj':>9} {'SE':>8} {'BIC':>10} |"
        f" {'MSE':>10} {'1-R²adj':>9} {'SE':>8} {'BIC':>10}\n"
    )
    lines = []
    for m, r in rows.items():
        t, v = r.teaching, r.verifying
        lines.append(
            f"{m:<6}| {t.mse:>10.4g} {1000 * t.one_minus_r2_adj:>8.4g}‰ {t.se:>8.4g} {t.bic:>10.6g} |"
            f" {v.mse:>10.4g} {1000 * v.one_minus_r2_adj:>8.4g}‰ {v.se:>8.4g} {v.bic:>10.6g}"
        )
    n_t = next(iter(rows.values())).teaching.n if rows else 0
    n_v = next(iter(rows.values())).verifying.n if rows else 0
    return head + "\n".join(lines) + f"\nMSE in {unit}; n = {n_t} teaching, {n_v} verifying samples"


def _extra_torque(fit: ModelFit, phi: float, vo: float, vi: float) -> float:
    """The fitted terms of Table 3 at one state (scalar form of the model's columns)."""
    model, p, k = _base(fit.model), fit.params, 0
    tau = 0.0
    if model == "B":
        tau -= p[0] * (1.0 if vo > 0.0 else -1.0 if vo < 0.0 else 0.0)
        k = 1
    elif model != "A":
        tau -= p[0] * math.tanh(fit.v * vo)
        k = 1
    if model in ("D", "E", "F"):
        tau += p[k] * math.sin(phi) + p[k + 1] * math.cos(phi)
        k += 2
    if model == "E":
        tau -= p[k] * vo
    if model == "F":
        tau -= p[k] * (vo - vi)
    return tau


def free_run(
    fit: ModelFit,
    law: SpringLaw,
    inertia: float,
    phi_in: npt.ArrayLike,
    phi_out: npt.ArrayLike,
    d_m: float,
    period_s: float,
) -> FloatArray:
    """Eq. 7: the position model fed with its own output (Fig. 13-15's long-term simulation).

    Starts from the first two measured output samples; the input shaft is the measured one.
    """
    pi, po = _arr("phi_in", phi_in), _arr("phi_out", phi_out)
    if pi.size != po.size or pi.size < 3:
        raise ModelSelectionError("a trial needs >= 3 samples of both shafts, of equal length")
    if not (math.isfinite(inertia) and inertia > 0.0):
        raise ModelSelectionError(f"inertia J must be > 0 kg m^2, got {inertia!r}")
    T = period_s
    sim = np.empty_like(po)
    sim[:2] = po[:2]
    k_lin = law.stiffness_nm_per_rad(d_m)
    for n in range(2, po.size):
        phr_deg = math.degrees(sim[n - 1] - pi[n - 1])
        if fit.model in LINEARISED:
            tau = -k_lin * math.radians((phr_deg + 60.0) % 120.0 - 60.0)
        else:
            tau = float(law.torque(d_m, phr_deg))
        tau += _extra_torque(
            fit, sim[n - 1], (sim[n - 1] - sim[n - 2]) / T, (pi[n - 1] - pi[n - 2]) / T
        )
        sim[n] = 2.0 * sim[n - 1] - sim[n - 2] + T * T / inertia * tau
    return sim
