"""Series elasticity of the flexible shaft at joint 3 (seed 000 eq. 1, 3, 8).

Twist ``twist_rad = theta_m - theta_s``; positive is the winding direction of the outermost coil,
the stiffer side. Stiffness per side falls linearly with the bend angle (eq. 3):

    K(phi) = k_base + k_slope * |phi|        (k_slope < 0)

where ``k_base = p0 + p1 D + p2 D^2 + p3 D^3 + p4 L`` and ``k_slope = p5 + p6 D^2`` are evaluated
once per shaft (see :mod:`fsarm_sim.plant.shaft`).
"""

from __future__ import annotations

import math


def eq3_base_and_slope(
    p: tuple[float, ...], diameter_mm: float, length_mm: float
) -> tuple[float, float]:
    """Split seed 000 eq. 3 into its bend-independent part and its slope in |phi_B|."""
    d = diameter_mm
    base = p[0] + p[1] * d + p[2] * d * d + p[3] * d * d * d + p[4] * length_mm
    slope = p[5] + p[6] * d * d
    return base, slope


def stiffness_nm_per_rad(
    twist_rad: float, bend_rad: float, k_pos: float, s_pos: float, k_neg: float, s_neg: float
) -> float:
    """Eq. 3/8 stiffness of the side selected by the sign of the twist (>= 0: winding side)."""
    if twist_rad >= 0.0:
        return k_pos + s_pos * abs(bend_rad)
    return k_neg + s_neg * abs(bend_rad)


def elastic_torque_nm(
    twist_rad: float, bend_rad: float, k_pos: float, s_pos: float, k_neg: float, s_neg: float
) -> float:
    """Seed 000 eq. 8: tau = K_sp(phi) * twist (twist >= 0), K_sn(phi) * twist (twist < 0)."""
    return stiffness_nm_per_rad(twist_rad, bend_rad, k_pos, s_pos, k_neg, s_neg) * twist_rad


def damping_torque_nm(twist_rad: float, twist_rate: float, b_pos: float, b_neg: float) -> float:
    """The B_p / B_n term of eq. 1, side selected by the sign of the twist."""
    return (b_pos if twist_rad >= 0.0 else b_neg) * twist_rate


def potential_j(
    twist_rad: float, bend_rad: float, k_pos: float, s_pos: float, k_neg: float, s_neg: float
) -> float:
    """Elastic energy 0.5 K(phi) twist^2 of eq. 8 (piecewise quadratic, C1 at zero twist)."""
    return (
        0.5 * stiffness_nm_per_rad(twist_rad, bend_rad, k_pos, s_pos, k_neg, s_neg) * twist_rad**2
    )


def bend_coupling_torque_nm(twist_rad: float, bend_rad: float, s_pos: float, s_neg: float) -> float:
    """-dV/dphi: the torque on the bend coordinate that makes eq. 8 energy-consistent.

    Eq. 8's stiffness depends on phi_B, so a twisted shaft stores energy that changes when joint 2
    bends it. Without this term the model would create or destroy energy. For the prototype at
    its rated torque it is 0.5-0.6 N*m at 45 deg of bend and 0.8 N*m at 90 deg (measured with
    this function); seed 000 observed that torsion does not change the bending moment noticeably
    (Sec. III-B2) - at fig14-sine's shaft torque it is ~2 mN*m.
    """
    slope = s_pos if twist_rad >= 0.0 else s_neg
    return (
        -0.5 * twist_rad * twist_rad * slope * math.copysign(1.0, bend_rad)
        if bend_rad != 0.0
        else 0.0
    )
