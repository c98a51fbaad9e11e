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
* :func:`masterflex08_torque_nm`, seed 001 Table 1 itself (Δθ in degrees in the paper), usable as
  a "real" curve for synthetic data and as a check of how far eq. 8 can be trusted. The small
  dissipative term ``c Δθ'`` of Table 1 (c = 3e-5 N*m per deg/s) is left to the damping effect.
"""

from __future__ import annotations

import math

# seed 001 Table 1, MasterFlex08 8 mm x 865 mm. Twist in degrees, torque in N*m.
MF08_LENGTH_MM = 865.0
MF08_POS = (4.202, -4.201, 0.0, 0.0, 0.1622, 0.0, 0.0, 0.03322)  # a0, a1..a3, b1..b3, omega
MF08_NEG = (-3.107, 2.335, 0.7484, 0.02559, -1.487, 0.3618, 0.1976, 0.04357)
MF08_RANGE_DEG = 90.0  # the measured range (seed 001 Fig. 5); beyond it: linear extension
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


def _fourier(c: tuple[float, ...], x_deg: float) -> float:
    w = c[7]
    v = c[0]
    for n in range(1, 4):
        v += c[n] * math.cos(n * w * x_deg) + c[n + 3] * math.sin(n * w * x_deg)
    return v


def _fourier_slope(c: tuple[float, ...], x_deg: float) -> float:
    w = c[7]
    v = 0.0
    for n in range(1, 4):
        v += n * w * (-c[n] * math.sin(n * w * x_deg) + c[n + 3] * math.cos(n * w * x_deg))
    return v


def masterflex08_torque_nm(twist_rad: float, twist_scale: float) -> float:
    """Seed 001 Table 1 torque at ``twist_rad * twist_scale`` (the MasterFlex08's own twist).

    ``twist_scale = 865 mm / L`` makes a shaft of length ``L`` with the same twist per length.
    The series is shifted so that it passes exactly through the origin (the paper forced it to;
    the printed, rounded coefficients miss by 1-2 mN*m) and continued linearly beyond the
    measured +-90 deg with its end slope (a Fourier series turns over outside its data).
    """
    x = twist_rad * twist_scale / DEG
    c = MF08_POS if x >= 0.0 else MF08_NEG
    zero = _fourier(c, 0.0)
    lim = MF08_RANGE_DEG if x >= 0.0 else -MF08_RANGE_DEG
    if abs(x) <= MF08_RANGE_DEG:
        return _fourier(c, x) - zero
    return _fourier(c, lim) - zero + _fourier_slope(c, lim) * (x - lim)


def masterflex08_stiffness(twist_rad: float, twist_scale: float) -> float:
    """d(tau)/d(twist) of :func:`masterflex08_torque_nm`, N*m/rad."""
    x = twist_rad * twist_scale / DEG
    c = MF08_POS if x >= 0.0 else MF08_NEG
    xe = max(-MF08_RANGE_DEG, min(MF08_RANGE_DEG, x))
    return _fourier_slope(c, xe) * twist_scale / DEG
