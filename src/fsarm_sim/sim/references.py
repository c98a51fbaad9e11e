"""Reference trajectories as pure functions of time: positions, velocities, accelerations.

Each returns an array of shape (len(t), 3) per quantity; scenarios stack them into the reference
table the controller reads (``q_ref[3], qd_ref[3], qdd_ref[3]`` per control tick).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
Triple = tuple[Array, Array, Array]


def hold(t: Array, value: float) -> Triple:
    """Constant position."""
    z = np.zeros_like(t)
    return np.full_like(t, value), z, z.copy()


def cosine_sweep(t: Array, low: float, high: float, period_s: float) -> Triple:
    """low + (high-low)/2 (1 - cos(2 pi t / T)): starts at rest at ``low`` (seed 000 Fig. 14)."""
    a = 0.5 * (high - low)
    w = 2.0 * np.pi / period_s
    return low + a * (1.0 - np.cos(w * t)), a * w * np.sin(w * t), a * w * w * np.cos(w * t)


def quintic(t: Array, q0: float, q1: float, t0: float, duration_s: float) -> Triple:
    """Minimum-jerk move from q0 to q1 starting at t0 (rest to rest), holding outside."""
    s = np.clip((t - t0) / duration_s, 0.0, 1.0)
    inside = (t > t0) & (t < t0 + duration_s)
    dq = q1 - q0
    pos = q0 + dq * (10 * s**3 - 15 * s**4 + 6 * s**5)
    vel = np.where(inside, dq * (30 * s**2 - 60 * s**3 + 30 * s**4) / duration_s, 0.0)
    acc = np.where(inside, dq * (60 * s - 180 * s**2 + 120 * s**3) / duration_s**2, 0.0)
    return pos, vel, acc


def step(t: Array, q0: float, q1: float, t_step: float) -> Triple:
    """Position step (velocity and acceleration references zero)."""
    z = np.zeros_like(t)
    return np.where(t >= t_step, q1, q0), z, z.copy()


def stack(joints: tuple[Triple, Triple, Triple]) -> Array:
    """Three joints' (pos, vel, acc) -> table rows ``q[3], qd[3], qdd[3]``."""
    cols = [joints[j][k] for k in range(3) for j in range(3)]
    return np.ascontiguousarray(np.stack(cols, axis=1))
