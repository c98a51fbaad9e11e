"""Payload error (arm setup): the payload on the flange differs from the one the run states.

A mass error ``dm`` at the payload's centre of mass changes the gravity torque on joints 2 and 3
(both axes horizontal and parallel, seed 000 Sec. IV / physics.md). With q2 measured from upright
and q3 relative to link 2 (models/fsarm/fsarm.xml: link 2 and link 3 point along +z, hinges about
+y), the payload centre sits at horizontal distance ``l2 sin q2 + l3 sin(q2 + q3)`` from joint 2
and ``l3 sin(q2 + q3)`` from joint 3, so gravity adds the generalized forces below (positive: away
from upright). Joint 3 passes its torque through the hypoid (i_G2) into the shaft, so the error
also shows as extra shaft twist ``tau_3 / (i_G2 K)`` - how the discrepancy workflow would see it.

Lengths and g are arguments: the caller reads them from the compiled MJCF (never repeated here).
On the arm the law acts through the registry like any other (``arm_torques`` of the named state);
``--effect payload_error=DM`` switches it on, and the model builder writes the geometry
(``FROM_MODEL``).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import S_Q2, S_Q3, State

FloatArray = npt.NDArray[np.float64]

# the parameters this law takes in the kernels (layout allocates their slots)
KERNEL_PARAMS = (
    Decl("dm_kg", "kg", 0.0, "payload mass the controllers do not know"),
    Decl("l2", "m", 0.0, "joint 2 -> joint 3 distance (read from the compiled MJCF)"),
    Decl("l3", "m", 0.0, "joint 3 -> payload centre of mass (read from the compiled MJCF)"),
    Decl("gravity", "m/s^2", 0.0, "|g| (read from the compiled MJCF)"),
)
FROM_MODEL = ("l2", "l3", "gravity")  # written by the model builder, never given by a user
SIZE = "dm_kg"  # at 0 the law acts as nothing (a model with it at 0 is the same run)
# the key of this law in the effects entry of older run records (records.sidecar)
LEGACY_FIELDS = (("payload_error_kg", "dm_kg"),)
STATES: tuple[Decl, ...] = ()


def gravity_torques_nm(
    dm_kg: float, q2_rad: float, q3_rad: float, l2_m: float, l3_m: float, g_m_s2: float
) -> tuple[float, float]:
    """Generalized gravity forces (joint 2, joint 3) of an extra payload mass ``dm_kg``.

    ``l2_m``: joint 2 to joint 3; ``l3_m``: joint 3 to the payload's centre of mass.
    """
    s23 = math.sin(q2_rad + q3_rad)
    tau3 = dm_kg * g_m_s2 * l3_m * s23
    tau2 = dm_kg * g_m_s2 * (l2_m * math.sin(q2_rad) + l3_m * s23)
    return tau2, tau3


def shaft_twist_error_rad(tau3_nm: float, gear_ratio: float, k_shaft: float) -> float:
    """Static extra shaft twist that carries an extra joint-3 torque through an i_G2 gearbox."""
    return tau3_nm / (gear_ratio * k_shaft)


def arm_torques(blk: FloatArray, s: State) -> tuple[float, float, float]:
    """(joint 2, joint 3, shaft input): the extra mass's gravity on joints 2 and 3 (zero where the
    model has no joint 2 or payload: its lever arms are 0 there)."""
    tau2, tau3 = gravity_torques_nm(blk[0], s[S_Q2], s[S_Q3], blk[1], blk[2], blk[3])
    return tau2, tau3, 0.0


def state_rate(blk: FloatArray, s: State, i: int) -> float:
    """The payload error has no state of its own (never called)."""
    return 0.0
