"""A catalogue's shafts evaluated: seed 000 eq. 3/4 for one (D, L) (Catalogue.shaft) into
ShaftParams; the file format and its reading are in :mod:.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from fsarm_sim.errors import CoefficientFileError, ShaftRangeError, real_number
from fsarm_sim.plant.effects import bending, conduit_viscoelastic, series_stiffness

PROTOTYPE_DIAMETER_MM = 9.0  # seed 000 Sec. IV-A1: MasterFlex D = 9 mm, L = 450 mm
PROTOTYPE_LENGTH_MM = 450.0


@dataclass(frozen=True)
class ShaftParams:
    """Everything the simulator needs about one shaft, in SI units (N*m/rad, N*m*s/rad, kg*m^2)."""

    diameter_mm: float
    length_mm: float
    k_pos: float  # eq. 3 winding side, bend-independent part
    s_pos: float  # eq. 3 winding side, slope in |phi_B|
    k_neg: float
    s_neg: float
    kb: float  # elastic bending stiffness K_b of M = K_b (phi + beta phi^3) (eq. 4 / test gain)
    beta: float  # bending stiffening, 1/rad^2
    conduit_k: tuple[float, float]  # Maxwell-branch stiffness, N*m/rad
    conduit_tau: tuple[float, float]  # Maxwell-branch time constants, s
    inertia_kgm2: float = 0.0  # eq. 1 J
    damping_pos: float = 0.0  # eq. 1 B_p
    damping_neg: float = 0.0  # eq. 1 B_n
    slip_k: tuple[float, float, float] = (0.0, 0.0, 0.0)
    slip_f: tuple[float, float, float] = (0.0, 0.0, 0.0)  # straight, winding side
    slip_unwinding_ratio: float = 1.0  # unwinding-side / winding-side slip torque
    bend_friction_per_rad: float = 0.0  # capstan-like growth of the slip torques with |phi_B|
    # the elements' apparent stiffness in seed 000's series test (k_pos, s_pos, k_neg, s_neg):
    # the plant's spring is eq. 3 less it while the elements are on (transmissions.flexible_shaft)
    slip_apparent: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    rating_nm: float = 0.0
    bend_limit_rad: float = 2.0 * math.pi / 3.0
    eq4_kb: float = 0.0  # eq. 4 as the file gives it (what eq. 2's test identifies); 0: = kb
    # where the numbers come from (named in errors); not part of equality
    source: str = field(default="", compare=False)

    def check_bend(self, bend_rad: float | Iterable[float], what: str = "bend angle") -> None:
        """Raise ShaftRangeError for a bend angle beyond the file's ``validity.bend_rad``."""
        check_bend_rad(bend_rad, self.bend_limit_rad, self.source or "the shaft", what)

    def k_series(self, bend_rad: float, side: int) -> float:
        """Eq. 3 stiffness at a bend angle for side +1 (winding) or -1 (unwinding)."""
        twist = 1.0 if side >= 0 else -1.0
        return series_stiffness.stiffness_nm_per_rad(
            twist, bend_rad, self.k_pos, self.s_pos, self.k_neg, self.s_neg
        )

    def k_spring(self, bend_rad: float, side: int) -> float:
        """The plant's spring at a bend (side +1 winding, -1 unwinding): eq. 3 less the slip
        elements' apparent stiffness in the series test (0 with the elements off)."""
        a = self.slip_apparent if max(self.slip_k) > 0.0 else (0.0, 0.0, 0.0, 0.0)
        dk, ds = (a[0], a[1]) if side >= 0 else (a[2], a[3])
        return self.k_series(bend_rad, side) - dk - ds * abs(bend_rad)

    @property
    def kb_eq4(self) -> float:
        """Eq. 4's K_b: the slope the paper's eq. 2 test (linear fit of Fig. 9) identifies."""
        return self.eq4_kb if self.eq4_kb > 0.0 else self.kb

    def static_relief_nm(self, bend_rad: float) -> float:
        """Static joint-2 torque relief from the bent shaft (elastic moment; branches relaxed)."""
        return bending.elastic_moment_nm(bend_rad, self.kb, self.beta)


@dataclass(frozen=True)
class CatalogueShaft:
    name: str
    diameter_mm: float
    length_mm: float


@dataclass(frozen=True)
class Catalogue:
    """A validated coefficient file."""

    source: str
    p_pos: tuple[float, ...]
    p_neg: tuple[float, ...]
    q_bend: tuple[float, ...]
    beta: float
    conduit_fraction: tuple[float, float]
    conduit_tau: tuple[float, float]
    diameter_range: tuple[float, float]
    length_range: tuple[float, float]
    bend_range: tuple[float, float]
    rating_coefficient: float
    inertia_kgm2: float
    damping_pos: float
    damping_neg: float
    slip_enabled: bool
    slip_k_fraction: tuple[float, float, float]  # of the straight K_sp
    slip_f_fraction: tuple[float, float, float]  # of the torque rating (straight, winding side)
    slip_unwinding_ratio: float = 1.0  # unwinding-side / winding-side slip torque
    bend_friction_per_rad: float = 0.0  # effects.bend_friction mu_b
    shafts: tuple[CatalogueShaft, ...] = field(default=())
    # series.reference_length_mm: > 0 selects eq. 3's inverse length law (K ~ L_ref / L); 0: eq. 3
    # as printed, affine in L (effects.series_stiffness)
    series_reference_length_mm: float = 0.0
    # series.maxwell_slip.apparent_stiffness_pos/_neg: [straight, slope in |phi_B|] as fractions
    # of the straight K_sp (see ShaftParams.slip_apparent)
    slip_apparent_fraction: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    # bending.eq2_test_*: the sinusoidal bend at which eq. 4 was identified (eq. 2's linear fit);
    # 0: eq. 4 is the elastic K_b itself
    eq2_test_amplitude_rad: float = 0.0
    eq2_test_period_s: float = 0.0
    # [uncertainty]: the declared plausible range of each coefficient group (empty: none declared)
    uncertainty: tuple[CoefficientRange, ...] = field(default=())

    def perturbed(self, factors: dict[str, float]) -> Catalogue:
        """This catalogue with each group of ``factors`` (a name of :data:`UNCERTAINTY_GROUPS`)
        multiplied by its factor; the calibrated apparent stiffness of the slip elements and the
        validity box stay (they are not re-calibrated per sample)."""
        unknown = sorted(set(factors) - set(UNCERTAINTY_GROUPS))
        if unknown:
            raise CoefficientFileError(
                f"unknown coefficient group(s) {unknown}; allowed: {', '.join(UNCERTAINTY_GROUPS)}"
            )
        bad = {g: f for g, f in factors.items() if not (math.isfinite(f) and f > 0.0)}
        if bad:
            raise CoefficientFileError(f"coefficient factors must be finite and > 0, got {bad}")
        f = {g: float(factors.get(g, 1.0)) for g in UNCERTAINTY_GROUPS}

        def times(values: tuple[float, ...], k: float) -> tuple[float, ...]:
            return tuple(v * k for v in values)

        return dataclasses.replace(
            self,
            p_pos=times(self.p_pos, f["series"]),
            p_neg=times(self.p_neg, f["series"]),
            q_bend=times(self.q_bend, f["bending"]),
            beta=self.beta * f["stiffening"],
            conduit_fraction=(
                self.conduit_fraction[0] * f["conduit"],
                self.conduit_fraction[1] * f["conduit"],
            ),
            slip_f_fraction=_scaled(self.slip_f_fraction, f["slip_torque"]),
            bend_friction_per_rad=self.bend_friction_per_rad * f["bend_friction"],
            rating_coefficient=self.rating_coefficient * f["rating"],
        )

    @property
    def bend_limit_rad(self) -> float:
        """Largest |phi_B| of ``validity.bend_rad`` (eq. 3/4 depend on |phi_B| only)."""
        return max(abs(self.bend_range[0]), abs(self.bend_range[1]))

    def check_bend(self, bend_rad: float | Iterable[float], what: str = "bend angle") -> None:
        """Raise ShaftRangeError for a bend angle beyond ``validity.bend_rad``."""
        check_bend_rad(bend_rad, self.bend_limit_rad, self.source, what)

    def check_range(self, diameter_mm: float, length_mm: float, extrapolate: bool = False) -> None:
        """Raise ShaftRangeError for a shaft outside the validity box (unless extrapolating)."""
        for label, value, (lo, hi), unit in (
            ("diameter", diameter_mm, self.diameter_range, "mm"),
            ("length", length_mm, self.length_range, "mm"),
        ):
            if not math.isfinite(value) or value <= 0.0:
                raise ShaftRangeError(
                    f"shaft {label} must be a positive number, got {value!r} {unit}"
                )
            if not extrapolate and not lo <= value <= hi:
                raise ShaftRangeError(
                    f"shaft {label} {value:g} {unit} is outside the validity range "
                    f"[{lo:g}, {hi:g}] {unit} of {self.source} (seed 000 eq. 3/4 were fitted there); "
                    "pass extrapolate=True (CLI: --extrapolate) to use it anyway"
                )

    def eq2_fit_gain(self) -> float:
        """Eq. 4's K_b over the elastic K_b: what eq. 2's linear fit of the file's test adds
        (stiffening, ``bending.linear_fit_gain``, and the conduit branches' storage stiffness at
        the test's period, ``conduit_viscoelastic.storage_fraction``); 1 without a test."""
        if self.eq2_test_amplitude_rad <= 0.0:
            return 1.0
        gain = bending.linear_fit_gain(self.beta, self.eq2_test_amplitude_rad)
        for frac, tau in zip(self.conduit_fraction, self.conduit_tau, strict=True):
            gain += frac * conduit_viscoelastic.storage_fraction(tau, self.eq2_test_period_s)
        return gain

    def eq3(self, diameter_mm: float, length_mm: float, side: int) -> tuple[float, float]:
        """Eq. 3 of one side (+1 winding, -1 unwinding): (straight K, slope in |phi_B|), with
        the file's length law."""
        p = self.p_pos if side >= 0 else self.p_neg
        return series_stiffness.eq3_base_and_slope(
            p, diameter_mm, length_mm, self.series_reference_length_mm
        )

    def rating_nm(self, diameter_mm: float) -> float:
        """Nominal torque rating; depends on D only (seed 000 Sec. IV-A1)."""
        return self.rating_coefficient * diameter_mm**3

    def shaft(
        self,
        diameter_mm: float = PROTOTYPE_DIAMETER_MM,
        length_mm: float = PROTOTYPE_LENGTH_MM,
        *,
        extrapolate: bool = False,
        series_hysteresis: bool | None = None,
    ) -> ShaftParams:
        """Evaluate eq. 3 and eq. 4 for one shaft."""
        real_number(diameter_mm, "shaft diameter (mm)", ShaftRangeError)  # True is not 1 mm
        real_number(length_mm, "shaft length (mm)", ShaftRangeError)
        self.check_range(diameter_mm, length_mm, extrapolate)
        k_pos, s_pos = self.eq3(diameter_mm, length_mm, 1)
        k_neg, s_neg = self.eq3(diameter_mm, length_mm, -1)
        kb_eq4 = bending.eq4_stiffness_nm_per_rad(self.q_bend, diameter_mm, length_mm)
        kb = kb_eq4 / self.eq2_fit_gain()
        bend_max = self.bend_limit_rad
        k_min = min(k_pos + min(s_pos, 0.0) * bend_max, k_neg + min(s_neg, 0.0) * bend_max)
        if k_min <= 0.0 or kb <= 0.0:
            raise ShaftRangeError(
                f"shaft D={diameter_mm:g} mm, L={length_mm:g} mm gives a non-positive stiffness "
                f"(series min {k_min:.3g}, bending {kb:.3g} N*m/rad) with {self.source}: "
                "the eq. 3/4 polynomials are not valid there"
            )
        slip_on = self.slip_enabled if series_hysteresis is None else bool(series_hysteresis)
        if slip_on and max(self.slip_k_fraction) <= 0.0:
            raise CoefficientFileError(
                f"{self.source}: series hysteresis is switched on "
                f"({'by the caller' if series_hysteresis else 'by series.maxwell_slip.enabled'})"
                " but 'series.maxwell_slip.stiffness_fraction' gives no element a stiffness > 0, "
                "so it would have no effect; give the elements' stiffness fractions"
            )
        return ShaftParams(
            diameter_mm=diameter_mm,
            length_mm=length_mm,
            k_pos=k_pos,
            s_pos=s_pos,
            k_neg=k_neg,
            s_neg=s_neg,
            kb=kb,
            beta=self.beta,
            conduit_k=(self.conduit_fraction[0] * kb, self.conduit_fraction[1] * kb),
            conduit_tau=self.conduit_tau,
            inertia_kgm2=self.inertia_kgm2,
            damping_pos=self.damping_pos,
            damping_neg=self.damping_neg,
            slip_k=_scaled(self.slip_k_fraction, k_pos) if slip_on else (0.0, 0.0, 0.0),
            slip_f=_scaled(self.slip_f_fraction, self.rating_nm(diameter_mm)),
            slip_unwinding_ratio=self.slip_unwinding_ratio,
            bend_friction_per_rad=self.bend_friction_per_rad,
            slip_apparent=_scaled4(self.slip_apparent_fraction, k_pos) if slip_on else _ZERO4,
            rating_nm=self.rating_nm(diameter_mm),
            bend_limit_rad=bend_max,
            eq4_kb=kb_eq4,
            source=self.source,
        )


def check_bend_rad(
    bend_rad: float | Iterable[float], limit_rad: float, source: str, what: str = "bend angle"
) -> None:
    """The one bend-angle check (bench, sweep, arm runs): |phi_B| <= ``limit_rad``, the largest
    |bend| of the coefficient file's ``validity.bend_rad``; ShaftRangeError names the worst value,
    the range and the file."""
    if isinstance(bend_rad, bool | np.bool_) or (
        isinstance(bend_rad, np.ndarray) and bend_rad.dtype == np.bool_
    ):
        raise ShaftRangeError(f"{what} must be an angle in rad, got {bend_rad!r}")
    raw = bend_rad if isinstance(bend_rad, int | float | np.ndarray) else list(bend_rad)
    values = np.atleast_1d(np.asarray(raw, dtype=np.float64)).ravel()
    if values.size == 0:
        return
    if not np.all(np.isfinite(values)):
        bad = float(values[~np.isfinite(values)][0])
        raise ShaftRangeError(f"{what} must be a finite angle in rad, got {bad!r}")
    worst = float(values[int(np.argmax(np.abs(values)))])
    if abs(worst) > limit_rad + 1e-9:
        raise ShaftRangeError(
            f"{what}: {worst:.4g} rad ({math.degrees(worst):.1f} deg) is outside the validity "
            f"range [-{limit_rad:.4g}, {limit_rad:.4g}] rad "
            f"(+-{math.degrees(limit_rad):.0f} deg) of "
            f"{source} (its validity.bend_rad: seed 000 eq. 3/4 were fitted there, Sec. IV-C); "
            "keep |phi_B| within it or widen validity.bend_rad in your own coefficient file"
        )


# [uncertainty]: the coefficient groups a file may give a plausible range for, each a factor on
# the group's nominal coefficients (Catalogue.perturbed)
UNCERTAINTY_GROUPS: tuple[str, ...] = (
    "series",  # eq. 3, both sides (p_pos, p_neg)
    "bending",  # eq. 4 (q)
    "stiffening",  # bending.stiffening_per_rad2
    "conduit",  # bending.conduit.branch_stiffness_fraction
    "slip_torque",  # series.maxwell_slip.slip_torque_fraction
    "bend_friction",  # series.maxwell_slip.bend_friction_per_rad
    "rating",  # rating.coefficient_nm_per_mm3
)


@dataclass(frozen=True)
class CoefficientRange:
    """One ``[uncertainty.<group>]`` entry: the factor range on the group's nominal values."""

    group: str
    low: float
    high: float
    reason: str


def _scaled(fractions: tuple[float, float, float], scale: float) -> tuple[float, float, float]:
    return (fractions[0] * scale, fractions[1] * scale, fractions[2] * scale)


_ZERO4 = (0.0, 0.0, 0.0, 0.0)


def _scaled4(
    fractions: tuple[float, float, float, float], scale: float
) -> tuple[float, float, float, float]:
    return (
        fractions[0] * scale,
        fractions[1] * scale,
        fractions[2] * scale,
        fractions[3] * scale,
    )
