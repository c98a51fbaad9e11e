"""Magnetic spring VSA (ATTRACTOR, flat-magnet spring FMS) as the joint-3 transmission, seed 003.

Source: /work/shared/seeds/003_4193e96e88679a8c.txt, eq. 1-2 (Sec. 6.2), Table 3 model F,
Table 5 (meaning of the terms), Sec. 7.1 (stable range 31.5 deg, linear range 19.7 deg, kinetic
friction about 0.05 N*m), Fig. 17.

Spring torque on the output ring (eq. 1, ``phi_r = phi_out - phi_in`` in degrees)::

    tau_sp(d, phi_r) = -P(d) (b1 sin(pi/60 phi_r) + b2 sin(pi/30 phi_r) + b3 sin(pi/15 phi_r))
    P(d) = 1 + a1 d + a2 d^2 + a3 d^3 + a4 d^4

Mapping to the arm: the input ring turns with the motor gearbox output ``theta_m`` and the output
ring with ``theta_s``, so ``phi_r = theta_s - theta_m = -x``. The torque the spring passes to the
joint side is ``tau_sp(d, -x)``, i.e. with x in rad (``pi/60 per deg = 3 per rad``)::

    tau = scale * (P(d) (b1 sin 3x + b2 sin 6x + b3 sin 12x) + z x')

``z x'`` is model F's ``-z (phi_out' - phi_in')``: the relative (eddy-current) damping between
the rings, the only dissipation *between* them ("there is no contact between rotating rings",
Sec. 7.2). It is 120 deg periodic: beyond the peak the spring slips to the next of its three
stable equilibria (a torque limiter, Sec. 2 "inherent maximum torque limit").

Ranges at any d (the law is a product, so the angles do not depend on d): stable range
|x| <= 31.5 deg (maximal torque, zero stiffness; negative stiffness beyond, Sec. 3, 7.1, Fig. 17),
linear range |x| <= 19.7 deg (torque within 5 % of ``k_sp x``, Sec. 3 and 7.1), stiffness in
stable equilibrium eq. 2 ``k_sp(d) = (3 b1 + 6 b2 + 12 b3) P(d)`` (N*m/rad). A *safe* range is
a user's margin below the stable one (Sec. 3 gives no number): :func:`safe_range_rad`.

What the seed text lacks (no digits to read, nothing garbled to repair):

* **b1, b2, b3 and a1..a4 are not printed** (Fig. 11/16/17 only). Here the shape ratios
  ``b2/b1, b3/b1`` are solved from the two published shape numbers - maximal torque at 31.5 deg
  and a 19.7 deg linear range at d = 0 - (the unique solution near the pure sinusoid:
  b2/b1 = -0.06200, b3/b1 = -0.01157); a pure sine gives the "theoretical" 30 deg and a 10.5 deg
  linear range (the paper: 30 deg and, for the arc-magnet spring of [42], about 11 deg).
  The amplitude is an **estimate**: peak torque 1.0 N*m at d = 0, from the size of Table 1's
  6-pole FMS (magnet rings about 40-44 mm across and 20 mm long, 4 mm gap: a magnetic shear
  stress of about 20 kPa over 2 pi r^2 l = 5.5e-5 m^3 gives about 1.1 N*m).
  P(d) is an **estimate**: the loss of axial overlap of 20 mm long rings (Table 1 P1 = P2 =
  20 mm read as the ring length), ``P = 1 - d / 0.020 m``, clamped at 0 (rings decoupled, the
  "zero stiffness configuration" of Sec. 2); the paper's own quartic is not in the text.
* Table 5 interprets the terms of Table 3; the **identified values** of J, v, w, x, y, z are not
  in the text. Only the kinetic friction is given: about 0.05 N*m (Sec. 7.1).
* Eq. 1 prints the harmonics pi/60, pi/30, pi/15 per degree (1st, 2nd and 4th of the 120 deg
  period) although Sec. 7.1 speaks of "the first three terms of sinus series"; eq. 1 and eq. 2
  agree with each other, so they are implemented as printed.

Model F terms that act on the output shaft against the *frame* - the bearing friction
``-tau_fr tanh(v phi_out')`` (Table 5: kinetic friction, smooth form) and the eccentric mass of
the bench flywheel ``w sin(phi_out + x)`` (Table 5: "imperfect wheel balance") - are not torques
between the two rings, so they are not in the twist kernels: :func:`output_side_torque_nm` of the
output-side angle and rate ``theta_s`` is applied on joint 3 by ``physics.passive_forces`` (the
interface's optional frame-referenced output torque). The flywheel unbalance belongs to the
bench, not the spring: ``w`` defaults to 0.

``scale`` (default 1 = the published device) multiplies every torque: n identical springs in
parallel. The arm's joint 3 needs more than the estimated 1 N*m (see :func:`scale_for_torque`).
No internal states.
"""

from __future__ import annotations

import math

import numpy as np

from fsarm_sim.plant.roots import bisect
from fsarm_sim.plant.transmissions.base import (
    Bounds,
    FloatArray,
    Param,
    TransmissionError,
    any_finite,
    check_bounds,
    fill_block,
    non_negative,
    positive,
)

NAME = "magnetic_spring"
TITLE = "Magnetic spring VSA (ATTRACTOR, flat-magnet spring, ring distance d)"
SOURCE = (
    "seed 003 (ATTRACTOR magnetic-spring VSA): eq. 1 (sinusoidal torque-angle law with ring "
    "distance d), eq. 2 (stiffness in stable equilibrium), Table 3 model F / Table 5 (friction, "
    "eccentric mass, relative damping), Sec. 7.1 / Fig. 17 (stable range 31.5 deg, linear range "
    "19.7 deg, kinetic friction 0.05 N*m)"
)
STATES: tuple[str, ...] = ()
# parameter values that switch every dissipation of the law off (energy checks)
CONSERVATIVE: dict[str, float] = {"z": 0.0, "tau_fr": 0.0}
ROUTED_OVER_JOINT2 = False

DEG = math.pi / 180.0
LINEAR_TOLERANCE = 0.05  # Sec. 3: "differs from the linearised one no more than 5 %"
PERIOD_RAD = 2.0 * math.pi / 3.0  # eq. 1: 120 deg (three stable equilibria, Sec. 6.1)
DATA_RANGE_DEG = 41.0  # Sec. 6.1 experiment A: -41..41 deg from the stable equilibrium

# parameter-block indices
I_D, I_B1, I_B2, I_B3, I_A1, I_A2, I_A3, I_A4 = 0, 1, 2, 3, 4, 5, 6, 7
I_Z, I_TAU_FR, I_V, I_W, I_XE, I_SCALE = 8, 9, 10, 11, 12, 13


class MagneticSpringParamError(TransmissionError):
    """A magnetic-spring parameter or argument outside what the seed-003 law allows."""


# ------------------------------------------------------------------ kernels (scalar math only)


def distance_factor(tr: FloatArray) -> float:
    """P(d) of eq. 1, clamped at 0 (rings fully decoupled)."""
    d = tr[I_D]
    p = 1.0 + tr[I_A1] * d + tr[I_A2] * d * d + tr[I_A3] * d**3.0 + tr[I_A4] * d**4.0
    if p < 0.0:
        return 0.0
    return p


def _shape(tr: FloatArray, x: float) -> float:
    """eq. 1's sine series at twist x (rad): pi/60 per deg = 3 per rad."""
    return (
        tr[I_B1] * math.sin(3.0 * x) + tr[I_B2] * math.sin(6.0 * x) + tr[I_B3] * math.sin(12.0 * x)
    )


def _shape_slope(tr: FloatArray, x: float) -> float:
    return (
        3.0 * tr[I_B1] * math.cos(3.0 * x)
        + 6.0 * tr[I_B2] * math.cos(6.0 * x)
        + 12.0 * tr[I_B3] * math.cos(12.0 * x)
    )


def _shape_energy(tr: FloatArray, x: float) -> float:
    return (
        tr[I_B1] * (1.0 - math.cos(3.0 * x)) / 3.0
        + tr[I_B2] * (1.0 - math.cos(6.0 * x)) / 6.0
        + tr[I_B3] * (1.0 - math.cos(12.0 * x)) / 12.0
    )


def torque_nm(
    tr: FloatArray, x: float, xdot: float, bend: float, act: FloatArray, a0: int
) -> float:
    """Spring torque (eq. 1, ``phi_r = -x``) plus model F's relative damping ``z x'``."""
    return tr[I_SCALE] * (distance_factor(tr) * _shape(tr, x) + tr[I_Z] * xdot)


def sensor_torque_nm(tr: FloatArray, x: float, bend: float) -> float:
    """Eq. 1 from the two encoders (the spring's static law); ``bend`` is not used."""
    return tr[I_SCALE] * distance_factor(tr) * _shape(tr, x)


def stiffness_nm_per_rad(tr: FloatArray, x: float, bend: float) -> float:
    """d(sensor torque)/dx; negative beyond the stable range."""
    return tr[I_SCALE] * distance_factor(tr) * _shape_slope(tr, x)


def state_rate(
    tr: FloatArray,
    x: float,
    xdot: float,
    bend: float,
    act: FloatArray,
    a0: int,
    i: int,
    vm: float = 0.0,
) -> float:
    """No internal states."""
    return 0.0


def bend_torque_nm(tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int) -> float:
    """-dV/dphi_B: 0, the law does not read the bend (not routed over joint 2)."""
    return 0.0


def potential_j(tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int) -> float:
    """Magnetic energy relative to the stable equilibrium x = 0 (periodic, 120 deg)."""
    return tr[I_SCALE] * distance_factor(tr) * _shape_energy(tr, x)


def output_side_torque_nm(tr: FloatArray, theta_s: float, theta_s_dot: float) -> float:
    """Model F's frame-referenced terms on the output shaft (not between the rings).

    ``-tau_fr tanh(v theta_s') + w sin(theta_s + x_e)``: smooth kinetic (bearing) friction and
    the eccentric mass of the bench flywheel, times ``scale``. Applied on the output (joint)
    side by ``physics.passive_forces`` (``physics.tr_output_torque``); no part of
    :func:`torque_nm`.
    """
    return tr[I_SCALE] * (
        -tr[I_TAU_FR] * math.tanh(tr[I_V] * theta_s_dot) + tr[I_W] * math.sin(theta_s + tr[I_XE])
    )


# ------------------------------------------------------------------ Python side: data and helpers

_EST_B = (
    "estimate: shape solved from the published 31.5 deg stable / 19.7 deg linear range "
    "(seed 003 Sec. 7.1), amplitude from a 1.0 N*m peak estimated from Table 1's FMS size; "
    "eq. 1's fitted value is not in the seed text"
)
_EST_A = (
    "estimate: P(d) = 1 - d/0.020 m (loss of overlap of 20 mm long rings, seed 003 Table 1 "
    "P1 = P2); eq. 1's fitted value is not in the seed text"
)

_SHAPE_WHY = (
    "a harmonic of eq. 1: either sign; the stiffness at x = 0 must stay > 0 (checked across b1..b3)"
)
_P_WHY = "a coefficient of P(d) (eq. 1): either sign; P(d) > 0 at the set d is checked"
_SCALE_WHY = (
    "a torque multiplier (springs in parallel): > 0 (0 transmits nothing, < 0 reverses the "
    "spring); a stiffness too high for the timestep is refused at build"
)

PARAMS: tuple[Param, ...] = (
    Param(
        "d",
        0.0,
        "m",
        "stiffness setting: ring distance; 0 = stiff configuration (Fig. 17)",
        non_negative(
            "a ring distance must be >= 0 (0 = full overlap, the stiff configuration); its "
            "upper end is where P(d) reaches 0 (rings decoupled), checked with a1..a4"
        ),
    ),
    Param(
        "b1",
        0.99697,
        "N*m",
        _EST_B,
        positive(
            "> 0: the first harmonic carries the spring (eq. 1); <= 0 makes x = 0 an unstable "
            "equilibrium"
        ),
    ),
    Param("b2", -0.061811, "N*m", _EST_B, any_finite(_SHAPE_WHY)),
    Param("b3", -0.011534, "N*m", _EST_B, any_finite(_SHAPE_WHY)),
    Param("a1", -50.0, "1/m", _EST_A, any_finite(_P_WHY)),
    Param("a2", 0.0, "1/m^2", _EST_A, any_finite(_P_WHY)),
    Param("a3", 0.0, "1/m^3", _EST_A, any_finite(_P_WHY)),
    Param("a4", 0.0, "1/m^4", _EST_A, any_finite(_P_WHY)),
    Param(
        "z",
        0.002,
        "N*m*s/rad",
        "estimate: model F relative (eddy-current) damping, value not in the seed text; "
        "small (Sec. 7.2: 'relatively low impact'): 0.002 N*m at 1 rad/s",
        non_negative("relative damping must be >= 0 (dissipative; < 0 would feed energy in)"),
    ),
    Param(
        "tau_fr",
        0.05,
        "N*m",
        "seed 003 Sec. 7.1: kinetic friction identified as about 0.05",
        non_negative("a friction level must be >= 0 (0 = no bearing friction)"),
    ),
    Param(
        "v",
        50.0,
        "s/rad",
        "estimate: tanh sharpness of model C-F, value not in the seed text (95 % of tau_fr "
        "at 0.037 rad/s)",
        non_negative(
            "the tanh sharpness must be >= 0 (0 switches the friction off; < 0 would make it "
            "drive the motion)"
        ),
    ),
    Param(
        "w",
        0.0,
        "N*m",
        "model D-F eccentric mass of the bench flywheel: not on the arm",
        non_negative("an amplitude must be >= 0 (its direction is the phase x_e)"),
    ),
    Param(
        "x_e",
        0.0,
        "rad",
        "model D-F phase of the eccentric mass (not in the seed text)",
        Bounds(-math.pi, math.pi, "a phase angle: one turn, [-pi, pi]"),
    ),
    Param(
        "scale",
        1.0,
        "-",
        "torque multiplier: 1 = the published device (n springs in parallel)",
        positive(_SCALE_WHY),
    ),
)
TWIST_RANGE_RAD = DATA_RANGE_DEG * DEG  # experiment A's range; includes the 31.5 deg peak


def default_block(overrides: dict[str, float] | None = None) -> FloatArray:
    """The parameter block (length N_TR) with the published values and ``overrides``."""
    return fill_block(
        "magnetic-spring", PARAMS, overrides, validate=validate, error=MagneticSpringParamError
    )


def validate(tr: FloatArray) -> None:
    """Raise :class:`MagneticSpringParamError` for a block the law does not cover.

    Each parameter's own range comes from ``PARAMS``' bounds (checked again here, so a block
    changed by hand - :func:`_block_at` - is covered); then the checks across parameters.
    """
    check_bounds("magnetic-spring", PARAMS, tr, MagneticSpringParamError)
    if distance_factor(tr) <= 0.0:
        raise MagneticSpringParamError(
            f"transmission 'magnetic-spring': parameter d = {float(tr[I_D])!r} m decouples the "
            f"rings (P(d) <= 0 with a1..a4 as set: no spring); allowed: 0 <= d < "
            f"{decoupling_distance_m(tr):.4g} m"
        )
    if _shape_slope(tr, 0.0) <= 0.0:
        raise MagneticSpringParamError(
            f"transmission 'magnetic-spring': b1 = {float(tr[I_B1])!r}, b2 = {float(tr[I_B2])!r}, "
            f"b3 = {float(tr[I_B3])!r} N*m give stiffness 3 b1 + 6 b2 + 12 b3 = "
            f"{_shape_slope(tr, 0.0):.4g} N*m/rad <= 0 at x = 0: must be > 0 (a stable "
            "equilibrium, eq. 2)"
        )


def _block_at(d: float, tr: FloatArray | None) -> FloatArray:
    if not math.isfinite(d):
        raise MagneticSpringParamError(f"ring distance d must be finite, got {d!r}")
    out = default_block() if tr is None else np.array(tr, dtype=float)
    out[I_D] = d
    validate(out)
    return out


def decoupling_distance_m(tr: FloatArray | None = None) -> float:
    """Smallest d > 0 where P(d) reaches 0 (rings decoupled); inf if it never does below 1 m."""
    t = default_block() if tr is None else np.array(tr, dtype=float)
    ds = np.linspace(0.0, 1.0, 100001)
    t2 = t.copy()
    for d in ds:
        t2[I_D] = d
        if distance_factor(t2) <= 0.0:
            return float(d)
    return math.inf


def stiffness_at_equilibrium(d: float, tr: FloatArray | None = None) -> float:
    """Eq. 2: ``k_sp(d) = (b1 pi/60 + b2 pi/30 + b3 pi/15) P(d)`` in N*m/rad, times scale."""
    t = _block_at(d, tr)
    k_per_deg = (t[I_B1] * math.pi / 60.0 + t[I_B2] * math.pi / 30.0 + t[I_B3] * math.pi / 15.0) * (
        distance_factor(t)
    )
    return float(k_per_deg / DEG * t[I_SCALE])


def stable_range_rad(d: float, tr: FloatArray | None = None) -> float:
    """Half-width of the stable range: the first twist > 0 of zero stiffness (maximal torque)."""
    t = _block_at(d, tr)
    lo, hi = 1e-6, 0.5 * PERIOD_RAD
    if _shape_slope(t, hi) >= 0.0:
        raise MagneticSpringParamError("no stiffness sign change within half a period")
    xs = np.linspace(lo, hi, 2001)
    k_prev = _shape_slope(t, lo)
    for x in xs[1:]:
        k = _shape_slope(t, float(x))
        if k <= 0.0 < k_prev:
            hi = float(x)
            break
        lo, k_prev = float(x), k
    return bisect(lambda x: _shape_slope(t, x) > 0.0, lo, hi)


def max_torque_nm(d: float, tr: FloatArray | None = None) -> float:
    """Maximal (static) torque: the torque at the stable-range limit."""
    t = _block_at(d, tr)
    return float(sensor_torque_nm(t, stable_range_rad(d, t), 0.0))


def linear_range_rad(
    d: float, tr: FloatArray | None = None, tolerance: float = LINEAR_TOLERANCE
) -> float:
    """Half-width of the range where the torque is within ``tolerance`` of ``k_sp(d) x``."""
    if not 0.0 < tolerance < 1.0:
        raise MagneticSpringParamError(f"tolerance must be in (0, 1), got {tolerance!r}")
    t = _block_at(d, tr)
    k0 = _shape_slope(t, 0.0)

    def dev(x: float) -> float:
        return abs(_shape(t, x) - k0 * x) - tolerance * k0 * x

    xs = np.linspace(1e-6, 0.5 * PERIOD_RAD, 4001)
    lo = float(xs[0])
    for x in xs[1:]:
        if dev(float(x)) > 0.0:
            return bisect(lambda m: not dev(m) > 0.0, lo, float(x))
        lo = float(x)
    return 0.5 * PERIOD_RAD


def safe_range_rad(d: float, torque_fraction: float = 0.9, tr: FloatArray | None = None) -> float:
    """Twist at which the torque reaches ``torque_fraction`` of the maximal torque (stable side).

    Seed 003 Sec. 3 leaves the safety margin to the user; 0.9 is a default, not a published value.
    """
    if not 0.0 < torque_fraction < 1.0:
        raise MagneticSpringParamError(
            f"torque_fraction must be in (0, 1), got {torque_fraction!r}"
        )
    t = _block_at(d, tr)
    x_max = stable_range_rad(d, t)
    target = torque_fraction * _shape(t, x_max)
    return bisect(lambda x: not _shape(t, x) >= target, 0.0, x_max)


def scale_for_torque(torque_nm: float, d: float = 0.0, within: str = "linear") -> float:
    """Smallest ``scale`` that carries ``torque_nm`` within the ``linear`` or ``stable`` range."""
    if not math.isfinite(torque_nm) or torque_nm <= 0.0:
        raise MagneticSpringParamError(f"torque must be finite and > 0 N*m, got {torque_nm!r}")
    t = _block_at(d, None)
    if within == "linear":
        x = linear_range_rad(d, t)
    elif within == "stable":
        x = stable_range_rad(d, t)
    else:
        raise MagneticSpringParamError(f"within must be 'linear' or 'stable', got {within!r}")
    return float(torque_nm / sensor_torque_nm(t, x, 0.0))


def rating_nm(tr: FloatArray) -> float:
    """The spring's maximal static torque at its ring distance (the stable-range limit)."""
    return max_torque_nm(float(tr[I_D]), tr)
