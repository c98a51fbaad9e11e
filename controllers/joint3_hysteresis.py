"""Joint 3's hysteresis-aware virtual torque sensor: eq. 8 plus a Maxwell-slip model of the shaft.

Seed 000 blames the shaft's series hysteresis, which eq. 8 cannot see, for Fig. 14's tracking
error and leaves its compensation as future work. This estimate adds to the controller's spring a
rate-independent hysteresis model, fed by the same three encoders (motor, joint 3, joint 2):

    tau_hat = K_c(side, phi_B) x + sum_i k_i z_i,
    z_i(t_k) = clamp(z_i(t_(k-1)) + x(t_k) - x(t_(k-1)),  -r g f_i / k_i,  g f_i / k_i),
    g = exp(mu |phi_B|)

with ``x`` the twist theta_m - theta_s and ``K_c`` the model's spring per twist sign, falling
linearly with |phi_B| (the structure of eq. 3). Why Maxwell-slip (rather than Prandtl-Ishlinskii
or Bouc-Wen):

* it is the structure of the shaft's physics: coils that stick and slide on each other and on the
  conduit are elasto-slip elements (a spring held by a friction torque), and the plant's own series
  hysteresis is written that way (``fsarm_sim.plant.effects.maxwell_slip``); a Prandtl-Ishlinskii
  model is the same superposition of play operators, but Bouc-Wen's shape parameters have no
  physical reading here;
* it is rate-independent (the loop does not change with frequency, as seed 000's series test shows
  from 0.5 to 20 Hz), so a discrete update per control tick is exact at any speed, needs no time
  derivative of the encoder twist and no state that drifts;
* its parameters are identifiable from the paper's own series test (a chirp into the blocked
  bench at a few held bends): given the elements' slip deflections, the torque is *linear* in the
  spring and element stiffnesses (``fsarm_sim.studies.hysteresis_id``);
* the bend dependence enters as one factor on every element's slip torque (the capstan-like
  growth of internal friction with the route's wrap) and one ratio for the unwinding side.

The parameters are the controller's own copy (identified from bench records, never read from the
plant). Pure functions of floats: Numba compiles them into the native callbacks.
"""

from __future__ import annotations

import math

N_ELEMENTS = 3  # elasto-slip elements of the controller's model


def bend_factor(bend_rad: float, mu_per_rad: float) -> float:
    """Growth of the slip torques with the bend: exp(mu |phi_B|)."""
    return math.exp(mu_per_rad * abs(bend_rad))


def element_step(
    z: float, dx: float, k: float, f: float, unwinding_ratio: float, factor: float
) -> float:
    """One elasto-slip element after a twist increment ``dx``: it follows the twist inside its
    band ``[-r g f/k, g f/k]`` and slides at its edges (0 for an element switched off, k = 0)."""
    if k <= 0.0:
        return 0.0
    hi = factor * f / k
    lo = -unwinding_ratio * hi
    z = z + dx
    if z > hi:
        return hi
    if z < lo:
        return lo
    return z


def spring_torque(
    x: float, bend_rad: float, k_pos: float, s_pos: float, k_neg: float, s_neg: float
) -> float:
    """The model's spring: K(side, phi_B) x with K = k + s |phi_B| per twist sign."""
    if x >= 0.0:
        return (k_pos + s_pos * abs(bend_rad)) * x
    return (k_neg + s_neg * abs(bend_rad)) * x


def initial_elements(
    x: float,
    bend_rad: float,
    target_nm: float,
    k_pos: float,
    s_pos: float,
    k_neg: float,
    s_neg: float,
    k1: float,
    k2: float,
    k3: float,
    f1: float,
    f2: float,
    f3: float,
    unwinding_ratio: float,
    mu_per_rad: float,
) -> tuple[float, float, float]:
    """Element deflections at the start: loaded in order, within their bands, so that the model
    holds ``target_nm`` at twist ``x`` (e.g. eq. 8's torque of a static start); all zero at x = 0."""
    need = target_nm - spring_torque(x, bend_rad, k_pos, s_pos, k_neg, s_neg)
    g = bend_factor(bend_rad, mu_per_rad)
    out = [0.0, 0.0, 0.0]
    ks = (k1, k2, k3)
    fs = (f1, f2, f3)
    for i in range(N_ELEMENTS):
        if ks[i] <= 0.0 or x == 0.0:
            continue
        hi = g * fs[i] / ks[i]
        lo = -unwinding_ratio * hi
        z = min(hi, max(lo, need / ks[i]))
        need -= ks[i] * z
        out[i] = z
    return out[0], out[1], out[2]
