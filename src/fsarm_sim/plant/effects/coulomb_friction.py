"""Coulomb (dry) friction: a torque of constant magnitude opposing motion.

Seed 003 Table 3/5 (``-tau_fr sign(phi_out')``, "model of dry kinetic friction") and seed 002
Sec. IV-C (friction of an elastic joint "modeled as pure Coulomb friction, depending on
sgn(phi')"). Two places it can act on a bench, same law:

* on a moving body (the load bearing of the series bench): sliding torque ``-F sgn(v)``, sticking
  while the other torques stay below ``F``. :func:`stick_slip_velocity` is the implicit
  time-stepping form (Karnopp-like): exact stick, no chatter, never adds energy.
* inside an elastic element, in parallel with its spring (shaft core rubbing in its casing, a
  joint's bearing ahead of a torque sensor): the element carries ``+F sgn(rate of deflection)``.
  Stated as a stiff elasto-slip ("presliding") element - a spring of deflection limit ``delta``
  that saturates at ``F`` - so a position-driven replay never divides by a noisy velocity:
  after a reversal the torque swings by ``2 F`` within a deflection ``2 delta``.

On the arm it acts at joint 3 (its bearing and hypoid) as a registry law MuJoCo applies itself
(:mod:`.base`, ``MODEL_WRITES``): ``F`` is added to joint 3's ``dof_frictionloss``, the
constraint solver's dry friction - exact stick within ``F``, sliding torque ``-F sgn(qd3)``,
never adds energy - rather than a smoothed sign in the passive callback.
"""

from __future__ import annotations

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import ModelWrite

# the arm law: joint 3's Coulomb friction level (0: none)
KERNEL_PARAMS = (Decl("f_c_nm", "N*m", 0.0, "Coulomb friction torque at joint 3"),)
STATES: tuple[Decl, ...] = ()
MODEL_WRITES = (ModelWrite("dof_frictionloss", "q3", "f_c_nm"),)
SIZE = "f_c_nm"  # at 0 the law acts as nothing (a model with it at 0 is the same run)
# the key of this law in the effects entry of older run records (records.sidecar)
LEGACY_FIELDS = (("q3_friction_nm", "f_c_nm"),)


def sliding_torque_nm(velocity: float, f_c: float) -> float:
    """Friction torque on a body sliding at ``velocity`` (rad/s): ``-F sgn(v)``, 0 at rest."""
    if velocity > 0.0:
        return -f_c
    if velocity < 0.0:
        return f_c
    return 0.0


def stick_slip_velocity(v_free: float, impulse_limit: float) -> float:
    """Velocity after one implicit step with Coulomb friction.

    ``v_free``: the velocity the body would reach in the step without friction;
    ``impulse_limit = h F / J``: the largest velocity change friction can cause in the step.
    Friction first brings the body to rest if it can (stick), otherwise removes ``impulse_limit``.
    """
    if v_free > impulse_limit:
        return v_free - impulse_limit
    if v_free < -impulse_limit:
        return v_free + impulse_limit
    return 0.0


def presliding_state(z_rad: float, d_deflection_rad: float, delta_rad: float) -> float:
    """Update of the presliding deflection: follows the element's deflection, limited to +-delta."""
    z = z_rad + d_deflection_rad
    if z > delta_rad:
        return delta_rad
    if z < -delta_rad:
        return -delta_rad
    return z


def presliding_torque_nm(z_rad: float, delta_rad: float, f_c: float) -> float:
    """Torque the friction element carries: ``F z / delta`` (``+-F`` while sliding)."""
    return f_c * z_rad / delta_rad if delta_rad > 0.0 else 0.0


def dissipation_w(velocity: float, f_c: float) -> float:
    """Power dissipated while sliding: ``F |v|`` (never negative)."""
    return f_c * abs(velocity)
