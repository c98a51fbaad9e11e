"""Sensor offset: a constant bias on a measured channel (torque sensor zeroed under load, an
encoder zeroed at a twisted shaft). ``reading = true value + offset``.

On an input channel (``theta_m``, ``phi_b``) the model sees the bias as a shift of the deflection
axis; on the output channel (``tau_s``, ``m_b``) as a shift of the torque axis. For a linear,
symmetric law the two are indistinguishable (``K c``); with eq. 8's two slopes they are not.
"""

from __future__ import annotations


def reading(true_value: float, offset: float) -> float:
    """What a sensor with a constant bias reports."""
    return true_value + offset


def true_value(reading_value: float, offset: float) -> float:
    """The physical quantity behind a biased reading (inverse of :func:`reading`)."""
    return reading_value - offset
