"""Series elasticity of the flexible shaft at joint 3 (seed 000 eq. 1, 3, 8).

Twist ``twist_rad = theta_m - theta_s``; positive is the winding direction of the outermost coil,
the stiffer side. Stiffness per side falls linearly with the bend angle (eq. 3):

    K(phi) = k_base + k_slope * |phi|        (k_slope < 0)

where ``k_base = p0 + p1 D + p2 D^2 + p3 D^3 + p4 L`` and ``k_slope = p5 + p6 D^2`` are evaluated
once per shaft (see :mod:`fsarm_sim.plant.shaft`).

Length law. Eq. 3 as printed is affine in L (one ``p4 L`` term for every D): the paper's regression
over its nine shafts. A uniform shaft is ``L / dL`` equal pieces in series, so its torsional
stiffness scales as ``1 / L`` whatever its construction (seed 000 Sec. II-A: "like traditional
springs, the increase in length ... results in decreased torsional stiffness"; seed 001 Sec. 2.2
measured 8 mm x 865 mm at ~5.3 N*m/rad, which the 1/L law predicts from the 450 mm catalogue
within ~6 %). An affine term cannot do that for thin and thick shafts at once (a slope steep enough
for 9 mm drives 4 mm negative). A coefficient file may therefore declare the *inverse* law: eq. 3
is evaluated at a reference length ``L_ref`` and scaled by ``L_ref / L``,

    K(D, L, phi) = K_eq3(D, L_ref, phi) * L_ref / L         (``reference_length_mm`` = L_ref > 0),

and ``reference_length_mm = 0`` keeps eq. 3 exactly as printed. The default catalogue
(``data/shafts.toml``) uses eq. 3 as printed, the paper's own form; ``data/shafts_inverse_length.toml``
is the same catalogue with the inverse law.
"""

from __future__ import annotations

import math


def eq3_base_and_slope(
    p: tuple[float, ...], diameter_mm: float, length_mm: float, reference_length_mm: float = 0.0
) -> tuple[float, float]:
    """Split seed 000 eq. 3 into its bend-independent part and its slope in |phi_B|.

    ``reference_length_mm`` > 0 selects the inverse length law (module docstring): eq. 3 at
    ``L_ref`` scaled by ``L_ref / L``; 0 evaluates eq. 3 as printed (affine in L)."""
    d = diameter_mm
    ell = reference_length_mm if reference_length_mm > 0.0 else length_mm
    base = p[0] + p[1] * d + p[2] * d * d + p[3] * d * d * d + p[4] * ell
    slope = p[5] + p[6] * d * d
    if reference_length_mm > 0.0:
        scale = reference_length_mm / length_mm
        return base * scale, slope * scale
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
