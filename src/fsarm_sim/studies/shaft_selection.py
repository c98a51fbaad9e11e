"""Shaft selection for a desired stiffness: seed 000 Algorithm 1 and a direct selector.

Seed 000 Sec. IV-A1: a shaft's nominal torque rating depends on its diameter only, so the
diameter is chosen from the torque need first; then the length is varied within the robot's
dimensional limits ``[L_min, L_max]`` until eq. 3 (series stiffness, at a bend angle) or eq. 4
(bending/parallel stiffness) gives the desired stiffness ``K_des``. "Series and parallel stiffness
cannot both be optimised by one shaft": each request names one kind.

Two selectors:

* :func:`algorithm1` - Algorithm 1 as published: ``D`` from the torque need, a random start
  length ``L <- rand([L_min, L_max])`` (seeded: deterministic by default), then ``N_itr =
  size(L)`` fixed steps of ``(L_max - L_min) / N_itr``, up when ``delta = K_des - K > 0``, down
  otherwise. Read literally, the printed algorithm computes ``delta`` once before the loop and
  steps *up* in L when more stiffness is wanted, although eq. 3 and eq. 4 both *fall* with L, so
  it walks monotonically out of the range. ``variant="interpreted"`` (default) is the evident
  intent: ``delta`` recomputed every iteration, the step taken in the direction that reduces
  ``|delta|`` (from the sign of dK/dL), L kept in range. ``variant="literal"`` reproduces the
  printed text for comparison (its answer may leave ``[L_min, L_max]``; eq. 3/4 are then
  evaluated outside their validity box and the result is marked infeasible).
* :func:`select_shaft` - for a fixed D and bend, eq. 4 and eq. 3 as printed are *affine in L*
  and eq. 3 with the inverse length law (:mod:`fsarm_sim.plant.effects.series_stiffness`) is
  ``K(D, L_ref) L_ref / L``, so the length that gives ``K_des`` follows in closed form:
  ``L* = (K_des - K(D, 0)) / dK/dL`` or ``L* = K(D, L_ref) L_ref / K_des``. Every
  catalogue diameter whose rating covers the torque need is tried, ``L*`` is clipped to the
  allowed range, shafts the catalogue refuses (non-positive stiffness somewhere in the bend range)
  are dropped, and the smallest diameter that reaches ``K_des`` within the tolerance wins
  (lightest shaft, least bending stiffness, the rating margin Algorithm 1 would also pick). If no
  shaft reaches ``K_des`` a :class:`ShaftSelectionError` says what range is reachable.

Units: diameter and length in mm (as the catalogue), bend in rad, stiffness in N*m/rad, torque
in N*m *at the shaft* (on the arm: joint-3 torque / i_G2).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from fsarm_sim.errors import FsarmError, ShaftRangeError
from fsarm_sim.plant.effects import bending
from fsarm_sim.plant.shaft import Catalogue

Kind = Literal["series", "parallel"]
Variant = Literal["interpreted", "literal"]
KINDS: tuple[str, ...] = ("series", "parallel")
DEFAULT_TOLERANCE = 0.01  # relative |K - K_des| / K_des accepted as "reached" by select_shaft
DEFAULT_RESOLUTION_MM = 1.0  # grid of the length range in Algorithm 1 (size(L) = its points)


class ShaftSelectionError(FsarmError, ValueError):
    """A selection request is malformed or cannot be met by any shaft of the catalogue."""


@dataclass(frozen=True)
class SelectionRequest:
    """What the robot needs from the shaft."""

    k_des: float  # desired stiffness, N*m/rad
    kind: Kind = "series"
    bend_rad: float = 0.0  # series: bend at which K_des is wanted (seed 000: straight first)
    torque_nm: float = 0.0  # torque the shaft must carry (rating >= this)
    length_range_mm: tuple[float, float] | None = None  # robot's [L_min, L_max]; None: catalogue
    side: int = 1  # series: +1 winding (K_sp), -1 unwinding (K_sn)
    diameters_mm: tuple[float, ...] | None = None  # available diameters; None: the catalogue's


@dataclass(frozen=True)
class Candidate:
    diameter_mm: float
    length_mm: float
    k_nm_per_rad: float
    rating_nm: float
    valid: bool  # the catalogue accepts the shaft (positive stiffness over the bend range)


@dataclass(frozen=True)
class Selection:
    """One selector's answer."""

    method: str
    diameter_mm: float
    length_mm: float
    k_nm_per_rad: float  # achieved stiffness at the request's bend/side
    k_des: float
    rating_nm: float
    feasible: bool  # |K - K_des| within tolerance and the shaft inside the validity box
    iterations: int = 0
    length_trace_mm: tuple[float, ...] = ()
    candidates: tuple[Candidate, ...] = field(default=())

    @property
    def error_nm_per_rad(self) -> float:
        return self.k_nm_per_rad - self.k_des

    @property
    def relative_error(self) -> float:
        return self.error_nm_per_rad / self.k_des


def stiffness(
    catalogue: Catalogue,
    kind: str,
    diameter_mm: float,
    length_mm: float,
    bend_rad: float = 0.0,
    side: int = 1,
) -> float:
    """Eq. 3 (series, at ``bend_rad``, winding side for ``side >= 0``) or eq. 4 (parallel).

    No range check: the selectors need the polynomials' values at trial points."""
    if kind == "series":
        base, slope = catalogue.eq3(diameter_mm, length_mm, side)
        return base + slope * abs(bend_rad)
    if kind == "parallel":
        return bending.eq4_stiffness_nm_per_rad(catalogue.q_bend, diameter_mm, length_mm)
    raise ShaftSelectionError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")


def _inverse_in_length(catalogue: Catalogue, req: SelectionRequest) -> bool:
    """Eq. 3 with the inverse length law (K ~ 1/L); else K is affine in L (eq. 4, printed eq. 3)."""
    return req.kind == "series" and catalogue.series_reference_length_mm > 0.0


def _length_for_k(
    catalogue: Catalogue, req: SelectionRequest, diameter_mm: float, lo: float, hi: float
) -> float:
    """The length (not yet clipped to [lo, hi]) whose stiffness is ``K_des``, in closed form;
    the middle of the range when K does not depend on L or cannot reach K_des's sign."""

    def k_of(ell: float) -> float:
        return stiffness(catalogue, req.kind, diameter_mm, ell, req.bend_rad, req.side)

    if _inverse_in_length(catalogue, req):
        ref = catalogue.series_reference_length_mm
        c = k_of(ref) * ref  # K(L) = c / L
        return 0.5 * (lo + hi) if c <= 0.0 else c / req.k_des
    k0 = k_of(0.0)
    slope = k_of(1.0) - k0
    return 0.5 * (lo + hi) if slope == 0.0 else (req.k_des - k0) / slope


def validate_request(catalogue: Catalogue, req: SelectionRequest) -> tuple[float, float]:
    """Check a request against the catalogue; return the allowed length range (mm)."""
    if req.kind not in KINDS:
        raise ShaftSelectionError(f"kind must be one of {', '.join(KINDS)}, got {req.kind!r}")
    if not (isinstance(req.k_des, int | float) and math.isfinite(req.k_des) and req.k_des > 0.0):
        raise ShaftSelectionError(
            f"desired stiffness K_des must be a finite number > 0 N*m/rad, got {req.k_des!r}"
        )
    if not (math.isfinite(req.torque_nm) and req.torque_nm >= 0.0):
        raise ShaftSelectionError(
            f"torque need must be a finite number >= 0 N*m, got {req.torque_nm!r}"
        )
    if req.side not in (1, -1):
        raise ShaftSelectionError(f"side must be +1 (winding) or -1 (unwinding), got {req.side!r}")
    lo_b, hi_b = catalogue.bend_range
    if not math.isfinite(req.bend_rad) or not lo_b <= req.bend_rad <= hi_b:
        raise ShaftSelectionError(
            f"bend angle {req.bend_rad!r} rad is outside the validity range "
            f"[{lo_b:.4g}, {hi_b:.4g}] rad of {catalogue.source}"
        )
    if req.kind == "parallel" and req.bend_rad != 0.0:
        raise ShaftSelectionError(
            "eq. 4 (parallel stiffness) does not depend on the bend angle: leave it at 0"
        )
    cat_lo, cat_hi = catalogue.length_range
    lo, hi = req.length_range_mm if req.length_range_mm is not None else (cat_lo, cat_hi)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        raise ShaftSelectionError(
            f"length range must be [L_min, L_max] with L_min < L_max, got [{lo!r}, {hi!r}] mm"
        )
    if lo < cat_lo or hi > cat_hi:
        raise ShaftSelectionError(
            f"length range [{lo:g}, {hi:g}] mm leaves the validity range [{cat_lo:g}, {cat_hi:g}] "
            f"mm of {catalogue.source}"
        )
    return float(lo), float(hi)


def available_diameters(catalogue: Catalogue, req: SelectionRequest) -> tuple[float, ...]:
    """Diameters to choose from: the request's, else the catalogue's bench shafts' (sorted)."""
    if req.diameters_mm is not None:
        ds = tuple(sorted({float(d) for d in req.diameters_mm}))
    else:
        ds = tuple(sorted({s.diameter_mm for s in catalogue.shafts}))
    if not ds:
        raise ShaftSelectionError(
            f"no diameters to choose from: {catalogue.source} lists no shafts; pass diameters_mm"
        )
    lo, hi = catalogue.diameter_range
    for d in ds:
        if not math.isfinite(d) or not lo <= d <= hi:
            raise ShaftSelectionError(
                f"diameter {d!r} mm is outside the validity range [{lo:g}, {hi:g}] mm of "
                f"{catalogue.source}"
            )
    return ds


def diameter_for_torque(
    catalogue: Catalogue, torque_nm: float, diameters_mm: Sequence[float]
) -> float:
    """Algorithm 1 line 1: the smallest available diameter whose rating covers the need."""
    for d in sorted(diameters_mm):
        if catalogue.rating_nm(d) >= torque_nm:
            return float(d)
    d_max = max(diameters_mm)
    raise ShaftSelectionError(
        f"no shaft carries {torque_nm:g} N*m: the thickest available, D = {d_max:g} mm, is rated "
        f"{catalogue.rating_nm(d_max):.3g} N*m (rating depends on D only, {catalogue.source})"
    )


def _valid_shaft(catalogue: Catalogue, diameter_mm: float, length_mm: float) -> bool:
    try:
        catalogue.shaft(diameter_mm, length_mm)
    except ShaftRangeError:
        return False
    return True


def algorithm1(
    catalogue: Catalogue,
    req: SelectionRequest,
    *,
    seed: int = 0,
    resolution_mm: float = DEFAULT_RESOLUTION_MM,
    variant: Variant = "interpreted",
    tolerance: float = DEFAULT_TOLERANCE,
) -> Selection:
    """Seed 000 Algorithm 1 (see the module docstring for the two variants).

    ``L <- [L_min, L_max]`` is the grid of the range at ``resolution_mm``; ``N_itr = size(L)``;
    ``rand(L)`` draws one grid point with ``numpy.random.default_rng(seed)``. Returns the last
    ``L_des`` (as the algorithm does), not the best one visited.
    """
    lo, hi = validate_request(catalogue, req)
    if variant not in ("interpreted", "literal"):
        raise ShaftSelectionError(f"variant must be 'interpreted' or 'literal', got {variant!r}")
    if not (math.isfinite(resolution_mm) and resolution_mm > 0.0):
        raise ShaftSelectionError(f"resolution must be > 0 mm, got {resolution_mm!r}")
    d_des = diameter_for_torque(catalogue, req.torque_nm, available_diameters(catalogue, req))
    grid = np.linspace(lo, hi, math.floor((hi - lo) / resolution_mm + 1e-9) + 1)
    n_itr = int(grid.size)
    step = (hi - lo) / n_itr
    rng = np.random.default_rng(seed)
    length = float(grid[int(rng.integers(n_itr))])

    def k_of(ell: float) -> float:
        return stiffness(catalogue, req.kind, d_des, ell, req.bend_rad, req.side)

    slope = k_of(hi) - k_of(lo)  # sign of dK/dL (eq. 3 and 4 are monotone in L)

    trace = [length]
    delta = req.k_des - k_of(length)
    for _ in range(n_itr):
        if variant == "interpreted":
            delta = req.k_des - k_of(length)
            if delta == 0.0:
                break
            up = (delta > 0.0) == (slope > 0.0)  # step toward K_des along dK/dL
            length = min(hi, max(lo, length + step if up else length - step))
        else:
            length = length + step if delta > 0.0 else length - step
        trace.append(length)
    k = k_of(length)
    inside = lo - 1e-9 <= length <= hi + 1e-9
    valid = inside and _valid_shaft(catalogue, d_des, length)
    return Selection(
        method=f"algorithm1 ({variant}, seed {seed})",
        diameter_mm=d_des,
        length_mm=length,
        k_nm_per_rad=k,
        k_des=req.k_des,
        rating_nm=catalogue.rating_nm(d_des),
        feasible=valid and abs(k - req.k_des) <= tolerance * req.k_des,
        iterations=len(trace) - 1,
        length_trace_mm=tuple(trace),
    )


def candidates(catalogue: Catalogue, req: SelectionRequest) -> tuple[Candidate, ...]:
    """For every diameter whose rating covers the need: the closed-form best length."""
    lo, hi = validate_request(catalogue, req)
    ds = available_diameters(catalogue, req)
    d_min = diameter_for_torque(catalogue, req.torque_nm, ds)
    out = []
    for d in ds:
        if d < d_min:
            continue
        ell = min(hi, max(lo, _length_for_k(catalogue, req, d, lo, hi)))
        out.append(
            Candidate(
                diameter_mm=d,
                length_mm=ell,
                k_nm_per_rad=stiffness(catalogue, req.kind, d, ell, req.bend_rad, req.side),
                rating_nm=catalogue.rating_nm(d),
                valid=_valid_shaft(catalogue, d, ell),
            )
        )
    return tuple(out)


def select_shaft(
    catalogue: Catalogue,
    req: SelectionRequest,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    nearest: bool = False,
) -> Selection:
    """The direct selector (closed-form L per diameter); see the module docstring.

    ``nearest=True`` returns the closest valid shaft (``feasible=False``) instead of raising when
    no shaft reaches ``K_des`` within ``tolerance``.
    """
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise ShaftSelectionError(f"tolerance must be a finite number >= 0, got {tolerance!r}")
    cands = candidates(catalogue, req)
    valid = [c for c in cands if c.valid]
    if not valid:
        raise ShaftSelectionError(
            "every shaft that carries the torque need is outside the catalogue's valid region "
            f"(non-positive stiffness somewhere in the bend range) for {catalogue.source}"
        )
    hits = [c for c in valid if abs(c.k_nm_per_rad - req.k_des) <= tolerance * req.k_des]
    if hits:
        best, feasible = min(hits, key=lambda c: c.diameter_mm), True
    else:
        best, feasible = min(valid, key=lambda c: abs(c.k_nm_per_rad - req.k_des)), False
        if not nearest:
            lo, hi = validate_request(catalogue, req)
            spans = []
            for c in valid:
                ka, kb = (
                    stiffness(catalogue, req.kind, c.diameter_mm, ell, req.bend_rad, req.side)
                    for ell in (lo, hi)
                )
                spans.append(f"D {c.diameter_mm:g}: [{min(ka, kb):.3g}, {max(ka, kb):.3g}]")
            shown = "; ".join(spans if len(spans) <= 12 else [*spans[:6], "...", *spans[-5:]])
            what = (
                f"eq. 3 at bend {math.degrees(req.bend_rad):g} deg"
                if req.kind == "series"
                else "eq. 4"
            )
            raise ShaftSelectionError(
                f"K_des = {req.k_des:g} N*m/rad is not reachable within {tolerance:.3g} "
                f"(relative): with a rating >= {req.torque_nm:g} N*m and L in [{lo:g}, {hi:g}] mm, "
                f"{what} reaches (N*m/rad per diameter in mm) {shown}; the nearest is "
                f"D = {best.diameter_mm:g} mm, L = {best.length_mm:.1f} mm with "
                f"{best.k_nm_per_rad:.4g} N*m/rad (nearest=True / --nearest accepts it; other "
                "diameters: diameters_mm / --diameters)"
            )
    return Selection(
        method="closed-form L per diameter",
        diameter_mm=best.diameter_mm,
        length_mm=best.length_mm,
        k_nm_per_rad=best.k_nm_per_rad,
        k_des=req.k_des,
        rating_nm=best.rating_nm,
        feasible=feasible,
        candidates=cands,
    )
