"""Disturbance observer on joint 3: nominal-model inverse with a first-order Q filter.

Joint 3's nominal model is the rigid link driven by the shaft through the hypoid:

    M33(q) qdd3 = i_G2 tau_shaft - bias3(q, qd)

with ``M33`` and ``bias3`` (gravity, Coriolis) from the model, as the outer computed-torque loop
uses them, and ``tau_shaft`` the virtual torque sensor's eq. 8 estimate. Whatever the joint does
beyond that - the shaft hysteresis that eq. 8 misses, the hypoid's viscous damping, an unstated
payload - is a lumped disturbance ``d``. The observer estimates it through a low-pass Q filter of
cut-off ``w_q`` without differentiating the encoder twice (the standard rearrangement of
``Q (i_G2 tau - bias - M33 s qd3)`` with ``Q = w_q / (s + w_q)``):

    y' = w_q (i_G2 tau_m - bias3 + M33 w_q qd3 - y),     d_hat = y - M33 w_q qd3

and the outer loop adds ``d_hat`` to the desired joint torque. ``w_q`` must stay below the torque
loop's bandwidth (the observer then sees the torque loop as ideal). Forward Euler per control
tick; pure functions of floats (Numba compiles them into the native callbacks).
"""

from __future__ import annotations


def observer_input(tau_joint: float, bias: float, inertia: float, qd: float, wq: float) -> float:
    """The Q filter's input: i_G2 tau_m - bias3 + M33 w_q qd3 (``tau_joint`` = i_G2 tau_m)."""
    return tau_joint - bias + inertia * wq * qd


def observer_step(y: float, u: float, wq: float, dt: float) -> float:
    """One forward-Euler tick of the first-order Q filter state."""
    return y + dt * wq * (u - y)


def disturbance(y: float, inertia: float, qd: float, wq: float) -> float:
    """The lumped disturbance estimate d_hat = y - M33 w_q qd3 (N*m at the joint)."""
    return y - inertia * wq * qd
