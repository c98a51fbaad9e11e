"""Viscous damping: a torque proportional to a velocity (seed 000 eq. 1 ``B dtheta/dt``; seed 003
Table 5 ``-y phi_out'`` / ``-z (phi_out' - phi_in')``).

On a bench it acts either in parallel with the shaft spring (rate of twist or of bend, eq. 1's
``B_p, B_n``; the torque sensor reads it) or on the load bearing (load speed; the sensor sees it
only through the load's motion). The damper carries ``b * rate``; whoever applies it decides the
sign (it always resists the rate), so it dissipates ``b rate^2 >= 0``.

On the arm it acts at joint 3 as extra viscous damping, a registry law MuJoCo applies itself
(:mod:`.base`, ``MODEL_WRITES``): ``b`` is added to joint 3's ``dof_damping``, which MuJoCo
integrates implicitly (stable for any ``b``), on top of the MJCF's own damping.
"""

from __future__ import annotations

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import ModelWrite

# the arm law: joint 3's extra damping coefficient (0: none)
KERNEL_PARAMS = (Decl("b_nms", "N*m*s/rad", 0.0, "extra viscous damping at joint 3"),)
STATES: tuple[Decl, ...] = ()
MODEL_WRITES = (ModelWrite("dof_damping", "q3", "b_nms"),)
SIZE = "b_nms"  # at 0 the law acts as nothing (a model with it at 0 is the same run)
# the key of this law in the effects entry of older run records (records.sidecar)
LEGACY_FIELDS = (("q3_damping_nms", "b_nms"),)


def damper_torque_nm(rate: float, b: float) -> float:
    """Torque the damper carries at ``rate`` (rad/s): ``b * rate``."""
    return b * rate


def dissipation_w(rate: float, b: float) -> float:
    """Power dissipated: ``b rate^2`` (never negative for b >= 0)."""
    return b * rate * rate
