"""Eq. 3 and eq. 4 re-fitted over a campaign's shafts and compared with the coefficients the
simulator was given; the campaign's result.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.plant.shaft import (
    Catalogue,
    CatalogueShaft,
)
from fsarm_sim.studies.campaign_bench import (
    EQ3_NAMES,
    EQ4_NAMES,
    Array,
    BenchSettings,
    BendTrend,
    CampaignError,
    ParallelFit,
    SeriesFit,
)

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
