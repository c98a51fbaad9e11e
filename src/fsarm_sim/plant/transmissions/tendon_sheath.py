"""Tendon-sheath transmission (seed 004): capstan friction along a bent sheath, tendon stretch, play.

Source: seed 004_5af85f66df40f93c.txt ("Compliant control of single tendon-sheath actuators
applied to a robotic manipulator"). Mapping onto joint 3: the motor pulley turns with ``theta_m``,
the joint pulley with ``theta_s``; both pulleys get the radius ``r`` (the seed's joint pulley,
r2 = 25 mm; the interface has no ratio, so the seed's r1 = 20 mm is not used). The sheath is
routed over joint 2 (``ROUTED_OVER_JOINT2``): its total curvature angle is the sheath's own bend
plus the bend joint 2 imposes, ``Theta = wrap + |phi_B|`` (separate arcs, curvature angles add).

Capstan (eq. 6-8), uniform curvature over the sheath length ``L_s``: while the tendon slides, the
tension at the actuator end is ``Phi = exp(+-mu Theta)`` times the one at the joint end.

Stretch (eq. 9-11, Hooke): ``Delta L = Theta_dir F_m`` with ``F_m`` the actuator-end tension
(eq. 10; eq. 11 with the inner integral's upper limit read as x - printed as L, garbled).
Closed form for uniform curvature, the free tendon ``L_t - L_s`` split equally between the ends
(estimate)::

    C_pull = [ (L_t-L_s)/2 (1 + e^-mT) + L_s (1 - e^-mT)/(mT) ] / (E A)    (motor pulling, x' > 0)
    C_rel  = [ (L_t-L_s)/2 (1 + e^+mT) + L_s (e^+mT - 1)/(mT) ] / (E A)    (releasing,     x' < 0)

so that ``C_rel / C_pull = exp(mu Theta)`` exactly (the capstan ratio) and both tend to L_t/(E A)
as mu -> 0. Twist -> stretch: ``Delta L = r x_eff``; motor-end torque = ``r F_m``; branch stiffnesses
``K_pull = r^2 / C_pull`` (loading), ``K_rel = r^2 / C_rel`` (unloading); ``K_m``, ``K_d`` their
mean and half-difference. Play: dead band of width ``w`` (the tendon loop's slack)::

    x_eff = x - w/2 (x > w/2);  0 (|x| <= w/2);  x + w/2 (x < -w/2)

Two ends (eq. 7-8): the joint end carries the tension after the sheath's friction, the motor end
``e^(+-mu Theta)`` times it. With a friction state ``z`` (state slot 0, ``|z| <= 1``; +1 while
the motor pulls a taut positive twist)::

    tau_joint = scale (K_m x_eff - K_d |x_eff| z)        (z = +1: K_rel x, -1: K_pull x)
    tau_motor = tau_joint e^(mu Theta z s)                (s = sgn x_eff; +1: K_pull x, -1: K_rel x)

``torque_nm`` is the joint end, ``motor_torque_nm`` the motor end (the interface applies each at
its own end). ``z`` follows the direction the tendon slides in the sheath: that of the sum of
its ends' speeds ``u = vm + vj`` (``state_rate`` gets the motor-side speed ``vm``; the joint
end's is ``vm - x'``). Where the joint end stays (seed 004 phases C and F: the motor turns, the
joint stays) ``u = vm``, eq. 5's sgn(x'); there z moves at the *stick rate*
``dz/dtheta_m = (K_m - s K_d z) / (K_d |x_eff| + K_m delta0)`` that keeps the joint end's
tension constant while the friction reverses (the full switch takes the ideal travel
``x (1 - K_rel/K_pull)``); in general at that rate per unit of ``u``. It moves towards
``sgn(u) |v| / (|v| + v0)``, ``v`` the faster end's speed (``friction_speed_rad_s`` = v0: a
velocity-strengthening friction, Table 1's rate effect; ~1 at the arm's speeds) and holds at
rest.

Energy: the elastic part ``K_m x_eff`` has the potential ``K_m x_eff^2 / 2``; the ``z`` part and
the difference between the ends are the sheath's friction (see below). The virtual torque sensor (what seed 004 estimates from the two encoders
with its model, eq. 14) cannot tell the direction branch from the encoders' angles alone, so it
uses the centre line ``K_m x_eff`` (Algorithm 1 picks the nearer branch; the centre is the best
single guess).

Single tendon or pair (``single_tendon``): seed 004's actuator is one tendon that only pulls
(Sec. II-B; gravity returns the joint): with ``single_tendon`` = 1 a negative twist is slack
(no torque, no stiffness, no energy). The arm's joint 3 must be driven both ways, so it defaults
to a pull-pull pair of the same tendon-sheaths (0; the seed's future-work double TSA).

Sheath compliance and routing: ``sheath_ea_n`` puts the sheath's axial compliance in series with
the tendon over the sheath length (the same capstan-weighted tension compresses it, so the
branch ratio stays exactly e^(mu Theta)); ``routing_wrap_rad`` adds the routing's curvature to
the total bend. Both default to "absent" (rigid sheath, designed bend only): the seed gives
neither.

Seed 004's bench (``SEED004_BENCH``: single tendon; sheath stiffness, routing curvature and mu
fitted, with ``friction_speed_rad_s``, to the six branch gaps of Tables 1 and 2 together) gives
branch gaps within 8.2 % of both tables (``fsarm reproduce --paper 004``); the arm's defaults keep a rigid
sheath and mu = 0.15 (estimates), whose gap is ~100x smaller.

Energy (sliding, ``|z| = 1``, taut ``x > 0``): with ``tau_j = K_m x - K_d x z`` and ``tau_m`` the
other branch, the power lost is ``tau_m vm - tau_j vj - K_m x x' = K_d x z (vm + vj)``: it is
``K_d |x| |vm + vj| >= 0`` exactly because z follows ``sgn(vm + vj)`` (a z following ``vm``
alone would return energy wherever the joint end is pushed back faster than the motor pulls,
``vj < -vm``: a held motor with the joint pushed by hand or by a collision). Only while
z reverses (the stick phase, ``|z| < 1``) can the power be briefly negative: the Dahl state's
own presliding spring.
"""

from __future__ import annotations

import math
from typing import Any

from fsarm_sim.plant.transmissions.base import (
    Bounds,
    FloatArray,
    Param,
    TransmissionError,
    non_negative,
    positive,
)

NAME = "tendon-sheath"
TITLE = "Tendon-sheath: capstan friction along the bent sheath, tendon stretch, play (seed 004)"
SOURCE = (
    "seed 004 (tendon-sheath actuator): eq. 6-11 capstan friction and stretch, eq. 14-19 "
    "direction-dependent position transmission, Tables 1-2, Sec. III geometry"
)
ROUTED_OVER_JOINT2 = True
# estimate: elastic limit of drawn stainless wire ~0.3 % strain -> 3.6 mm on 1.2 m of tendon ->
# 0.14 rad at r = 25 mm (about 16 N*m at the default stiffness)
TWIST_RANGE_RAD = 0.15
STATES: tuple[str, ...] = ("z_friction",)
# parameter values that switch every dissipation of the law off (energy checks)
CONSERVATIVE: dict[str, float] = {"mu": 0.0}

# Seed 004 Tables 1-2: position transmission eq. 19, theta_1 = P th2^2 + Q th2 + M per direction
# (R.C. = rotate clockwise, R.A. = counter-clockwise), with the maximal error M.E. (rad).
# key -> {"RC": (P, Q, M, ME), "RA": (P, Q, M, ME)}
TABLE_1_VELOCITY: dict[float, dict[str, tuple[float, float, float, float]]] = {
    0.02: {"RC": (-0.145, 0.920, 0.225, 0.024), "RA": (-0.099, 0.914, 0.019, 0.021)},
    0.04: {"RC": (-0.208, 0.912, 0.308, 0.034), "RA": (-0.033, 0.911, -0.055, 0.044)},
    0.06: {"RC": (-0.251, 0.897, 0.361, 0.054), "RA": (-0.012, 0.904, -0.116, 0.055)},
}
TABLE_2_BEND: dict[float, dict[str, tuple[float, float, float, float]]] = {
    math.pi / 2.0: {"RC": (-0.208, 0.916, 0.301, 0.033), "RA": (-0.030, 0.913, -0.063, 0.034)},
    math.pi: {"RC": (-0.266, 0.911, 0.361, 0.031), "RA": (-0.055, 0.893, -0.123, 0.028)},
    3.0 * math.pi / 2.0: {
        "RC": (-0.307, 0.920, 0.414, 0.026),
        "RA": (-0.048, 0.883, -0.171, 0.024),
    },
}

# Seed 004's validation bench (Sec. III-IV: single tendon, 1 kg load) as our law reads it. The
# seed gives neither the sheath's axial stiffness, nor mu, nor any curvature beyond the designed
# bend, nor the load's lever: sheath_ea_n, routing_wrap_rad and mu are FITTED (estimate), with
# the default friction_speed_rad_s, to the six branch gaps of Tables 1 and 2 (M(R.C.) - M(R.A.):
# three bends at 0.06 rad/s, three speeds at bend pi; measure004) at the estimated 0.1 m lever
# (measure004.LEVER_M; the fit absorbs it): the largest relative error is minimised (8.2 %; the
# two tables disagree with each other by up to 33 %, see measure004.DEFAULT_SPEED). 1010 N is
# the compliance of everything in series with the sheathed run (a 0.6 mm steel tendon alone is
# ~1.1e5 N): tendon, sheath coil, end fittings; mu 0.405 is dry steel on a wound steel sheath.
SEED004_BENCH: dict[str, float] = {
    "single_tendon": 1.0,
    "sheath_ea_n": 1010.0,
    "routing_wrap_rad": 0.5,
    "mu": 0.405,
}

# parameter block indices (order of PARAMS)
I_MU = 0
I_WRAP = 1
I_RADIUS = 2
I_TENDON_R = 3
I_E = 4
I_L_TENDON = 5
I_L_SHEATH = 6
I_BACKLASH = 7
I_DELTA0 = 8
I_ROUTING = 9
I_SHEATH_EA = 10
I_V0 = 11
I_SINGLE = 12
I_SCALE = 13

# estimate: elastic limit of drawn stainless wire ~0.3 % strain (yield ~600 MPa / 193 GPa)
ELASTIC_STRAIN = 0.003

PARAMS: tuple[Param, ...] = (
    Param(
        "mu",
        0.15,
        "-",
        "estimate: tendon/sheath friction coefficient, not given in seed 004; steel tendon in a "
        "bare wound-steel sheath, typical 0.1-0.2",
        non_negative(
            "a Coulomb friction coefficient: >= 0 (friction only opposes sliding; < 0 would "
            "drive the tendon), <= 1 (dry steel on steel ~0.8, lined sheaths 0.05-0.3)",
            1.0,
        ),
    ),
    Param(
        "wrap_rad",
        math.pi / 2.0,
        "rad",
        "seed 004 Sec. III: 'whole bending angle of the tendon sheath is designed to pi/2'",
        non_negative(
            "the sheath's own total curvature angle: >= 0 (curvature angles add as magnitudes), "
            "<= 2 pi, one full loop (seed 004 Table 2 tests up to 3 pi/2)",
            2.0 * math.pi,
        ),
    ),
    Param(
        "pulley_radius_m",
        0.025,
        "m",
        "seed 004 Sec. III: joint pulley r2 = 25 mm (r1 = 20 mm)",
        positive(
            "a radius: > 0 (0 transmits no torque), <= 0.25 m, 10x the seed's 25 mm pulley and "
            "beyond any joint pulley of an arm (catches mm given as m)",
            0.25,
        ),
    ),
    Param(
        "tendon_radius_m",
        0.6e-3,
        "m",
        "seed 004 Sec. III: stainless tendon radius 0.6 mm",
        positive(
            "a radius: > 0 (0 leaves no cross-section: infinite compliance), <= 10 mm "
            "(seed 004: 0.6 mm; catches mm given as m)",
            0.01,
        ),
    ),
    Param(
        "youngs_modulus_pa",
        193e9,
        "Pa",
        "estimate: AISI 304 stainless steel; seed 004 gives no modulus (a stranded cable is softer)",
        Bounds(
            1e8,
            1.2e12,
            "a tendon material's modulus: >= 1e8 Pa (anything softer than nylon's 2-4 GPa is a "
            "rubber band, not a tendon), <= 1.2e12 Pa, diamond's: nothing is stiffer",
        ),
    ),
    Param(
        "tendon_length_m",
        1.2,
        "m",
        "seed 004 Sec. III: tendon 1.2 m",
        positive("a length: > 0, <= 10 m (a tendon along an arm; seed 004: 1.2 m)", 10.0),
    ),
    Param(
        "sheath_length_m",
        0.8,
        "m",
        "seed 004 Sec. III: sheath 0.8 m",
        non_negative(
            "a length: >= 0 (0 = a bare tendon), <= 10 m; and at most tendon_length_m (the "
            "tendon runs through the whole sheath)",
            10.0,
        ),
    ),
    Param(
        "backlash_rad",
        0.0,
        "rad",
        "dead band width; Tables 1-2 resolve none. Inside their data range the branch gap is "
        "G cos(theta2) + b (load-proportional capstan part + play): b = dM + 2 dP = 0.008, "
        "0.062, 0.067 rad (Table 2) and 0.114, 0.013, -0.001 rad (Table 1), mean 0.044 with a "
        "scatter of 0.045 rad, inside the fits' M.E. (0.021-0.055 rad); so the seed's "
        "'backlash' (phases C, F) is the load-proportional hysteresis of the friction state",
        non_negative(
            "a dead band width: >= 0, below the law's twist range TWIST_RANGE_RAD = 0.15 rad "
            "(wider play leaves no elastic range)",
            TWIST_RANGE_RAD,
            hi_open=True,
        ),
    ),
    Param(
        "presliding_rad",
        1e-3,
        "rad",
        "estimate: Dahl presliding floor at zero load (seed 004 uses static Coulomb friction)",
        positive(
            "> 0: the Dahl rate divides by it (0 is a division by zero), <= the twist range "
            "0.15 rad (a larger 'presliding' deflection is the whole law)",
            TWIST_RANGE_RAD,
        ),
    ),
    Param(
        "routing_wrap_rad",
        0.0,
        "rad",
        "curvature angle of the routing outside the designed bend (entries onto a plate, into the "
        "pulleys); 0: seed 004 states only the designed bend. Table 2's branch gaps "
        "(0.364/0.484/0.585 rad at pi/2, pi, 3pi/2) lie on a line through 0.25 rad at zero bend, "
        "which a routing curvature of ~3.6 rad would explain (not applied: see the module note)",
        non_negative(
            "a curvature angle: >= 0 (curvature angles add as magnitudes), <= 4 pi (two loops; "
            "more is a coiled sheath, not a routing)",
            4.0 * math.pi,
        ),
    ),
    Param(
        "sheath_ea_n",
        0.0,
        "N",
        "axial stiffness E A of the sheath (and its end fittings) in series with the tendon over "
        "the sheath length; 0: a rigid sheath (seed 004 gives no sheath stiffness; its Fig. 10(b) "
        "shows the tendon radius barely matters, which points at the sheath's compliance)",
        non_negative(
            "an axial stiffness: >= 0 (0 = rigid sheath), <= 1e9 N (a solid steel tube of the "
            "sheath's size is ~1e7 N)",
            1e9,
        ),
    ),
    Param(
        "friction_speed_rad_s",
        0.118,
        "rad/s",
        "fitted to seed 004 Tables 1-2 (estimate): the mobilised capstan friction grows with the "
        "sliding speed as |v| / (|v| + v0), v the motor end's speed (0: speed-independent). "
        "Table 1's branch gap grows with the motion velocity at quasi-static speeds "
        "(0.02-0.06 rad/s) where inertia is negligible: a velocity-strengthening (lubricated) "
        "friction. v0 is fitted with SEED004_BENCH to the tables' six branch gaps (within "
        "8.2 %; Table 1's gap ratios 0.43, 0.76, ours 0.46, 0.76); at the arm's motor speeds "
        "(rad/s and more) the factor is ~1",
        non_negative("a speed: >= 0 (0 = speed-independent friction), <= 100 rad/s", 100.0),
    ),
    Param(
        "single_tendon",
        0.0,
        "-",
        "1: seed 004's single tendon (pull only: no torque when slack, Sec. II-B); 0: a pull-pull "
        "pair of the same tendon-sheaths (what joint 3 needs to be driven both ways; the seed's "
        "future-work double TSA)",
        Bounds(0.0, 1.0, "a switch: 0 (pull-pull pair) or 1 (single tendon)"),
    ),
    Param(
        "scale",
        1.0,
        "-",
        "torque scale for the arm (1 = the seed's tendon and pulley)",
        positive(
            "a torque multiplier (tendons in parallel): > 0 (0 transmits nothing, < 0 reverses "
            "the spring); a stiffness too high for the timestep is refused at build"
        ),
    ),
)


def validate(tr: FloatArray) -> None:
    """Cross-parameter checks (each parameter's own range: ``PARAMS``' bounds, base.fill_block)."""
    if tr[I_L_SHEATH] > tr[I_L_TENDON]:
        raise TransmissionError(
            f"transmission {NAME!r}: sheath_length_m = {float(tr[I_L_SHEATH])!r} m is longer "
            f"than tendon_length_m = {float(tr[I_L_TENDON])!r} m; the tendon runs through the "
            "whole sheath, "
            "so sheath_length_m <= tendon_length_m"
        )


# ------------------------------------------------------------------ kernels (Numba-compilable)


def total_wrap_rad(tr: Any, bend: float) -> float:
    """Total curvature angle of the sheath: routing + its designed bend + the bend over joint 2."""
    return tr[I_ROUTING] + tr[I_WRAP] + abs(bend)


def capstan_ratio(mu: float, wrap_rad: float) -> float:
    """Eq. 7-8: tension ratio Phi_p = exp(mu Theta) between the ends while the tendon slides."""
    return math.exp(mu * wrap_rad)


def _axial_stiffness(tr: Any) -> float:
    """E A of the tendon (N)."""
    r = tr[I_TENDON_R]
    return tr[I_E] * math.pi * r * r


def _sheathed_compliance(tr: Any) -> float:
    """Axial compliance per metre of the sheathed run: tendon stretch + sheath compression (1/N);
    ``sheath_ea_n`` = 0 is a rigid sheath."""
    c = 1.0 / _axial_stiffness(tr)
    if tr[I_SHEATH_EA] > 0.0:
        c += 1.0 / tr[I_SHEATH_EA]
    return c


def _free_length(tr: Any) -> float:
    lf = tr[I_L_TENDON] - tr[I_L_SHEATH]
    return lf if lf > 0.0 else 0.0


def _sheath_factor(m: float) -> float:
    """(e^m - 1)/m, -> 1 as m -> 0 (eq. 11 integral over the sheath, uniform curvature)."""
    if abs(m) < 1e-9:
        return 1.0 + 0.5 * m
    return math.expm1(m) / m


def compliance_pull(tr: Any, bend: float) -> float:
    """Eq. 11 Theta_p: stretch per actuator-end tension while the motor pulls (m/N)."""
    m = tr[I_MU] * total_wrap_rad(tr, bend)
    lf = _free_length(tr)
    return 0.5 * lf * (1.0 + math.exp(-m)) / _axial_stiffness(tr) + tr[I_L_SHEATH] * _sheath_factor(
        -m
    ) * _sheathed_compliance(tr)


def compliance_release(tr: Any, bend: float) -> float:
    """Eq. 11 Theta_r: stretch per actuator-end tension while the load pulls back (m/N)."""
    m = tr[I_MU] * total_wrap_rad(tr, bend)
    lf = _free_length(tr)
    return 0.5 * lf * (1.0 + math.exp(m)) / _axial_stiffness(tr) + tr[I_L_SHEATH] * _sheath_factor(
        m
    ) * _sheathed_compliance(tr)


def branch_stiffness_pull(tr: Any, bend: float) -> float:
    """Loading branch: r^2 / C_pull (N*m/rad, no scale)."""
    r = tr[I_RADIUS]
    return r * r / compliance_pull(tr, bend)


def branch_stiffness_release(tr: Any, bend: float) -> float:
    """Unloading branch: r^2 / C_rel (N*m/rad, no scale)."""
    r = tr[I_RADIUS]
    return r * r / compliance_release(tr, bend)


def _sheath_factor_slope(m: float) -> float:
    """d/dm of (e^m - 1)/m (-> 1/2 as m -> 0)."""
    if abs(m) < 1e-6:
        return 0.5 + m / 3.0
    return (m * math.exp(m) - math.expm1(m)) / (m * m)


def effective_twist_rad(tr: Any, x: float) -> float:
    """Twist reaching the tendon through the dead band of width backlash_rad (centred at 0);
    a single tendon (``single_tendon`` = 1) is slack below it: no negative twist reaches it."""
    half = 0.5 * tr[I_BACKLASH]
    if x > half:
        return x - half
    if x < -half and tr[I_SINGLE] < 0.5:
        return x + half
    return 0.0


def _mean_stiffness(tr: Any, bend: float) -> float:
    return 0.5 * (branch_stiffness_pull(tr, bend) + branch_stiffness_release(tr, bend))


def bend_torque_nm(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    """-dV/dphi_B: the capstan factor e^(mu Theta) grows with the bend over joint 2, so the
    branch stiffnesses (eq. 11) and the stored energy change with it at constant twist."""
    if bend == 0.0 or tr[I_MU] == 0.0:
        return 0.0
    m = tr[I_MU] * total_wrap_rad(tr, bend)
    lf = _free_length(tr)
    ea = _axial_stiffness(tr)
    cs = _sheathed_compliance(tr)
    r2 = tr[I_RADIUS] * tr[I_RADIUS]
    c_p = compliance_pull(tr, bend)
    c_r = compliance_release(tr, bend)
    dc_p = -0.5 * lf * math.exp(-m) / ea - tr[I_L_SHEATH] * _sheath_factor_slope(-m) * cs
    dc_r = 0.5 * lf * math.exp(m) / ea + tr[I_L_SHEATH] * _sheath_factor_slope(m) * cs
    dkm_dm = 0.5 * (-r2 * dc_p / (c_p * c_p) - r2 * dc_r / (c_r * c_r))
    xe = effective_twist_rad(tr, x)
    dm_db = tr[I_MU] * math.copysign(1.0, bend)
    return -tr[I_SCALE] * 0.5 * xe * xe * dkm_dm * dm_db


def sensor_torque_nm(tr: Any, x: float, bend: float) -> float:
    return tr[I_SCALE] * _mean_stiffness(tr, bend) * effective_twist_rad(tr, x)


def stiffness_nm_per_rad(tr: Any, x: float, bend: float) -> float:
    half = 0.5 * tr[I_BACKLASH]
    if abs(x) < half or (tr[I_SINGLE] > 0.5 and x < half):  # in the play, or slack
        return 0.0
    return tr[I_SCALE] * _mean_stiffness(tr, bend)


def _z(act: Any, a0: int) -> float:
    z = act[a0]
    if z > 1.0:
        return 1.0
    if z < -1.0:
        return -1.0
    return float(z)


def torque_nm(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int) -> float:
    """Joint-end torque ``r F_j``: while the motor pulls (z = +1 for a taut positive twist) the
    tension falls along the sheath towards the joint, so the joint sees the softer branch
    ``K_rel x``; while it releases, ``K_pull x`` (``K_m x - K_d |x| z``)."""
    kp = branch_stiffness_pull(tr, bend)
    kr = branch_stiffness_release(tr, bend)
    xe = effective_twist_rad(tr, x)
    return tr[I_SCALE] * (0.5 * (kp + kr) * xe - 0.5 * (kp - kr) * abs(xe) * _z(act, a0))


def motor_torque_nm(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int) -> float:
    """Motor-end torque ``r F_m = r F_j e^(mu Theta z s)`` (eq. 7-8; s the sign of the taut
    tendon's twist, z -> +-1 while sliding): the sheath's friction takes the difference, so the
    motor pays ``e^(mu Theta)`` times the joint's torque while pulling (``K_pull x``) and gets
    ``e^(-mu Theta)`` of it while releasing (``K_rel x``)."""
    tau_j = torque_nm(tr, x, xdot, bend, act, a0)
    xe = effective_twist_rad(tr, x)
    if xe == 0.0:
        return tau_j
    s = 1.0 if xe > 0.0 else -1.0
    return tau_j * math.exp(tr[I_MU] * total_wrap_rad(tr, bend) * _z(act, a0) * s)


def presliding_rad(tr: Any, x: float, bend: float) -> float:
    """Scale of the friction state's switch in motor travel: ``D / K_m = delta0 + K_d/K_m
    |x_eff|`` (the full switch at constant joint torque takes ~2 K_d |x| / K_pull, seed 004
    phases C and F)."""
    kp = branch_stiffness_pull(tr, bend)
    kr = branch_stiffness_release(tr, bend)
    return tr[I_DELTA0] + (kp - kr) / (kp + kr) * abs(effective_twist_rad(tr, x))


def stick_rate(tr: Any, x: float, bend: float, z: float) -> float:
    """dz/dtheta_m that keeps the joint end's tension constant while the friction along the
    sheath reverses (the joint end stuck, seed 004 phases C and F: the motor turns, the joint
    stays): from ``d(K_m x - K_d |x| z) = 0``, ``(K_m - s K_d z) / (K_d |x| + K_m delta0)``
    (s the taut twist's sign; ``delta0`` keeps it finite at zero twist)."""
    km, kd, s, d = _dahl_terms(tr, x, bend)
    return (km - s * kd * z) / d


def _dahl_terms(tr: Any, x: float, bend: float) -> tuple[float, float, float, float]:
    """``(K_m, K_d, s, D)`` of the friction state's stick law at twist ``x``: the branches' mean
    and half-difference stiffness, the taut twist's sign and ``D = K_d |x_eff| + K_m delta0``
    (shared by :func:`stick_rate` and :func:`friction_step`)."""
    kp = branch_stiffness_pull(tr, bend)
    kr = branch_stiffness_release(tr, bend)
    km, kd = 0.5 * (kp + kr), 0.5 * (kp - kr)
    xe = effective_twist_rad(tr, x)
    s = -1.0 if xe < 0.0 else 1.0
    return km, kd, s, kd * abs(xe) + km * tr[I_DELTA0]


def friction_fraction(tr: Any, vm: float) -> float:
    """Speed-dependent share of the capstan friction mobilised while sliding:
    ``|vm| / (|vm| + v0)`` (1 with v0 = 0; Table 1's rate effect)."""
    v = abs(vm)
    if tr[I_V0] <= 0.0:
        return 1.0
    return v / (v + tr[I_V0])


def sliding_target(tr: Any, travel: float, speed: float) -> float:
    """Where the friction state heads while the tendon slides: ``sgn(travel)
    friction_fraction(speed)`` (``travel`` the sliding direction, the sum of the ends' motions;
    ``speed`` the faster end's)."""
    target = friction_fraction(tr, speed)
    return -target if travel < 0.0 else target


# width (in z) over which the ramp slows down on reaching its target (smooths the arrival)
Z_SMOOTH = 0.02


def state_rate(
    tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int, i: int, vm: float
) -> float:
    """dz/dt: z follows the direction the tendon slides in the sheath, that of the sum of its two
    ends' speeds ``u = vm + vj`` (``vj = vm - xdot``, the joint end; see the module docstring,
    *Energy*: this is what keeps the sliding friction dissipative), at the stick rate per unit
    of ``u`` (:func:`stick_rate`: the joint end holds while the friction reverses, phases C and
    F, where ``u = vm`` as in eq. 5's sgn(x')) towards ``sgn(u) friction_fraction(v)``, ``v`` the
    faster end's speed; at rest it holds."""
    if i != 0:
        return 0.0
    z = _z(act, a0)
    vj = vm - xdot
    u = vm + vj
    target = sliding_target(tr, u, max(abs(vm), abs(vj)))
    gap = (target - z) / Z_SMOOTH
    if gap > 1.0:
        gap = 1.0
    elif gap < -1.0:
        gap = -1.0
    return abs(u) * stick_rate(tr, x, bend, z) * gap


def potential_j(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    xe = effective_twist_rad(tr, x)
    return tr[I_SCALE] * 0.5 * _mean_stiffness(tr, bend) * xe * xe


# ------------------------------------------------------------------ Python side


def valid_twist_rad(tr: Any) -> float:
    """Twist at which the tendon reaches its elastic limit on the softer (releasing) branch,
    straight: ``ELASTIC_STRAIN E A C_rel / r`` (the twist the law is valid for)."""
    f_lim = ELASTIC_STRAIN * _axial_stiffness(tr)
    return float(f_lim * compliance_release(tr, 0.0) / tr[I_RADIUS] + 0.5 * tr[I_BACKLASH])


def state_limits(tr: Any) -> list[tuple[float, float] | None]:
    """The Dahl state stays within [-1, 1]."""
    return [(-1.0, 1.0)]


def initial_states(tr: Any, x: float, bend: float) -> list[float]:
    """Friction element relaxed."""
    return [0.0]


def friction_step(
    tr: Any,
    x: float,
    dtheta_m: float,
    bend: float,
    z: float,
    dt: float = 0.0,
    dtheta_j: float = 0.0,
) -> float:
    """z after a step of the motor end ``dtheta_m`` and of the joint end ``dtheta_j`` taken over
    ``dt`` (> 0; 0: infinitely fast) at constant twist: the stick rate of :func:`state_rate`
    solved exactly over the sliding travel ``u = dtheta_m + dtheta_j``
    (``z -> A + (z - A) exp(-s K_d u / D)``, ``A = s K_m / K_d``), stopping at its target
    (for quasi-static solutions)."""
    travel = dtheta_m + dtheta_j
    if travel == 0.0:
        return z
    if dt > 0.0:
        target = sliding_target(tr, travel, max(abs(dtheta_m), abs(dtheta_j)) / dt)
    else:  # infinitely fast: the full friction
        target = -1.0 if travel < 0.0 else 1.0
    km, kd, s, d = _dahl_terms(tr, x, bend)
    if kd <= 0.0:  # no friction: the state jumps to its target (it carries no torque)
        return target
    a = s * km / kd
    moved = a + (z - a) * math.exp(-s * kd * travel / d)
    if (target - z) * (target - moved) <= 0.0:  # reached (or passed) the target
        return target
    if (target - z) * (moved - z) < 0.0:  # never moves away from its target
        return z
    return moved


def position_transmission_rad(theta2_hat: float, p: float, q: float, m: float) -> float:
    """Eq. 19: the motor angle the seed's fitted model predicts for joint-encoder reading th2."""
    return p * theta2_hat * theta2_hat + q * theta2_hat + m
