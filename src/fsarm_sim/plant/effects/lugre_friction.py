"""LuGre friction at joint 3: a bristle state gives presliding, stiction and the Stribeck dip.

Canudas de Wit, Olsson, Astrom and Lischinsky, "A new model for control of systems with
friction", IEEE Trans. Automatic Control 40(3), 1995, eq. 2-5, written for joint 3's rate
``v = qd3`` and its own state, the mean bristle deflection ``z`` (rad):

    g(v)  = F_c + (F_s - F_c) exp(-(v / v_s)^2)          Stribeck curve
    dz/dt = v - sigma_0 |v| z / g(v)
    F     = sigma_0 z + sigma_1 dz/dt + sigma_2 v        torque on joint 3: -F

At steady sliding ``dz/dt = 0`` and ``F = g(v) sgn(v) + sigma_2 v`` (the Stribeck curve); at rest
``dz/dt = 0`` and the joint sits on a spring ``sigma_0`` (presliding) until the load exceeds
``F_s``. The law acts on the plant's joint 3 (its bearing and hypoid), the controllers do not
know it.

Parameters (the paper's example is a 1 kg mass: sigma_0 = 1e5 N/m, sigma_1 = sqrt(1e5) N*s/m,
sigma_2 = 0.4 N*s/m, F_c = 1 N, F_s = 1.5 N, v_s = 1e-3 m/s; none is measured for this arm):

* ``F_c`` 0.3 N*m: estimate (no seed states joint 3's friction): 0.5 % of the 67 N*m the
  joint carries at the shaft's 6.7 N*m rating through the 10:1 hypoid; the diagnosis fits it.
* ``F_s`` = 1.5 F_c: the paper's ratio (estimate).
* ``v_s`` 0.01 rad/s: estimate, the paper's 1 mm/s at a 0.1 m lever (joint 3's scenarios move at
  up to 1.3 rad/s, so they cross the dip only at reversals).
* ``sigma_0`` 1000 N*m/rad: estimate; presliding of F_c / sigma_0 = 0.3 mrad, and the stuck
  joint's mode sqrt(sigma_0 / I_3) ~ 90 rad/s with I_3 ~ 0.12 kg*m^2 (link 3 unloaded,
  models/fsarm/README.md) keeps omega * h ~ 0.09 at the 1 ms step.
* ``sigma_1`` 10 N*m*s/rad: sqrt(sigma_0 I_3), a damping ratio of ~0.5 of that mode (the
  paper's choice sqrt(sigma_0 m) for its mass); h sigma_1 / I_3 ~ 0.08 stays explicit-stable.
* ``sigma_2`` 0: joint 3's viscous friction is already the MJCF's damping (0.2 N*m*s/rad).

Integration: ``dz/dt`` is stiff when ``sigma_0 |v| h / g`` is large (a fast joint, a small F_c).
:func:`state_rate` therefore returns the rate that makes MuJoCo's explicit step of length h land
on the exact solution of ``dz/dt = v - a z`` at the step's ``v`` (``a = sigma_0 |v| / g``):
``z(h) = z_ss + (z - z_ss) exp(-a h)``, ``z_ss = v / a``; it equals the ODE's rate for ``a h``
small. The damping term ``sigma_1 dz/dt`` uses the same step rate: eq. 3's raw rate ``a (z_ss - z)``
grows without bound where ``g`` is small (``F_s = 0`` at rest, ``F_c = 0`` at speed) and would
kick the joint; the step rate never exceeds ``|z_ss - z| / h``. Without friction (``g <= 0``) or
without bristles (``sigma_0 <= 0``) the law is the viscous term alone and ``z`` relaxes to 0 in
one step.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import S_OWN, S_QD3, S_TIMESTEP, State

FloatArray = npt.NDArray[np.float64]

KERNEL_PARAMS = (
    Decl("f_c_nm", "N*m", 0.3, "Coulomb level F_c (estimate, module docstring; fitted)"),
    Decl("f_s_nm", "N*m", 0.45, "static (breakaway) level F_s = 1.5 F_c (paper's ratio; fitted)"),
    Decl("v_s_rad_s", "rad/s", 0.01, "Stribeck speed v_s (estimate, module docstring)"),
    Decl("sigma0_nm_per_rad", "N*m/rad", 1000.0, "bristle stiffness sigma_0 (estimate)"),
    Decl("sigma1_nms", "N*m*s/rad", 10.0, "bristle damping sigma_1 (estimate)"),
    Decl("sigma2_nms", "N*m*s/rad", 0.0, "viscous sigma_2 (0: the MJCF's damping has it)"),
)
# validity of each parameter (engine.model.validate_laws): sigma_0 and sigma_1 bounded so the stuck
# joint's mode and its damping stay explicit-stable at a 1 ms step with I_3 >= 0.12 kg*m^2
# (omega h <= 0.3, h sigma_1 / I_3 <= 0.4); the registry's fit bounds take precedence
LIMITS = {
    "f_c_nm": (0.0, 20.0),
    "f_s_nm": (0.0, 20.0),
    "v_s_rad_s": (0.0, 10.0),
    "sigma0_nm_per_rad": (0.0, 1e4),
    "sigma1_nms": (0.0, 50.0),
    "sigma2_nms": (0.0, 20.0),
}
STATES = (Decl("z_rad", "rad", 0.0, "mean bristle deflection z (starts relaxed)"),)


def stribeck_nm(v: float, f_c: float, f_s: float, v_s: float) -> float:
    """g(v) = F_c + (F_s - F_c) exp(-(v / v_s)^2) (> 0 for F_c, F_s > 0); F_c for v_s <= 0."""
    if v_s <= 0.0:
        return f_c
    r = v / v_s
    return f_c + (f_s - f_c) * math.exp(-r * r)


def steady_friction_nm(v: float, blk: FloatArray) -> float:
    """Friction torque at steady sliding at rate ``v``: g(v) sgn(v) + sigma_2 v (the law's
    fixed point; for tests and plots)."""
    g = stribeck_nm(v, blk[0], blk[1], blk[2])
    return math.copysign(g, v) + blk[5] * v if v != 0.0 else 0.0


def bristle_rate(v: float, z: float, blk: FloatArray, h: float) -> float:
    """dz/dt over one step of length ``h``, exact for eq. 3 at frozen ``v`` (module docstring):
    the ODE's rate ``v - a z`` while ``a h`` is small, never more than reaches the fixed point
    in one step; ``-z / h`` (relax) without bristles or friction."""
    g = stribeck_nm(v, blk[0], blk[1], blk[2])
    sigma0 = blk[3]
    if g <= 0.0 or sigma0 <= 0.0:
        return -z / h
    ah_g = sigma0 * abs(v) * h  # a h g, a = sigma_0 |v| / g (never divided by a tiny g)
    if ah_g < 1e-9 * g:
        return v - sigma0 * abs(v) * z / g
    z_ss = math.copysign(g / sigma0, v)  # = v / a
    decay = -math.expm1(-ah_g / g) if ah_g < 700.0 * g else 1.0
    return (z_ss - z) * decay / h


def friction_nm(v: float, z: float, blk: FloatArray, h: float) -> float:
    """F = sigma_0 z + sigma_1 dz/dt + sigma_2 v (opposes motion; the joint feels -F), with the
    step's bristle rate (:func:`bristle_rate`: bounded where eq. 3's raw rate is stiff); the
    viscous term alone without bristles or friction."""
    g = stribeck_nm(v, blk[0], blk[1], blk[2])
    if g <= 0.0 or blk[3] <= 0.0:
        return blk[5] * v
    return blk[3] * z + blk[4] * bristle_rate(v, z, blk, h) + blk[5] * v


def arm_torques(blk: FloatArray, s: State) -> tuple[float, float, float]:
    """(joint 2, joint 3, shaft input): the friction acts on joint 3 only."""
    return 0.0, -friction_nm(s[S_QD3], s[S_OWN], blk, s[S_TIMESTEP]), 0.0


def state_rate(blk: FloatArray, s: State, i: int) -> float:
    """dz/dt over one step (:func:`bristle_rate`)."""
    return bristle_rate(s[S_QD3], s[S_OWN], blk, s[S_TIMESTEP])
