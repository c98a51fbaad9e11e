"""Seed 003's arc-magnet comparison spring (AMS of [42]) beside our flat-magnet spring (FMS).

Source: /work/shared/seeds/003_4193e96e88679a8c.txt Sec. 7.1: the FMS's stable and linear ranges
are 31.5 deg and 19.7 deg; "as a reference, in paper [42] where the same number of pole pairs was
used these values were about: 26 deg (87 %) and 11 deg (37 %)". Sec. 3: AMS characteristics are
trapezoidal, their safe and linear ranges narrow; the abstract: "choosing flat magnets over arc
ones enables shaping spring characteristics in a way that broadens the safe range".

What the text gives is the two range numbers of each spring; what it does not give is either
spring's torque curve. Both are therefore written in eq. 1's form (three harmonics of the 120 deg
period) with the shape ratios ``b2/b1, b3/b1`` solved from the spring's two numbers
(:func:`solve_shape`: zero stiffness at the stable-range limit, torque 5 % off the linearised one
at the linear-range limit; the solution is unique near the pure sinusoid). For the FMS that gives
back the ratios of :mod:`fsarm_sim.plant.transmissions.magnetic_spring`. The AMS's torque scale is
not given either: :func:`arc_overrides` gives it the FMS's peak torque, so that the two shapes
compare at equal strength. A safe range (Sec. 3: a margin below the stable range, size left to the
user) is the twist at which the torque reaches a fraction of the maximal torque.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fsarm_sim.errors import FsarmError

DEG = math.pi / 180.0
ARC_STABLE_DEG = 26.0  # Sec. 7.1, [42] "about 26 deg (87 %)"
ARC_LINEAR_DEG = 11.0  # Sec. 7.1, [42] "about 11 deg (37 %)"
LINEAR_TOLERANCE = 0.05  # Sec. 3: the 5 % rule
SAFE_MARGINS = (0.8, 0.9, 0.95)  # fractions of the maximal torque (Sec. 3 gives no number)


class ArcSpringError(FsarmError, ValueError):
    """Range numbers no three-harmonic eq. 1 shape can meet."""


def _shape(x: float, r2: float, r3: float) -> float:
    return math.sin(3.0 * x) + r2 * math.sin(6.0 * x) + r3 * math.sin(12.0 * x)


def _slope(x: float, r2: float, r3: float) -> float:
    return 3.0 * math.cos(3.0 * x) + 6.0 * r2 * math.cos(6.0 * x) + 12.0 * r3 * math.cos(12.0 * x)


def solve_shape(stable_deg: float, linear_deg: float) -> tuple[float, float]:
    """(b2/b1, b3/b1) of eq. 1 with the given stable and linear (5 %) range at d = 0."""
    from scipy.optimize import fsolve

    if not (0.0 < linear_deg < stable_deg < 60.0):
        raise ArcSpringError(
            f"need 0 < linear range < stable range < 60 deg (half the 120 deg period), got "
            f"{linear_deg!r}, {stable_deg!r}"
        )
    xs, xl = stable_deg * DEG, linear_deg * DEG

    def eqs(p: np.ndarray) -> list[float]:
        r2, r3 = float(p[0]), float(p[1])
        k0 = _slope(0.0, r2, r3)
        return [_slope(xs, r2, r3), abs(_shape(xl, r2, r3) - k0 * xl) - LINEAR_TOLERANCE * k0 * xl]

    sol, _, ier, msg = fsolve(eqs, np.array([0.0, 0.0]), full_output=True)
    r2, r3 = float(sol[0]), float(sol[1])
    if ier != 1 or max(abs(v) for v in eqs(sol)) > 1e-9:
        raise ArcSpringError(f"no eq. 1 shape meets {stable_deg} / {linear_deg} deg: {msg}")
    return r2, r3


def fms_overrides() -> dict[str, float]:
    """Our spring as it is (the module's defaults)."""
    from fsarm_sim.plant.transmissions import magnetic_spring as ms

    b = ms.default_block()
    return {"b1": float(b[ms.I_B1]), "b2": float(b[ms.I_B2]), "b3": float(b[ms.I_B3])}


def arc_overrides() -> dict[str, float]:
    """The AMS shape (26 / 11 deg) scaled to the FMS's maximal torque at d = 0."""
    from fsarm_sim.plant.transmissions import magnetic_spring as ms

    r2, r3 = solve_shape(ARC_STABLE_DEG, ARC_LINEAR_DEG)
    unit = ms.default_block({"b1": 1.0, "b2": r2, "b3": r3})
    peak_unit = ms.max_torque_nm(0.0, unit)
    peak_fms = ms.max_torque_nm(0.0, ms.default_block())
    b1 = peak_fms / peak_unit
    return {"b1": b1, "b2": r2 * b1, "b3": r3 * b1}


@dataclass(frozen=True)
class SpringRanges:
    name: str
    stable_deg: float
    linear_deg: float
    safe_deg: dict[float, float]  # torque fraction -> safe range
    max_torque_nm: float
    stiffness_nm_per_rad: float


def ranges(name: str, overrides: dict[str, float]) -> SpringRanges:
    from fsarm_sim.plant.transmissions import magnetic_spring as ms

    b = ms.default_block(overrides)
    return SpringRanges(
        name=name,
        stable_deg=ms.stable_range_rad(0.0, b) / DEG,
        linear_deg=ms.linear_range_rad(0.0, b) / DEG,
        safe_deg={f: ms.safe_range_rad(0.0, f, b) / DEG for f in SAFE_MARGINS},
        max_torque_nm=ms.max_torque_nm(0.0, b),
        stiffness_nm_per_rad=ms.stiffness_at_equilibrium(0.0, b),
    )


def compare() -> tuple[SpringRanges, SpringRanges]:
    """(FMS, AMS) at d = 0 and equal maximal torque."""
    return ranges("FMS (ours)", fms_overrides()), ranges("AMS [42]", arc_overrides())
