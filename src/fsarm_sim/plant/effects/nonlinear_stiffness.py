"""Nonlinear stiffness: a torque-deflection curve that bends away from eq. 8's straight lines.

Seed 000 eq. 8 is linear per twist sign (and Fig. 9's bending moment "nearly linear"); the one
*measured* shaft curve in the seeds - seed 001 Table 1, MasterFlex08 (8 mm x 865 mm), a Fourier
series per twist sign - is clearly not: it is soft near zero twist and stiffens (1 - cos shape).

Two laws live here:

* :func:`polynomial_torque_nm`, the form the discrepancy workflow fits (one coefficient set per
  deflection sign; ``r = x / x_ref`` with a reference deflection ``x_ref``, so that ``c2, c3``
  are the extra torques, N*m, the two terms add at ``x = x_ref``)::

      tau = k x + c2 r |r| + c3 r^3

  ``c2, c3 > 0`` stiffen, ``< 0`` soften; ``c2 = c3 = 0`` is eq. 8. Linear in every coefficient
  (a least-squares data matrix fits it directly) and conservative (the gradient of
  :func:`polynomial_potential_j`).
* :func:`masterflex08_torque_nm`, seed 001 Table 1 itself, usable as a "real" curve for synthetic
  data and as a check of how far eq. 8 can be trusted. There is one implementation of that curve
  in the project - the RTCA transmission's straight law (:mod:`fsarm_sim.plant.transmissions.rtca`,
  published block: the fitted range |T| <= 5 N*m of seed 001 Sec. 3.2, continued linearly with
  the end slope beyond it) - and this law evaluates it (without that law's dead zone, which the
  backlash effect stands for here). The small dissipative term ``c Δθ'`` of Table 1
  (c = 3e-5 N*m per deg/s) is left to the damping effect.
"""

from __future__ import annotations

import math

from fsarm_sim.plant.transmissions import rtca
from fsarm_sim.plant.transmissions.base import fill_block

# seed 001 Table 1, MasterFlex08 8 mm x 865 mm (twist in degrees, torque in N*m): the RTCA
# transmission's published block is the one copy of it
MF08_LENGTH_MM = 865.0
MF08_POS = rtca.TABLE1_POS  # a0, a1..a3, b1..b3, omega
MF08_NEG = rtca.TABLE1_NEG
# the printed curve through the origin: the RTCA law's dead zone (its negative branch held at zero
# where the printed series runs the wrong way, a play-like feature of its own) is left to the
# backlash effect here
# (the RTCA law's own cross-check refuses that: within 6.6 mrad the printed series falls by
# 0.2 N*m/rad - kept as printed for this synthetic-truth law)
MF08_BLOCK = fill_block(rtca.NAME, rtca.PARAMS, {"x_dead_neg": 0.0})
DEG = math.pi / 180.0


def polynomial_torque_nm(x: float, k: float, c2: float, c3: float, x_ref: float) -> float:
    """``k x + c2 r |r| + c3 r^3`` with ``r = x / x_ref`` (``x_ref > 0``)."""
    r = x / x_ref
    return k * x + c2 * r * abs(r) + c3 * r * r * r


def polynomial_potential_j(x: float, k: float, c2: float, c3: float, x_ref: float) -> float:
    """Energy whose gradient is :func:`polynomial_torque_nm`."""
    r = x / x_ref
    return 0.5 * k * x * x + x_ref * (c2 * abs(r) ** 3 / 3.0 + c3 * r**4 / 4.0)


def polynomial_stiffness(x: float, k: float, c2: float, c3: float, x_ref: float) -> float:
    """Local stiffness d(tau)/dx."""
    r = x / x_ref
    return k + (2.0 * c2 * abs(r) + 3.0 * c3 * r * r) / x_ref


def masterflex08_torque_nm(twist_rad: float, twist_scale: float) -> float:
    """Seed 001 Table 1 torque at ``twist_rad * twist_scale`` (the MasterFlex08's own twist).

    ``twist_scale = 865 mm / L`` makes a shaft of length ``L`` with the same twist per length.
    The RTCA transmission's straight law on its published block (module docstring).
    """
    return rtca.straight_elastic_nm(MF08_BLOCK, twist_rad * twist_scale)


def masterflex08_stiffness(twist_rad: float, twist_scale: float) -> float:
    """d(tau)/d(twist) of :func:`masterflex08_torque_nm`, N*m/rad."""
    return rtca.straight_stiffness(MF08_BLOCK, twist_rad * twist_scale) * twist_scale
