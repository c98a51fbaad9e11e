"""Joint-3 low-level loop of seed 000 Fig. 13: shaft as a virtual torque sensor.

    tau_m   = eq. 8(theta_m - theta_s, phi_B)           (encoders before/after the shaft, joint-2 encoder)
    omega_d = omega_ff + PID(tau_d - tau_m)              (desired shaft-input speed)
    tau_mot = sat(PI(i_G1 omega_d - omega_motor))        (EPOS-like speed loop, current limit)

Gain scheduling: with an ideal speed loop the torque obeys d(tau)/dt = K (omega_d - omega_ff), so a
proportional gain kp gives a torque-loop bandwidth of K kp. The gains are therefore set from a
desired bandwidth and the controller's own eq. 8 stiffness K(phi_B, side) - the same model the
virtual sensor uses - so the loop keeps its bandwidth when the bend angle or the shaft changes
(seed 000 notes fixed gains "needed retuning").

``omega_ff`` is the measured shaft-output speed (i_G2 * dq3/dt): the input must turn that fast
just to keep the twist - and so the torque - constant. It is an addition to Fig. 13 (switchable,
``speed_ff``) that removes the load motion from the torque loop; with it off the loop is the
paper's pure PID. Integrators use conditional integration (no windup while saturated).
"""

from __future__ import annotations

from fsarm_sim.controllers.joint_position import clamp


def scheduled_gains(
    bandwidth_rad_s: float, integral_rad_s: float, derivative: float, stiffness_nm_per_rad: float
) -> tuple[float, float, float]:
    """(kp, ki, kd) of the torque PID for a loop bandwidth on a shaft of the given stiffness.

    kp = w_t / K  [rad/s per N*m],  ki = w_t w_i / K,  kd = d / K  (d dimensionless).
    """
    k = max(stiffness_nm_per_rad, 1e-9)
    return bandwidth_rad_s / k, bandwidth_rad_s * integral_rad_s / k, derivative / k


def torque_pid(
    tau_d: float,
    tau_m: float,
    integ: float,
    e_prev: float,
    initialized: float,
    dt: float,
    kp: float,
    ki: float,
    kd: float,
    omega_ff: float,
    omega_max: float,
) -> tuple[float, float, float, float, float, float]:
    """One tick of the torque->speed PID.

    Returns (omega_d, new_integral, error, p_term, i_term, d_term). ``omega_max`` bounds the
    shaft-input speed.
    """
    e = tau_d - tau_m
    de = (e - e_prev) / dt if initialized > 0.5 else 0.0
    p_term = kp * e
    d_term = kd * de
    new_integ = integ + e * dt
    raw = omega_ff + p_term + ki * new_integ + d_term
    if raw > omega_max or raw < -omega_max:
        new_integ = integ  # conditional integration: hold the integral while saturated
        raw = omega_ff + p_term + ki * new_integ + d_term
    return clamp(raw, omega_max), new_integ, e, p_term, ki * new_integ, d_term


def speed_loop(
    omega_d_motor: float,
    omega_motor: float,
    integ: float,
    dt: float,
    kp: float,
    ki: float,
    tau_max: float,
) -> tuple[float, float]:
    """One tick of the EPOS-like PI speed loop. Returns (motor torque, new integral)."""
    e = omega_d_motor - omega_motor
    new_integ = integ + e * dt
    raw = kp * e + ki * new_integ
    if raw > tau_max or raw < -tau_max:
        new_integ = integ
        raw = kp * e + ki * new_integ
    return clamp(raw, tau_max), new_integ
