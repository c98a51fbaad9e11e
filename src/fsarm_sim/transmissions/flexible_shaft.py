"""The flexible shaft (seed 000): the default joint-3 transmission, seen through the interface.

The simulator's kernels run the flexible shaft from its own parameter slots (eq. 3/8 asymmetric
stiffness per twist sign falling with |phi_B|, eq. 1 damping, Maxwell-slip series hysteresis:
:mod:`fsarm_sim.effects.series_stiffness`, :mod:`fsarm_sim.effects.maxwell_slip`, see
:mod:`fsarm_sim.physics`). This module states the same elastic law on the generic parameter
block, so analyses written against :class:`fsarm_sim.transmissions.base.Transmission` (bandwidth,
comparison tables, static twist) treat all transmissions alike. ``model.write_params`` fills the
block from the run's :class:`fsarm_sim.shaft.ShaftParams`, so both views carry the same numbers.
"""

from __future__ import annotations

from typing import Any

from fsarm_sim.effects import series_stiffness
from fsarm_sim.shaft import load_catalogue
from fsarm_sim.transmissions.base import (
    FloatArray,
    Param,
    TransmissionError,
    any_finite,
    non_negative,
    positive,
)

NAME = "flexible-shaft"
TITLE = "Flexible shaft, asymmetric series stiffness (seed 000)"
SOURCE = "seed 000 eq. 1, 3, 8 (coefficients: src/fsarm_sim/data/shafts.toml, estimates)"
ROUTED_OVER_JOINT2 = True
TWIST_RANGE_RAD = 1.0  # estimate: about 1.5x the twist at rated torque of the default shaft
STATES: tuple[str, ...] = ()  # slip states live in the shaft's own slots


_K_WHY = (
    "eq. 3's straight stiffness: > 0 (a spring); a stiffness too high for the timestep is "
    "refused at build"
)
_S_WHY = (
    "eq. 3's slope in |phi_B|: either sign as fitted; the stiffness at the largest bend of the "
    "validity range must stay > 0 (checked across parameters)"
)
_B_WHY = "eq. 1 damping must be >= 0 (dissipative; < 0 would feed energy in)"


def _params() -> tuple[Param, ...]:
    sh = load_catalogue().shaft()
    src = f"catalogue default shaft {sh.diameter_mm:g} x {sh.length_mm:g} mm (estimates)"
    return (
        Param(
            "k_pos", sh.k_pos, "N*m/rad", f"eq. 3 winding side, straight; {src}", positive(_K_WHY)
        ),
        Param(
            "s_pos",
            sh.s_pos,
            "N*m/rad^2",
            f"eq. 3 winding side slope in |phi_B|; {src}",
            any_finite(_S_WHY),
        ),
        Param(
            "k_neg", sh.k_neg, "N*m/rad", f"eq. 3 unwinding side, straight; {src}", positive(_K_WHY)
        ),
        Param(
            "s_neg", sh.s_neg, "N*m/rad^2", f"eq. 3 unwinding side slope; {src}", any_finite(_S_WHY)
        ),
        Param("b_pos", sh.damping_pos, "N*m*s/rad", f"eq. 1 B_p; {src}", non_negative(_B_WHY)),
        Param("b_neg", sh.damping_neg, "N*m*s/rad", f"eq. 1 B_n; {src}", non_negative(_B_WHY)),
        Param(
            "rating_nm",
            sh.rating_nm,
            "N*m",
            f"nominal torque of the shaft; {src}",
            positive("a torque rating: > 0 (it sizes test signals and flags overloads)"),
        ),
    )


PARAMS = _params()
BEND_LIMIT_RAD = load_catalogue().bend_limit_rad  # the default file's validity.bend_rad


def validate(tr: FloatArray) -> None:
    """Cross-parameter check: eq. 3 stays > 0 on both sides up to the largest valid bend."""
    for side, k, slope in (("pos", tr[0], tr[1]), ("neg", tr[2], tr[3])):
        k_bent = float(k + min(float(slope), 0.0) * BEND_LIMIT_RAD)
        if k_bent <= 0.0:
            raise TransmissionError(
                f"transmission {NAME!r}: k_{side} = {float(k)!r} N*m/rad with s_{side} = "
                f"{float(slope)!r} N*m/rad^2 gives stiffness {k_bent:.4g} N*m/rad <= 0 at the "
                f"largest valid bend {BEND_LIMIT_RAD:.4g} rad: eq. 3 must stay > 0 there"
            )


def sensor_torque_nm(tr: Any, x: float, bend: float) -> float:
    return series_stiffness.elastic_torque_nm(x, bend, tr[0], tr[1], tr[2], tr[3])


def stiffness_nm_per_rad(tr: Any, x: float, bend: float) -> float:
    return series_stiffness.stiffness_nm_per_rad(x, bend, tr[0], tr[1], tr[2], tr[3])


def torque_nm(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int) -> float:
    return sensor_torque_nm(tr, x, bend) + series_stiffness.damping_torque_nm(x, xdot, tr[4], tr[5])


def state_rate(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int, i: int) -> float:
    return 0.0


def rating_nm(tr: Any) -> float:
    return float(tr[6])


def potential_j(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    return series_stiffness.potential_j(x, bend, tr[0], tr[1], tr[2], tr[3])
