"""Simulated bench experiments of seed 000 Sec. III and the nine-shaft campaign.

Series test (Sec. III-A, Fig. 6-7, Table I): on the series bench (:mod:`fsarm_sim.studies.bench`, blocked
output) a chirp 0.5-20 Hz is fed to the torque controller, amplitude by the shaft's nominal
rating (capped by the DBRK-20 sensor range), at bend angles 0-90 deg in 15 deg steps. Per twist
sign and bend angle, eq. 8 (``tau = K * twist``) and eq. 1 (``tau = J twist'' + B twist' +
K twist``, J shared by both signs) are fitted by least squares; RMSE per sign = a Table I-like
table. The bend trend per sign (eq. 8's ``f_p(phi_B)``) is fitted as ``K(phi) = K0 + s |phi|``.

Parallel test (Sec. III-B2, Fig. 9): on the parallel bench the joint bends the shaft through one
cycle ``0 -> +A -> 0 -> -A -> 0`` (both directions), without and with torsion (input held at a
twist of ``torsion_fraction`` of the rating). Fits of the moment loop M(phi): eq. 2 linear
``M = K_b phi`` (the paper's "linear fit for approximation"), per bending direction, and
``M = K_b (phi + beta phi^3)``; the loop area is the energy the conduit dissipates per cycle.

Campaign (Sec. III-B, Fig. 8, Fig. 10): both tests for every shaft of the catalogue, then eq. 3
(per sign, from the 7 bend angles x N shafts) and eq. 4 (from the N shafts' K_b) are re-fitted by
nonlinear least squares (``scipy.optimize.least_squares``) and compared with the coefficients the
simulator was given: coefficient by coefficient and as surfaces over the validity box. Eq. 3 is
re-fitted with the catalogue's length law (``series.length_law``: with "inverse" p4 is 0 and not
fitted).

Every bench run is an independent task (:func:`bench_task`), run through
:func:`fsarm_sim.executors.run_tasks`, so campaigns use all cores or a Dask cluster.
"""

from __future__ import annotations

import csv
import json
import math
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError, InvalidParameterError
from fsarm_sim.executors import Outcome, run_tasks
from fsarm_sim.paths import named_os_errors
from fsarm_sim.plant.shaft import (
    Catalogue,
    CatalogueShaft,
    ShaftParams,
    load_catalogue,
    parse_catalogue,
)
from fsarm_sim.studies import bench

Array = npt.NDArray[np.float64]
BEND_STEPS_DEG: tuple[float, ...] = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)  # Sec. III-A
SENSOR_RANGE_NM = 20.0  # DBRK-20 torque sensor, seed 000 Sec. III-A
LOOP_POINTS = 1200  # samples kept per loop for figures
SERIES_LOOP_S = 2.5  # series loops in figures: the chirp's first seconds (slow, ~0.5-1 Hz)
EQ3_NAMES = ("p0", "p1", "p2", "p3", "p4", "p5", "p6")
EQ4_NAMES = ("q0", "q1", "q2", "q3", "q4")


class CampaignError(FsarmError, ValueError):
    """A bench experiment or surface fit cannot be done with the data or settings given."""


# ----------------------------------------------------------------------------------------------
# settings


@dataclass(frozen=True)
class BenchSettings:
    """How the simulated bench experiments are run (defaults: seed 000 Sec. III-A where stated)."""

    chirp_s: float = 10.0  # estimate: long enough for ~100 cycles of each twist sign
    f_start_hz: float = 0.5  # Sec. III-A
    f_stop_hz: float = 20.0  # Sec. III-A
    amplitude_fraction: float = 0.8  # of the rating ("amplitudes based on their nominal torque")
    bend_period_s: float = 8.0  # parallel test, one cycle (estimate: Fig. 9's slow bending)
    bend_cycles: int = 2  # the first cycle settles the conduit; fits use the last one
    bend_amplitude_deg: float = 90.0  # Sec. III-A: bend capability up to 90 deg
    torsion_fraction: float = 0.5  # "with torsion": held twist torque / rating (estimate)
    series_hysteresis: bool | None = None  # Maxwell-slip elements; None: the catalogue's setting
    backend: str = "native"

    def validate(self) -> None:
        for name in ("chirp_s", "f_start_hz", "f_stop_hz", "amplitude_fraction", "bend_period_s"):
            v = getattr(self, name)
            if (
                isinstance(v, bool)
                or not isinstance(v, int | float)
                or not math.isfinite(v)
                or v <= 0
            ):
                raise CampaignError(f"bench setting {name} must be a finite number > 0, got {v!r}")
        if self.f_start_hz >= self.f_stop_hz:
            raise CampaignError(
                f"chirp needs f_start < f_stop, got {self.f_start_hz:g} >= {self.f_stop_hz:g} Hz"
            )
        if (
            isinstance(self.bend_cycles, bool)
            or not isinstance(self.bend_cycles, int)
            or self.bend_cycles < 1
        ):
            raise CampaignError(
                f"bend_cycles must be a whole number >= 1, got {self.bend_cycles!r}"
            )
        if not 0.0 < self.bend_amplitude_deg <= 120.0:
            raise CampaignError(
                f"bend amplitude must be in (0, 120] deg, got {self.bend_amplitude_deg!r}"
            )
        if not 0.0 <= self.torsion_fraction <= 1.0:
            raise CampaignError(
                f"torsion_fraction must be in [0, 1], got {self.torsion_fraction!r}"
            )
        if self.amplitude_fraction > 1.0:
            raise CampaignError(
                f"amplitude_fraction above 1 overloads the shaft, got {self.amplitude_fraction!r}"
            )
        if self.backend not in ("python", "native"):
            raise CampaignError(f"backend must be 'python' or 'native', got {self.backend!r}")


def _shaft(catalogue: Catalogue, d: float, ell: float, s: BenchSettings) -> ShaftParams:
    return catalogue.shaft(d, ell, series_hysteresis=s.series_hysteresis)


# ----------------------------------------------------------------------------------------------
# series test


def chirp_amplitude_nm(shaft: ShaftParams, s: BenchSettings) -> float:
    """Chirp amplitude: a fraction of the rating, never beyond the sensor range."""
    return min(s.amplitude_fraction * shaft.rating_nm, 0.9 * SENSOR_RANGE_NM)


def series_test(shaft: ShaftParams, bend_rad: float, s: BenchSettings) -> dict[str, Array]:
    """One chirp into the bench's torque controller at a held bend; the bench's columns."""
    dt = bench.TorqueLoopGains().ctrl_dt_s
    t = np.arange(round(s.chirp_s / dt) + 1, dtype=np.float64) * dt
    rate = (s.f_stop_hz - s.f_start_hz) / s.chirp_s
    tau_d = chirp_amplitude_nm(shaft, s) * np.sin(
        2.0 * math.pi * (s.f_start_hz * t + 0.5 * rate * t * t)
    )
    b = bench.build_series_bench(shaft, bench.BLOCKED, bend_rad, backend=s.backend)  # type: ignore[arg-type]
    return b.run_torque_control(tau_d, t)


@dataclass(frozen=True)
class SeriesFit:
    """Fits of one series test (N*m/rad, N*m*s/rad, kg*m^2, N*m)."""

    bend_deg: float
    k_pos: float  # eq. 8, twist >= 0
    k_neg: float  # eq. 8, twist < 0
    rmse_pos: float
    rmse_neg: float
    eq1_j: float  # eq. 1 (J shared, B and K per sign)
    eq1_b_pos: float
    eq1_b_neg: float
    eq1_k_pos: float
    eq1_k_neg: float
    eq1_rmse_pos: float
    eq1_rmse_neg: float
    n_pos: int
    n_neg: int
    max_torque_nm: float


def fit_series(cols: Mapping[str, Array], bend_deg: float) -> SeriesFit:
    """Eq. 8 and eq. 1 per twist sign from a series test's columns."""
    t = np.asarray(cols["t"], dtype=np.float64)
    twist = np.asarray(cols["theta_m"], dtype=np.float64) - np.asarray(cols["theta_s"])
    tau = np.asarray(cols["tau_s"], dtype=np.float64)
    pos, neg = twist >= 0.0, twist < 0.0
    if np.count_nonzero(pos) < 10 or np.count_nonzero(neg) < 10:
        raise CampaignError(
            "a series fit needs both twist signs (>= 10 samples each); the chirp did not twist "
            "the shaft both ways"
        )

    def through_origin(sel: npt.NDArray[np.bool_]) -> tuple[float, float]:
        x, y = twist[sel], tau[sel]
        k = float(np.dot(x, y) / np.dot(x, x))
        return k, float(np.sqrt(np.mean((y - k * x) ** 2)))

    k_pos, r_pos = through_origin(pos)
    k_neg, r_neg = through_origin(neg)
    rate = np.gradient(twist, t)
    acc = np.gradient(rate, t)
    p, n = pos.astype(float), neg.astype(float)
    X = np.column_stack((acc, rate * p, rate * n, twist * p, twist * n))
    scale = np.linalg.norm(X, axis=0)
    scale[scale == 0.0] = 1.0
    coef, *_ = np.linalg.lstsq(X / scale, tau, rcond=None)
    coef = coef / scale
    res = tau - X @ coef
    return SeriesFit(
        bend_deg=bend_deg,
        k_pos=k_pos,
        k_neg=k_neg,
        rmse_pos=r_pos,
        rmse_neg=r_neg,
        eq1_j=float(coef[0]),
        eq1_b_pos=float(coef[1]),
        eq1_b_neg=float(coef[2]),
        eq1_k_pos=float(coef[3]),
        eq1_k_neg=float(coef[4]),
        eq1_rmse_pos=float(np.sqrt(np.mean(res[pos] ** 2))),
        eq1_rmse_neg=float(np.sqrt(np.mean(res[neg] ** 2))),
        n_pos=int(np.count_nonzero(pos)),
        n_neg=int(np.count_nonzero(neg)),
        max_torque_nm=float(np.max(np.abs(tau))),
    )


@dataclass(frozen=True)
class BendTrend:
    """K(phi) = k0 + slope |phi| per sign (eq. 8's f_p(phi) = 1 + slope/k0 |phi|), phi in rad."""

    k0_pos: float
    slope_pos: float
    k0_neg: float
    slope_neg: float
    rmse_pos: float
    rmse_neg: float


def fit_bend_trend(fits: Sequence[SeriesFit]) -> BendTrend:
    if len(fits) < 2:
        raise CampaignError("the bend trend needs series fits at >= 2 bend angles")
    phi = np.radians([abs(f.bend_deg) for f in fits])
    if np.ptp(phi) == 0.0:
        raise CampaignError("the bend trend needs series fits at >= 2 different bend angles")
    out = []
    for ks in ([f.k_pos for f in fits], [f.k_neg for f in fits]):
        slope, k0 = np.polyfit(phi, ks, 1)
        out.append((float(k0), float(slope), float(np.sqrt(np.mean((k0 + slope * phi - ks) ** 2)))))
    return BendTrend(out[0][0], out[0][1], out[1][0], out[1][1], out[0][2], out[1][2])


# ----------------------------------------------------------------------------------------------
# parallel test


def parallel_test(shaft: ShaftParams, torsion: bool, s: BenchSettings) -> dict[str, Array]:
    """``bend_cycles`` bending cycles 0 -> +A -> 0 -> -A -> 0 on the parallel bench; the
    returned columns hold the last cycle only (the conduit has settled into its loop)."""
    dt = bench.DEFAULT_MAX_TIMESTEP_S
    per = round(s.bend_period_s / dt)
    t = np.arange(per * s.bend_cycles + 1, dtype=np.float64) * dt
    phi = math.radians(s.bend_amplitude_deg) * np.sin(2.0 * math.pi * t / s.bend_period_s)
    twist = 0.0
    if torsion:
        twist = s.torsion_fraction * shaft.rating_nm / shaft.k_series(0.0, 1)
    cols = bench.simulate_parallel_bench(phi, t, shaft, twist_rad=twist, backend=s.backend)  # type: ignore[arg-type]
    start = per * (s.bend_cycles - 1)
    return {k: np.asarray(v)[start:] for k, v in cols.items()}


@dataclass(frozen=True)
class ParallelFit:
    """Fits of one bending cycle (N*m/rad, 1/rad^2, N*m, J)."""

    torsion: bool
    kb_linear: float  # eq. 2: M = K_b phi over the whole loop
    rmse_linear: float
    kb_pos_bend: float  # eq. 2 on phi >= 0 only
    kb_neg_bend: float  # eq. 2 on phi < 0 only
    kb_cubic: float  # M = K_b (phi + beta phi^3)
    beta_cubic: float
    rmse_cubic: float
    loop_energy_j: float  # closed-loop integral of M dphi (dissipated per cycle)
    moment_at_max_bend_nm: float  # mean of the moments at the largest bend


def fit_parallel(cols: Mapping[str, Array], torsion: bool) -> ParallelFit:
    phi = np.asarray(cols["phi_b"], dtype=np.float64)
    m = np.asarray(cols["m_b"], dtype=np.float64)
    if np.count_nonzero(phi > 0) < 10 or np.count_nonzero(phi < 0) < 10:
        raise CampaignError("a parallel fit needs bends in both directions (>= 10 samples each)")

    def slope(sel: npt.NDArray[np.bool_]) -> tuple[float, float]:
        x, y = phi[sel], m[sel]
        k = float(np.dot(x, y) / np.dot(x, x))
        return k, float(np.sqrt(np.mean((y - k * x) ** 2)))

    every = np.ones(phi.size, dtype=bool)
    kb, r_lin = slope(every)
    kb_p, _ = slope(phi >= 0.0)
    kb_n, _ = slope(phi < 0.0)
    X = np.column_stack((phi, phi**3))
    (a, b), *_ = np.linalg.lstsq(X, m, rcond=None)
    r_cub = float(np.sqrt(np.mean((m - X @ np.array([a, b])) ** 2)))
    top = np.abs(phi) >= 0.999 * np.max(np.abs(phi))
    return ParallelFit(
        torsion=torsion,
        kb_linear=kb,
        rmse_linear=r_lin,
        kb_pos_bend=kb_p,
        kb_neg_bend=kb_n,
        kb_cubic=float(a),
        beta_cubic=float(b / a) if a != 0.0 else math.nan,
        rmse_cubic=r_cub,
        loop_energy_j=float(abs(np.sum(0.5 * (m[1:] + m[:-1]) * np.diff(phi)))),
        moment_at_max_bend_nm=float(np.mean(np.abs(m[top]))),
    )


# ----------------------------------------------------------------------------------------------
# tasks (one bench run each; module-level so process pools and Dask can pickle them)


def _decimate(x: Array, n: int = LOOP_POINTS) -> list[float]:
    step = max(1, x.size // n)
    return [float(v) for v in x[::step]]


def bench_task(task: Mapping[str, Any]) -> dict[str, Any]:
    """Run one bench test described by a plain dict and return its fit (and a decimated loop).

    Keys: ``test`` ("series" | "parallel"), ``diameter_mm``, ``length_mm``, ``bend_deg``
    (series) or ``torsion`` (parallel), ``settings`` (BenchSettings fields), ``catalogue_toml``
    (the coefficient file's text; None: default catalogue), ``loop`` (bool: return the loop).
    """
    text = task.get("catalogue_toml")
    cat = (
        load_catalogue()
        if text is None
        else parse_catalogue(tomllib.loads(text), str(task.get("catalogue_source", "catalogue")))
    )
    s = BenchSettings(**task.get("settings", {}))
    sh = _shaft(cat, float(task["diameter_mm"]), float(task["length_mm"]), s)
    out: dict[str, Any] = {"test": task["test"]}
    if task["test"] == "series":
        bend_deg = float(task["bend_deg"])
        cols = series_test(sh, math.radians(bend_deg), s)
        out["fit"] = asdict(fit_series(cols, bend_deg))
        if task.get("loop", False):  # the slow start of the chirp, undecimated in time
            first = cols["t"] - cols["t"][0] <= SERIES_LOOP_S
            out["loop"] = {
                "twist": _decimate((cols["theta_m"] - cols["theta_s"])[first]),
                "tau_s": _decimate(cols["tau_s"][first]),
            }
    elif task["test"] == "parallel":
        torsion = bool(task["torsion"])
        cols = parallel_test(sh, torsion, s)
        out["fit"] = asdict(fit_parallel(cols, torsion))
        if task.get("loop", False):
            out["loop"] = {"phi_b": _decimate(cols["phi_b"]), "m_b": _decimate(cols["m_b"])}
    else:
        raise CampaignError(f"unknown bench test {task['test']!r}: 'series' or 'parallel'")
    return out


# ----------------------------------------------------------------------------------------------
# surface fits (eq. 3, eq. 4)


@dataclass(frozen=True)
class SurfaceFit:
    equation: str  # "eq3 positive", "eq3 negative", "eq4"
    names: tuple[str, ...]
    coefficients: tuple[float, ...]
    rmse: float  # N*m/rad
    max_abs_residual: float
    n: int
    cost: float
    success: bool


def eq3_design(d: Array, ell: Array, phi: Array, reference_length_mm: float = 0.0) -> Array:
    """Columns of seed 000 eq. 3: 1, D, D^2, D^3, L, |phi|, D^2 |phi| (D, L in mm, phi in rad).

    ``reference_length_mm`` > 0: the inverse length law (``effects.series_stiffness``), every
    column evaluated at ``L_ref`` and scaled by ``L_ref / L`` (p4's column is then constant x the
    scale, which the law requires to carry p4 = 0: :func:`fit_eq3` leaves it out)."""
    a = np.abs(phi)
    if reference_length_mm > 0.0:
        scale = reference_length_mm / np.asarray(ell, dtype=np.float64)
        ref = np.full_like(scale, reference_length_mm)
        cols = (np.ones_like(d), d, d**2, d**3, ref, a, d**2 * a)
        return np.column_stack([c * scale for c in cols])
    return np.column_stack((np.ones_like(d), d, d**2, d**3, ell, a, d**2 * a))


def eq4_design(d: Array, ell: Array) -> Array:
    """Columns of seed 000 eq. 4: 1, D, L, D^2, D L."""
    return np.column_stack((np.ones_like(d), d, ell, d**2, d * ell))


def fit_surface(X: Array, k: Array, equation: str, names: Sequence[str]) -> SurfaceFit:
    """Nonlinear least squares (``scipy.optimize.least_squares``, trust region) of K = X p.

    Columns are scaled to unit norm for conditioning (D^3 spans ~2000x), and the fit refuses
    data that cannot determine every coefficient (rank-deficient design: e.g. one length only).
    """
    from scipy.optimize import least_squares

    X = np.asarray(X, dtype=np.float64)
    k = np.asarray(k, dtype=np.float64)
    if X.shape[0] != k.size or not np.all(np.isfinite(X)) or not np.all(np.isfinite(k)):
        raise CampaignError(f"{equation}: data must be finite with one stiffness per row")
    scale = np.linalg.norm(X, axis=0)
    scale[scale == 0.0] = 1.0
    Xs = X / scale
    rank = int(np.linalg.matrix_rank(Xs))
    if X.shape[0] < X.shape[1] or rank < X.shape[1]:
        raise CampaignError(
            f"{equation}: {X.shape[0]} data points of rank {rank} cannot determine "
            f"{X.shape[1]} coefficients ({', '.join(names)}); vary diameter (>= 4 values for "
            "eq. 3, >= 3 for eq. 4), length (>= 2) and, for eq. 3, bend angle (>= 2)"
        )
    x0, *_ = np.linalg.lstsq(Xs, k, rcond=None)  # start point; least_squares polishes it
    sol = least_squares(
        lambda p: Xs @ p - k, x0, jac=lambda p: Xs, method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    coef = sol.x / scale
    res = X @ coef - k
    return SurfaceFit(
        equation=equation,
        names=tuple(names),
        coefficients=tuple(float(c) for c in coef),
        rmse=float(np.sqrt(np.mean(res**2))),
        max_abs_residual=float(np.max(np.abs(res))),
        n=int(k.size),
        cost=float(sol.cost),
        success=bool(sol.success),
    )


def fit_eq3(
    d: Array, ell: Array, phi: Array, k: Array, side: str, reference_length_mm: float = 0.0
) -> SurfaceFit:
    """Eq. 3 by least squares; with the inverse length law p4 is 0 by definition (not fitted)."""
    X = eq3_design(d, ell, phi, reference_length_mm)
    if reference_length_mm <= 0.0:
        return fit_surface(X, k, f"eq3 {side}", EQ3_NAMES)
    free = [0, 1, 2, 3, 5, 6]
    fit = fit_surface(X[:, free], k, f"eq3 {side}", [EQ3_NAMES[i] for i in free])
    coef = [*fit.coefficients[:4], 0.0, *fit.coefficients[4:]]
    return SurfaceFit(**{**asdict(fit), "names": EQ3_NAMES, "coefficients": tuple(coef)})


def fit_eq4(d: Array, ell: Array, k: Array) -> SurfaceFit:
    return fit_surface(eq4_design(d, ell), k, "eq4", EQ4_NAMES)


@dataclass(frozen=True)
class SurfaceComparison:
    """Refit vs the coefficients the simulator was given, over the validity box."""

    equation: str
    catalogue: tuple[float, ...]
    refit: tuple[float, ...]
    coefficient_rel_error: tuple[float, ...]
    surface_rms_error: float  # N*m/rad over the grid
    surface_max_abs_error: float
    surface_rms_rel_error: float  # fraction
    surface_max_rel_error: float


def compare_surface(
    fit: SurfaceFit, catalogue: Catalogue, bend_max_rad: float = math.radians(90.0)
) -> SurfaceComparison:
    """Coefficient and surface errors of a refit against the catalogue (grid over the box)."""
    d = np.linspace(*catalogue.diameter_range, 19)
    ell = np.linspace(*catalogue.length_range, 13)
    if fit.equation.startswith("eq3"):
        phi = np.linspace(0.0, bend_max_rad, 7)
        D, Lg, P = (a.ravel() for a in np.meshgrid(d, ell, phi, indexing="ij"))
        X = eq3_design(D, Lg, P, catalogue.series_reference_length_mm)
        ref = catalogue.p_pos if fit.equation.endswith("positive") else catalogue.p_neg
    else:
        D, Lg = (a.ravel() for a in np.meshgrid(d, ell, indexing="ij"))
        X = eq4_design(D, Lg)
        ref = catalogue.q_bend
    k_ref = X @ np.asarray(ref)
    err = X @ np.asarray(fit.coefficients) - k_ref
    rel = err / np.abs(k_ref)
    return SurfaceComparison(
        equation=fit.equation,
        catalogue=tuple(ref),
        refit=fit.coefficients,
        coefficient_rel_error=tuple(
            float((f - c) / c) if c != 0.0 else math.nan
            for f, c in zip(fit.coefficients, ref, strict=True)
        ),
        surface_rms_error=float(np.sqrt(np.mean(err**2))),
        surface_max_abs_error=float(np.max(np.abs(err))),
        surface_rms_rel_error=float(np.sqrt(np.mean(rel**2))),
        surface_max_rel_error=float(np.max(np.abs(rel))),
    )


# ----------------------------------------------------------------------------------------------
# bench experiments for one shaft, and the campaign


def _catalogue_text(path: str | Path | None) -> str | None:
    if path is None:
        return None
    with named_os_errors("coefficient file", path, CampaignError):
        return Path(path).read_text("utf-8")


def series_tasks(
    shaft: CatalogueShaft,
    bends_deg: Sequence[float],
    s: BenchSettings,
    catalogue_toml: str | None,
    loop: bool,
) -> list[dict[str, Any]]:
    return [
        {
            "test": "series",
            "name": shaft.name,
            "diameter_mm": shaft.diameter_mm,
            "length_mm": shaft.length_mm,
            "bend_deg": float(b),
            "settings": asdict(s),
            "catalogue_toml": catalogue_toml,
            "loop": loop,
        }
        for b in bends_deg
    ]


def parallel_tasks(
    shaft: CatalogueShaft, s: BenchSettings, catalogue_toml: str | None, loop: bool
) -> list[dict[str, Any]]:
    return [
        {
            "test": "parallel",
            "name": shaft.name,
            "diameter_mm": shaft.diameter_mm,
            "length_mm": shaft.length_mm,
            "torsion": torsion,
            "settings": asdict(s),
            "catalogue_toml": catalogue_toml,
            "loop": loop,
        }
        for torsion in (False, True)
    ]


@dataclass
class CampaignResult:
    settings: BenchSettings
    catalogue_source: str
    shafts: list[CatalogueShaft]
    series: dict[str, list[SeriesFit]] = field(default_factory=dict)  # by shaft name, by bend
    parallel: dict[str, list[ParallelFit]] = field(default_factory=dict)
    loops: dict[str, dict[str, Any]] = field(default_factory=dict)  # "name/series/45" -> columns
    trends: dict[str, BendTrend] = field(default_factory=dict)
    fits: dict[str, SurfaceFit] = field(default_factory=dict)
    comparisons: dict[str, SurfaceComparison] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)


def run_bench_tasks(
    tasks: Sequence[Mapping[str, Any]],
    *,
    executor: str = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    on_done: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    return run_tasks(
        bench_task,
        list(tasks),
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        on_done=on_done,
    )


def collect(result: CampaignResult, outcomes: Sequence[Outcome]) -> None:
    """Sort task outcomes into the result (fits per shaft, loops, errors)."""
    for o in sorted(outcomes, key=lambda o: o.index):
        task = o.task
        name = task["name"]
        if o.error is not None or o.result is None:
            what = (
                f"{task['test']} bend {task.get('bend_deg')}"
                if task["test"] == "series"
                else (f"parallel torsion={task.get('torsion')}")
            )
            result.errors.append(f"{name} {what}: {o.error}")
            continue
        fit = o.result["fit"]
        if task["test"] == "series":
            result.series.setdefault(name, []).append(SeriesFit(**fit))
            tag = f"{name}/series/{fit['bend_deg']:g}"
        else:
            result.parallel.setdefault(name, []).append(ParallelFit(**fit))
            tag = f"{name}/parallel/{'torsion' if fit['torsion'] else 'plain'}"
        if "loop" in o.result:
            result.loops[tag] = o.result["loop"]
    for name, fits in result.series.items():
        fits.sort(key=lambda f: f.bend_deg)
        if len(fits) >= 2:
            result.trends[name] = fit_bend_trend(fits)


def refit(result: CampaignResult, catalogue: Catalogue) -> None:
    """Eq. 3 per sign and eq. 4 (linear and cubic K_b) from the collected fits; compare."""
    by_name = {s.name: s for s in result.shafts}
    rows = [
        (by_name[n].diameter_mm, by_name[n].length_mm, math.radians(f.bend_deg), f.k_pos, f.k_neg)
        for n, fits in result.series.items()
        for f in fits
    ]
    if rows:
        a = np.asarray(rows)
        for side, col in (("positive", 3), ("negative", 4)):
            try:
                fit = fit_eq3(
                    a[:, 0], a[:, 1], a[:, 2], a[:, col], side, catalogue.series_reference_length_mm
                )
            except CampaignError as exc:
                result.errors.append(str(exc))
                continue
            result.fits[fit.equation] = fit
            result.comparisons[fit.equation] = compare_surface(
                fit, catalogue, max(r[2] for r in rows)
            )
    plain = [
        (by_name[n].diameter_mm, by_name[n].length_mm, f.kb_linear, f.kb_cubic)
        for n, fits in result.parallel.items()
        for f in fits
        if not f.torsion
    ]
    if plain:
        b = np.asarray(plain)
        for label, col in (("eq4", 2), ("eq4 (cubic K_b)", 3)):
            try:
                fit = fit_eq4(b[:, 0], b[:, 1], b[:, col])
            except CampaignError as exc:
                result.errors.append(str(exc))
                continue
            fit = SurfaceFit(**{**asdict(fit), "equation": label})
            result.fits[label] = fit
            result.comparisons[label] = compare_surface(fit, catalogue)


def run_campaign(
    catalogue_path: str | Path | None = None,
    *,
    shafts: Sequence[CatalogueShaft] | None = None,
    bends_deg: Sequence[float] = BEND_STEPS_DEG,
    settings: BenchSettings | None = None,
    executor: str = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    loops_for: Sequence[str] | None = None,
    on_done: Callable[[Outcome], None] | None = None,
) -> CampaignResult:
    """Both bench tests for every shaft, then the eq. 3/4 refits and their comparison.

    ``loops_for``: shaft names whose loops are kept for figures (default: the prototype's,
    ``MF09-450``, or the first shaft)."""
    s = settings or BenchSettings()
    s.validate()
    cat = load_catalogue(catalogue_path)
    text = _catalogue_text(catalogue_path)
    chosen = list(shafts if shafts is not None else cat.shafts)
    if not chosen:
        raise CampaignError(f"{cat.source} lists no shafts to test")
    for b in bends_deg:
        if not math.isfinite(b) or not 0.0 <= b <= math.degrees(cat.bend_range[1]):
            raise CampaignError(
                f"bend angle {b!r} deg is outside [0, {math.degrees(cat.bend_range[1]):.0f}] deg"
            )
    for sh in chosen:
        cat.check_range(sh.diameter_mm, sh.length_mm)
    if loops_for is None:
        names = [x.name for x in chosen]
        loops_for = ["MF09-450"] if "MF09-450" in names else names[:1]
    tasks: list[dict[str, Any]] = []
    for sh in chosen:
        keep = sh.name in loops_for
        tasks += series_tasks(sh, bends_deg, s, text, keep)
        tasks += parallel_tasks(sh, s, text, keep)
    for tk in tasks:
        tk["catalogue_source"] = cat.source
    result = CampaignResult(settings=s, catalogue_source=cat.source, shafts=chosen)
    outcomes = run_bench_tasks(
        tasks, executor=executor, workers=workers, scheduler=scheduler, on_done=on_done
    )
    collect(result, outcomes)
    refit(result, cat)
    return result


# ----------------------------------------------------------------------------------------------
# writing: tables, JSON, figures


def run_one_shaft(
    catalogue: Catalogue,
    diameter_mm: float,
    length_mm: float,
    shaft_file: str | Path | None,
    settings: BenchSettings,
    make_tasks: Callable[[CatalogueShaft, str | None], list[dict[str, Any]]],
    workers: int | None = None,
) -> tuple[str, CampaignResult]:
    """One shaft's bench tasks (``make_tasks(shaft, coefficient_text)``, e.g. :func:`series_tasks`)
    run and collected; the shaft's name and the result. The first failure is a CampaignError."""
    name = f"D{diameter_mm:g}-L{length_mm:g}"
    sh = CatalogueShaft(name, diameter_mm, length_mm)
    result = CampaignResult(settings=settings, catalogue_source=catalogue.source, shafts=[sh])
    collect(result, run_bench_tasks(make_tasks(sh, _catalogue_text(shaft_file)), workers=workers))
    if result.errors:
        raise CampaignError("; ".join(result.errors))
    return name, result


def write_series_test(result: CampaignResult, name: str, folder: Path) -> Path:
    """One shaft's series test into ``folder``: its table (CSV) and its Fig. 6 loops."""
    folder.mkdir(parents=True, exist_ok=True)
    write_csv(folder / f"series_table_{name}.csv", series_table_rows(result.series[name]))
    loops = {f"φ_B = {t.split('/')[2]}°": lp for t, lp in result.loops.items()}
    plot_series_loops(
        loops, f"{name}: series test (Fig. 6)", folder / f"fig6_series_loops_{name}.png"
    )
    return folder


def write_parallel_test(result: CampaignResult, name: str, folder: Path) -> Path:
    """One shaft's parallel test into ``folder``: its table (CSV) and its Fig. 9 loop."""
    fits = result.parallel[name]
    folder.mkdir(parents=True, exist_ok=True)
    write_csv(folder / f"parallel_table_{name}.csv", [asdict(f) for f in fits])
    loops = {t.split("/")[2]: lp for t, lp in result.loops.items()}
    plot_parallel_loops(
        loops, fits, f"{name}: parallel test (Fig. 9)", folder / f"fig9_parallel_loop_{name}.png"
    )
    return folder


def series_table_rows(fits: Sequence[SeriesFit]) -> list[dict[str, float]]:
    """Table I-like rows: bend, K_sp, K_sn, RMSE_p, RMSE_n (eq. 8) and the eq. 1 terms."""
    return [
        {
            "bend_deg": f.bend_deg,
            "K_sp": f.k_pos,
            "K_sn": f.k_neg,
            "RMSE_p": f.rmse_pos,
            "RMSE_n": f.rmse_neg,
            "eq1_J": f.eq1_j,
            "eq1_B_p": f.eq1_b_pos,
            "eq1_B_n": f.eq1_b_neg,
            "eq1_RMSE_p": f.eq1_rmse_pos,
            "eq1_RMSE_n": f.eq1_rmse_neg,
        }
        for f in fits
    ]


def write_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> Path:
    """``rows`` as a CSV table (columns: the first row's keys); no rows: an empty file."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        if rows:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return path


def write_campaign(result: CampaignResult, catalogue: Catalogue, out_dir: str | Path) -> list[Path]:
    """Tables (CSV), results.json and figures into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    by_name = {s.name: s for s in result.shafts}
    for name, fits in result.series.items():
        files.append(write_csv(out / f"series_table_{name}.csv", series_table_rows(fits)))
    prows = [
        {"shaft": n, "D_mm": by_name[n].diameter_mm, "L_mm": by_name[n].length_mm, **asdict(f)}
        for n, fits in result.parallel.items()
        for f in fits
    ]
    if prows:
        files.append(write_csv(out / "parallel_table.csv", prows))
    crow = []
    for eq, c in result.comparisons.items():
        for nm, cat_v, fit_v, rel in zip(
            result.fits[eq].names, c.catalogue, c.refit, c.coefficient_rel_error, strict=True
        ):
            crow.append(
                {
                    "equation": eq,
                    "coefficient": nm,
                    "catalogue": cat_v,
                    "refit": fit_v,
                    "rel_error": rel,
                }
            )
    if crow:
        files.append(write_csv(out / "refit_coefficients.csv", crow))
    doc = {
        "catalogue": result.catalogue_source,
        "settings": asdict(result.settings),
        "shafts": [asdict(s) for s in result.shafts],
        "series": {n: [asdict(f) for f in fits] for n, fits in result.series.items()},
        "bend_trends": {n: asdict(t) for n, t in result.trends.items()},
        "parallel": {n: [asdict(f) for f in fits] for n, fits in result.parallel.items()},
        "fits": {k: asdict(v) for k, v in result.fits.items()},
        "comparisons": {k: asdict(v) for k, v in result.comparisons.items()},
        "errors": result.errors,
    }
    path = out / "campaign.json"
    path.write_text(json.dumps(doc, indent=2, allow_nan=True), "utf-8")
    files.append(path)
    files += plot_campaign(result, catalogue, out)
    result.files = files
    return files


def new_figure(size: tuple[float, float] = (7.0, 4.5)) -> Any:
    """A matplotlib figure on its own Agg canvas (headless, no pyplot state); ``size`` in inches."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, dpi=110)
    FigureCanvasAgg(fig)
    return fig


def plot_series_loops(
    loops: Mapping[str, Mapping[str, Sequence[float]]], title: str, path: Path
) -> Path:
    """Fig. 6-like: torque vs twist, one loop per bend angle."""
    fig = new_figure()
    ax = fig.add_subplot(1, 1, 1)
    for label, lp in loops.items():
        ax.plot(np.degrees(lp["twist"]), lp["tau_s"], lw=0.8, label=label)
    ax.set_xlabel("twist Δθ [deg]")
    ax.set_ylabel("shaft torque τ [N·m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_parallel_loops(
    loops: Mapping[str, Mapping[str, Sequence[float]]],
    fits: Sequence[ParallelFit],
    title: str,
    path: Path,
) -> Path:
    """Fig. 9-like: bending moment vs bend angle, with and without torsion, and the linear fit."""
    fig = new_figure()
    ax = fig.add_subplot(1, 1, 1)
    for label, lp in loops.items():
        ax.plot(np.degrees(lp["phi_b"]), lp["m_b"], lw=1.0, label=label)
    for f in fits:
        if not f.torsion:
            x = np.linspace(-math.pi / 2, math.pi / 2, 50)
            ax.plot(
                np.degrees(x),
                f.kb_linear * x,
                "k--",
                lw=0.8,
                label=f"eq. 2 fit K_b = {f.kb_linear:.3g}",
            )
    ax.set_xlabel("bend φ_B [deg]")
    ax.set_ylabel("bending moment M [N·m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_eq3_surfaces(
    fits: Mapping[str, SurfaceFit],
    points: Array,
    catalogue: Catalogue,
    path: Path,
) -> Path:
    """Fig. 8-like: refit eq. 3 surfaces K(D, L) at 0 and 90 deg per sign, with the data."""
    fig = new_figure((11.0, 8.0))
    d = np.linspace(*catalogue.diameter_range, 30)
    ell = np.linspace(*catalogue.length_range, 30)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    i = 1
    for side, col in (("positive", 3), ("negative", 4)):
        fit = fits.get(f"eq3 {side}")
        for bend in (0.0, 90.0):
            ax = fig.add_subplot(2, 2, i, projection="3d")
            i += 1
            if fit is not None:
                X = eq3_design(
                    D.ravel(),
                    Lg.ravel(),
                    np.full(D.size, math.radians(bend)),
                    catalogue.series_reference_length_mm,
                )
                K = (X @ np.asarray(fit.coefficients)).reshape(D.shape)
                ax.plot_surface(D, Lg, K, cmap="viridis", alpha=0.7, linewidth=0)
            sel = np.isclose(points[:, 2], math.radians(bend))
            ax.scatter(points[sel, 0], points[sel, 1], points[sel, col], color="r", s=12)
            ax.set_xlabel("D [mm]")
            ax.set_ylabel("L [mm]")
            ax.set_zlabel("K [N·m/rad]")
            ax.set_title(f"K_s{'p' if side == 'positive' else 'n'} at φ_B = {bend:g}°", fontsize=9)
    fig.suptitle("eq. 3 re-fitted from the simulated bench campaign (red: per-shaft fits)")
    fig.savefig(path)
    return path


def plot_eq4_surface(
    fit: SurfaceFit | None, points: Array, catalogue: Catalogue, path: Path
) -> Path:
    """Fig. 10-like: refit eq. 4 surface K_b(D, L) with the per-shaft fits."""
    fig = new_figure((7.0, 5.5))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    d = np.linspace(*catalogue.diameter_range, 30)
    ell = np.linspace(*catalogue.length_range, 30)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    if fit is not None:
        K = (eq4_design(D.ravel(), Lg.ravel()) @ np.asarray(fit.coefficients)).reshape(D.shape)
        ax.plot_surface(D, Lg, K, cmap="plasma", alpha=0.7, linewidth=0)
    ax.scatter(points[:, 0], points[:, 1], points[:, 2], color="k", s=14)
    ax.set_xlabel("D [mm]")
    ax.set_ylabel("L [mm]")
    ax.set_zlabel("K_b [N·m/rad]")
    ax.set_title("eq. 4 re-fitted (black: per-shaft linear K_b)")
    fig.savefig(path)
    return path


def plot_error_maps(result: CampaignResult, catalogue: Catalogue, path: Path) -> Path:
    """Heat maps of the refit's relative error against the catalogue over (D, L)."""
    d = np.linspace(*catalogue.diameter_range, 46)
    ell = np.linspace(*catalogue.length_range, 31)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    panels = []
    for eq in ("eq3 positive", "eq3 negative"):
        if eq in result.fits:
            for bend in (0.0, 90.0):
                X = eq3_design(
                    D.ravel(),
                    Lg.ravel(),
                    np.full(D.size, math.radians(bend)),
                    catalogue.series_reference_length_mm,
                )
                ref = catalogue.p_pos if eq.endswith("positive") else catalogue.p_neg
                panels.append((f"{eq}, φ_B = {bend:g}°", X, ref, result.fits[eq]))
    for eq in ("eq4", "eq4 (cubic K_b)"):
        if eq in result.fits:
            panels.append(
                (eq, eq4_design(D.ravel(), Lg.ravel()), catalogue.q_bend, result.fits[eq])
            )
    fig = new_figure((4.0 * max(1, min(3, len(panels))), 3.4 * math.ceil(max(1, len(panels)) / 3)))
    cols = max(1, min(3, len(panels)))
    rows = math.ceil(max(1, len(panels)) / cols)
    for i, (title, X, ref, fit) in enumerate(panels):
        ax = fig.add_subplot(rows, cols, i + 1)
        k_ref = X @ np.asarray(ref)
        rel = 100.0 * (X @ np.asarray(fit.coefficients) - k_ref) / np.abs(k_ref)
        im = ax.pcolormesh(d, ell, rel.reshape(D.shape).T, shading="auto", cmap="RdBu_r")
        fig.colorbar(im, ax=ax, label="refit − catalogue [%]")
        ax.set_xlabel("D [mm]")
        ax.set_ylabel("L [mm]")
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_campaign(result: CampaignResult, catalogue: Catalogue, out: Path) -> list[Path]:
    files = []
    by_name = {s.name: s for s in result.shafts}
    names = {tag.split("/")[0] for tag in result.loops}
    for name in sorted(names):
        series = {
            f"φ_B = {tag.split('/')[2]}°": lp
            for tag, lp in result.loops.items()
            if tag.startswith(f"{name}/series/")
        }
        if series:
            files.append(
                plot_series_loops(
                    series, f"{name}: series test (Fig. 6)", out / f"fig6_series_loops_{name}.png"
                )
            )
        par = {
            tag.split("/")[2]: lp
            for tag, lp in result.loops.items()
            if tag.startswith(f"{name}/parallel/")
        }
        if par:
            files.append(
                plot_parallel_loops(
                    par,
                    result.parallel.get(name, []),
                    f"{name}: parallel test (Fig. 9)",
                    out / f"fig9_parallel_loop_{name}.png",
                )
            )
    pts = [
        (by_name[n].diameter_mm, by_name[n].length_mm, math.radians(f.bend_deg), f.k_pos, f.k_neg)
        for n, fits in result.series.items()
        for f in fits
    ]
    if pts:
        files.append(
            plot_eq3_surfaces(
                result.fits, np.asarray(pts), catalogue, out / "fig8_eq3_surfaces.png"
            )
        )
    kb = [
        (by_name[n].diameter_mm, by_name[n].length_mm, f.kb_linear)
        for n, fits in result.parallel.items()
        for f in fits
        if not f.torsion
    ]
    if kb:
        files.append(
            plot_eq4_surface(
                result.fits.get("eq4"), np.asarray(kb), catalogue, out / "fig10_eq4_surface.png"
            )
        )
    if result.fits:
        files.append(plot_error_maps(result, catalogue, out / "refit_error_maps.png"))
    return files


def check_bends(bends_deg: Sequence[float], catalogue: Catalogue) -> tuple[float, ...]:
    """Validate a list of bend angles (deg) for the series test."""
    if not bends_deg:
        raise InvalidParameterError("give at least one bend angle")
    hi = math.degrees(catalogue.bend_range[1])
    out = []
    for b in bends_deg:
        if not math.isfinite(b) or not 0.0 <= b <= hi:
            raise InvalidParameterError(f"bend angle {b!r} deg is outside [0, {hi:.0f}] deg")
        out.append(float(b))
    return tuple(out)
