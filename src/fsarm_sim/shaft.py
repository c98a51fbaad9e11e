"""Shaft catalogue: coefficient files (seed 000 eq. 3/4) and the evaluated shaft parameters.

A coefficient file is TOML with the keys of ``data/shafts.toml`` (the default catalogue).
``load_catalogue(path)`` validates it; ``Catalogue.shaft(D, L)`` evaluates eq. 3 and eq. 4 for one
shaft and refuses D or L outside the validity range unless ``extrapolate=True``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from fsarm_sim.effects import bending, series_stiffness
from fsarm_sim.errors import CoefficientFileError, ShaftRangeError

DEFAULT_CATALOGUE = "shafts.toml"
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
    kb: float  # eq. 4
    beta: float  # bending stiffening, 1/rad^2
    conduit_k: tuple[float, float]  # Maxwell-branch stiffness, N*m/rad
    conduit_tau: tuple[float, float]  # Maxwell-branch time constants, s
    inertia_kgm2: float = 0.0  # eq. 1 J
    damping_pos: float = 0.0  # eq. 1 B_p
    damping_neg: float = 0.0  # eq. 1 B_n
    slip_k: tuple[float, float, float] = (0.0, 0.0, 0.0)
    slip_f: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rating_nm: float = 0.0
    bend_limit_rad: float = 2.0 * math.pi / 3.0

    def k_series(self, bend_rad: float, side: int) -> float:
        """Eq. 3 stiffness at a bend angle for side +1 (winding) or -1 (unwinding)."""
        twist = 1.0 if side >= 0 else -1.0
        return series_stiffness.stiffness_nm_per_rad(
            twist, bend_rad, self.k_pos, self.s_pos, self.k_neg, self.s_neg
        )

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
    slip_f_fraction: tuple[float, float, float]  # of the torque rating
    shafts: tuple[CatalogueShaft, ...] = field(default=())

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
        self.check_range(diameter_mm, length_mm, extrapolate)
        k_pos, s_pos = series_stiffness.eq3_base_and_slope(self.p_pos, diameter_mm, length_mm)
        k_neg, s_neg = series_stiffness.eq3_base_and_slope(self.p_neg, diameter_mm, length_mm)
        kb = bending.eq4_stiffness_nm_per_rad(self.q_bend, diameter_mm, length_mm)
        bend_max = max(abs(self.bend_range[0]), abs(self.bend_range[1]))
        k_min = min(k_pos + min(s_pos, 0.0) * bend_max, k_neg + min(s_neg, 0.0) * bend_max)
        if k_min <= 0.0 or kb <= 0.0:
            raise ShaftRangeError(
                f"shaft D={diameter_mm:g} mm, L={length_mm:g} mm gives a non-positive stiffness "
                f"(series min {k_min:.3g}, bending {kb:.3g} N*m/rad) with {self.source}: "
                "the eq. 3/4 polynomials are not valid there"
            )
        slip_on = self.slip_enabled if series_hysteresis is None else series_hysteresis
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
            rating_nm=self.rating_nm(diameter_mm),
            bend_limit_rad=bend_max,
        )


def _scaled(fractions: tuple[float, float, float], scale: float) -> tuple[float, float, float]:
    return (fractions[0] * scale, fractions[1] * scale, fractions[2] * scale)


def _get(table: dict[str, Any], dotted: str, source: str) -> Any:
    node: Any = table
    for key in dotted.split("."):
        if not isinstance(node, dict) or key not in node:
            raise CoefficientFileError(f"{source}: missing key '{dotted}'")
        node = node[key]
    return node


def _floats(
    value: Any, n: int, dotted: str, source: str, *, positive: bool = False
) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise CoefficientFileError(
            f"{source}: '{dotted}' must be a list of {n} numbers, got {value!r}"
        )
    out = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(float(v)):
            raise CoefficientFileError(
                f"{source}: '{dotted}'[{i}] must be a finite number, got {v!r}"
            )
        if positive and float(v) < 0.0:
            raise CoefficientFileError(f"{source}: '{dotted}'[{i}] must be >= 0, got {v!r}")
        out.append(float(v))
    return tuple(out)


def _float(value: Any, dotted: str, source: str, *, minimum: float | None = None) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(float(value))
    ):
        raise CoefficientFileError(f"{source}: '{dotted}' must be a finite number, got {value!r}")
    if minimum is not None and float(value) < minimum:
        raise CoefficientFileError(f"{source}: '{dotted}' must be >= {minimum}, got {value!r}")
    return float(value)


def parse_catalogue(data: dict[str, Any], source: str) -> Catalogue:
    """Validate a parsed coefficient table; every problem is a CoefficientFileError."""
    p_pos = _floats(_get(data, "series.positive.p", source), 7, "series.positive.p", source)
    p_neg = _floats(_get(data, "series.negative.p", source), 7, "series.negative.p", source)
    q_bend = _floats(_get(data, "bending.q", source), 5, "bending.q", source)
    beta = _float(
        _get(data, "bending.stiffening_per_rad2", source),
        "bending.stiffening_per_rad2",
        source,
        minimum=0.0,
    )
    frac = _floats(
        _get(data, "bending.conduit.branch_stiffness_fraction", source),
        2,
        "bending.conduit.branch_stiffness_fraction",
        source,
        positive=True,
    )
    tau = _floats(
        _get(data, "bending.conduit.branch_time_constant_s", source),
        2,
        "bending.conduit.branch_time_constant_s",
        source,
        positive=True,
    )
    if min(tau) <= 0.0:
        raise CoefficientFileError(
            f"{source}: 'bending.conduit.branch_time_constant_s' must be > 0, got {tau}"
        )
    d_rng = _floats(
        _get(data, "validity.diameter_mm", source), 2, "validity.diameter_mm", source, positive=True
    )
    l_rng = _floats(
        _get(data, "validity.length_mm", source), 2, "validity.length_mm", source, positive=True
    )
    b_rng = _floats(_get(data, "validity.bend_rad", source), 2, "validity.bend_rad", source)
    for name, rng in (
        ("validity.diameter_mm", d_rng),
        ("validity.length_mm", l_rng),
        ("validity.bend_rad", b_rng),
    ):
        if rng[0] >= rng[1]:
            raise CoefficientFileError(
                f"{source}: '{name}' must be [low, high] with low < high, got {list(rng)}"
            )
    rating = _float(
        _get(data, "rating.coefficient_nm_per_mm3", source),
        "rating.coefficient_nm_per_mm3",
        source,
        minimum=0.0,
    )
    dyn = data.get("series", {}).get("dynamic", {})
    slip = data.get("series", {}).get("maxwell_slip", {})
    slip_k = _floats(
        slip.get("stiffness_fraction", [0.0, 0.0, 0.0]),
        3,
        "series.maxwell_slip.stiffness_fraction",
        source,
        positive=True,
    )
    slip_f = _floats(
        slip.get("slip_torque_fraction", [0.0, 0.0, 0.0]),
        3,
        "series.maxwell_slip.slip_torque_fraction",
        source,
        positive=True,
    )
    shafts = []
    for i, entry in enumerate(data.get("shafts", [])):
        if not isinstance(entry, dict):
            raise CoefficientFileError(f"{source}: shafts[{i}] must be a table")
        shafts.append(
            CatalogueShaft(
                name=str(entry.get("name", f"shaft{i}")),
                diameter_mm=_float(
                    entry.get("diameter_mm"), f"shafts[{i}].diameter_mm", source, minimum=0.0
                ),
                length_mm=_float(
                    entry.get("length_mm"), f"shafts[{i}].length_mm", source, minimum=0.0
                ),
            )
        )
    return Catalogue(
        source=source,
        p_pos=p_pos,
        p_neg=p_neg,
        q_bend=q_bend,
        beta=beta,
        conduit_fraction=(frac[0], frac[1]),
        conduit_tau=(tau[0], tau[1]),
        diameter_range=(d_rng[0], d_rng[1]),
        length_range=(l_rng[0], l_rng[1]),
        bend_range=(b_rng[0], b_rng[1]),
        rating_coefficient=rating,
        inertia_kgm2=_float(
            dyn.get("inertia_kgm2", 0.0), "series.dynamic.inertia_kgm2", source, minimum=0.0
        ),
        damping_pos=_float(
            dyn.get("damping_pos_nms", 0.0), "series.dynamic.damping_pos_nms", source, minimum=0.0
        ),
        damping_neg=_float(
            dyn.get("damping_neg_nms", 0.0), "series.dynamic.damping_neg_nms", source, minimum=0.0
        ),
        slip_enabled=bool(slip.get("enabled", False)),
        slip_k_fraction=(slip_k[0], slip_k[1], slip_k[2]),
        slip_f_fraction=(slip_f[0], slip_f[1], slip_f[2]),
        shafts=tuple(shafts),
    )


def load_catalogue(path: str | Path | None = None) -> Catalogue:
    """Load and validate a coefficient file; None loads the default (estimated) catalogue."""
    if path is None:
        text = resources.files("fsarm_sim.data").joinpath(DEFAULT_CATALOGUE).read_text("utf-8")
        source = f"default catalogue ({DEFAULT_CATALOGUE})"
    else:
        p = Path(path)
        if not p.is_file():
            raise CoefficientFileError(
                f"coefficient file not found: {p} (expected a TOML file like the default shafts.toml)"
            )
        try:
            text = p.read_text("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise CoefficientFileError(f"cannot read coefficient file {p}: {exc}") from exc
        source = str(p)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CoefficientFileError(f"{source}: not valid TOML ({exc})") from exc
    return parse_catalogue(data, source)
