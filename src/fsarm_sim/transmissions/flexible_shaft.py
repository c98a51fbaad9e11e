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
from fsarm_sim.transmissions.base import Param

NAME = "flexible-shaft"
TITLE = "Flexible shaft, asymmetric series stiffness (seed 000)"
SOURCE = "seed 000 eq. 1, 3, 8 (coefficients: src/fsarm_sim/data/shafts.toml, estimates)"
ROUTED_OVER_JOINT2 = True
TWIST_RANGE_RAD = 1.0  # estimate: about 1.5x the twist at rated torque of the default shaft
STATES: tuple[str, ...] = ()  # slip states live in the shaft's own slots


def _params() -> tuple[Param, ...]:
    sh = load_catalogue().shaft()
    src = f"catalogue default shaft {sh.diameter_mm:g} x {sh.length_mm:g} mm (estimates)"
    return (
        Param("k_pos", sh.k_pos, "N*m/rad", f"eq. 3 winding side, straight; {src}"),
        Param("s_pos", sh.s_pos, "N*m/rad^2", f"eq. 3 winding side slope in |phi_B|; {src}"),
        Param("k_neg", sh.k_neg, "N*m/rad", f"eq. 3 unwinding side, straight; {src}"),
        Param("s_neg", sh.s_neg, "N*m/rad^2", f"eq. 3 unwinding side slope; {src}"),
        Param("b_pos", sh.damping_pos, "N*m*s/rad", f"eq. 1 B_p; {src}"),
        Param("b_neg", sh.damping_neg, "N*m*s/rad", f"eq. 1 B_n; {src}"),
        Param("rating_nm", sh.rating_nm, "N*m", f"nominal torque of the shaft; {src}"),
    )


PARAMS = _params()


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
