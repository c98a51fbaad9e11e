"""Joint position loops with model feedforward (joints 1, 2 and the outer loop of joint 3).

Computed-torque on the diagonal: the gains are natural frequency and damping ratio, scaled by the
joint's own inertia from the model, so the same gains hold with and without payload (seed 000
notes that fixed gains "needed retuning per load").

    tau = M_ii(q) (qdd_ref + wn^2 (q_ref - q) + 2 zeta wn (qd_ref - qd)) + bias_i(q, qd) + extra

``bias_i`` is MuJoCo's ``qfrc_bias`` (gravity + Coriolis), which ``fsarm check-dynamics`` checks
against Pinocchio's RNEA. ``extra`` lets joint 2 add the modeled elastic bending moment of the shaft.
"""

from __future__ import annotations


def clamp(x: float, limit: float) -> float:
    """Symmetric saturation."""
    if x > limit:
        return limit
    if x < -limit:
        return -limit
    return x


def computed_torque(
    q: float,
    qd: float,
    q_ref: float,
    qd_ref: float,
    qdd_ref: float,
    inertia: float,
    bias: float,
    wn: float,
    zeta: float,
) -> float:
    """Desired joint torque of one joint (N*m)."""
    return inertia * (qdd_ref + wn * wn * (q_ref - q) + 2.0 * zeta * wn * (qd_ref - qd)) + bias
