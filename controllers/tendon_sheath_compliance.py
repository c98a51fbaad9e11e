"""Seed 004's sensorless compliant control from two encoders: Algorithms 1 and 2 as written.

Source: seed 004_5af85f66df40f93c.txt, Sec. V. The position transmission is identified without
disturbance as one quadratic per direction of joint motion (eq. 19, Tables 1-2)::

    theta_1p = P_p th2^2 + Q_p th2 + M_p        (omega_2 > 0)
    theta_1r = P_r th2^2 + Q_r th2 + M_r        (omega_2 < 0)

with ``th2`` the joint encoder and ``theta_1`` the motor angle. At run time neither algorithm
needs the direction: both take the branch *nearer* to the measured motor angle.

* Algorithm 1 (collision detection): ``delta`` = nearer branch - measured motor angle; while
  ``|delta| <= delta_a`` the motor's position command ``theta_c`` is the nearer branch's value
  (line 7), else the motor holds where it was (line 8, ``theta_c = theta_1(t-)``) - the alarm.
* Algorithm 2 (hand guiding): the motor is commanded to the nearer branch's value ``theta_h``,
  so a joint moved by hand drags the motor along the identified no-load relation.

Pure functions of floats and coefficient triples ``(P, Q, M)`` (:data:`Branch`; Numba-compilable
like the other controllers).
"""

from __future__ import annotations

Branch = tuple[float, float, float]  # one direction's eq. 19 coefficients (P, Q, M)


def branch_angle(theta2: float, p: float, q: float, m: float) -> float:
    """Eq. 19: the motor angle one branch predicts for the joint angle ``theta2``."""
    return p * theta2 * theta2 + q * theta2 + m


def nearer_branch(theta1: float, theta2: float, up: Branch, down: Branch) -> float:
    """Algorithms 1-2, lines 1-5: the branch value nearer to the measured motor angle (``up``:
    the branch identified with omega_2 > 0, ``down``: omega_2 < 0)."""
    t1p = branch_angle(theta2, up[0], up[1], up[2])
    t1r = branch_angle(theta2, down[0], down[1], down[2])
    if abs(t1p - theta1) < abs(t1r - theta1):
        return t1p
    return t1r


def collision_monitor(
    theta1: float, theta2: float, theta1_prev: float, delta_a: float, up: Branch, down: Branch
) -> tuple[float, float, bool]:
    """Algorithm 1, one tick: ``(delta, theta_c, alarm)``.

    ``delta`` = nearer branch - ``theta1``; no alarm: ``theta_c`` = the nearer branch (line 7);
    alarm (``|delta| > delta_a``): ``theta_c = theta1_prev``, the motor holds (line 8).
    """
    near = nearer_branch(theta1, theta2, up, down)
    delta = near - theta1
    if abs(delta) <= delta_a:
        return delta, near, False
    return delta, theta1_prev, True


def hand_guiding_command(theta1: float, theta2: float, up: Branch, down: Branch) -> float:
    """Algorithm 2, one tick, as the seed writes it: the motor command ``theta_h`` is the nearer
    branch's value (lines 1-5 of Algorithm 1 again). On the arm's cascade the same idea runs as
    ``studies.collision.Algorithm2Guiding`` (the controller's own no-load relation stands in for
    eq. 19's fitted branches)."""
    return nearer_branch(theta1, theta2, up, down)


# Position loop of the drive motor (Fig. 13/14: "a closed-loop control of the drive motor is
# formed by the motor encoder, and theta_c is obtained and outputted to form a second closed
# loop"). Estimate: the seed prints no gains; 60 rad/s puts the motor position loop at the
# arm's torque-loop bandwidth (Gains.torque_bandwidth_rad_s), well below the speed loop.
MOTOR_POSITION_GAIN_RAD_S = 60.0


def position_command(theta_s_ref: float, tau_d: float, stiffness: float) -> float:
    """The motor (shaft-input) angle theta_c for the joint reference: eq. 14 read forward,
    ``theta_1 = theta_2 + Delta L / r`` with the tendon stretch the desired torque needs
    (``tau_d / K`` on the controller's copy of the law; the seed's eq. 19 branches play this
    role on its bench)."""
    return theta_s_ref + tau_d / stiffness


def motor_speed_command(
    theta_c: float,
    theta_m: float,
    omega_ref: float,
    gain_rad_s: float,
    omega_max: float,
) -> float:
    """Shaft-input speed command of the motor position loop: ``omega_ref + k (theta_c -
    theta_m)``, bounded by the motor's speed limit (shaft side)."""
    raw = omega_ref + gain_rad_s * (theta_c - theta_m)
    if raw > omega_max:
        return omega_max
    if raw < -omega_max:
        return -omega_max
    return raw
