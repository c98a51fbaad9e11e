"""Viscous damping: a torque proportional to a velocity (seed 000 eq. 1 ``B dtheta/dt``; seed 003
Table 5 ``-y phi_out'`` / ``-z (phi_out' - phi_in')``).

On a bench it acts either in parallel with the shaft spring (rate of twist or of bend, eq. 1's
``B_p, B_n``; the torque sensor reads it) or on the load bearing (load speed; the sensor sees it
only through the load's motion). The damper carries ``b * rate``; whoever applies it decides the
sign (it always resists the rate), so it dissipates ``b rate^2 >= 0``.
"""

from __future__ import annotations


def damper_torque_nm(rate: float, b: float) -> float:
    """Torque the damper carries at ``rate`` (rad/s): ``b * rate``."""
    return b * rate


def dissipation_w(rate: float, b: float) -> float:
    """Power dissipated: ``b rate^2`` (never negative for b >= 0)."""
    return b * rate * rate
