"""Drag of the shaft's core in its casing, growing with the bend of the route (arm).

The core of a flexible shaft turns inside a fixed casing. Where the route bends, the core is
pressed against the casing's liner and rubs on it, so part of the motor's torque is lost before it
reaches the shaft's spring. Like the shaft's internal friction (:mod:`.bend_friction`), the loss
grows with the route's wrap angle as on a capstan (seed 004 eq. 7-8, ``T_out = T_in e^(mu Theta)``
along a bent sheath): joint 2's bend adds ``|phi_B|`` to the wrap. The drag acts on the shaft
input theta_m (the core turns with the motor side), not on the twist, so the virtual torque sensor
(eq. 8, on the twist) does not see it; the speed loop must supply it, and it is the bend-dependent
loss of seed 001's transmission efficiency and torque capacity (Sec. 6.1: "the losses increase
with the bending"). Torque on the shaft input:

    tau_d = -T_0 exp(mu_b |phi_B|) tanh(omega_m / omega_s)

``T_0`` (straight) and ``mu_b`` are per-shaft unknowns (no paper states them: found by the
discrepancy workflow, default off). ``omega_s`` smooths the sign: an estimate, 1 rad/s at the
shaft input, well below the shaft speeds of the tracking scenarios (up to ~12 rad/s in fig14-sine)
so the drag is Coulomb-like there, and large enough that the equivalent damping on the rotor,
``T_0 / omega_s / i_G1^2`` (i_G1 = 16), stays far below ``I_rotor / h`` (3e-5 kg m^2 / 1 ms) for
``T_0`` up to the registry's 2 N*m, so explicit integration stays stable.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import S_BEND, S_OMEGA_M, State

FloatArray = npt.NDArray[np.float64]

KERNEL_PARAMS = (
    Decl("drag_nm", "N*m", 0.0, "drag torque straight, at the shaft input (fitted; unknown)"),
    Decl("mu_per_rad", "1/rad", 0.0, "capstan growth with |bend| (fitted; seed 004 eq. 7-8 form)"),
    Decl("omega_s", "rad/s", 1.0, "sign-smoothing speed at the shaft input (estimate, see above)"),
)
STATES: tuple[Decl, ...] = ()


def drag_torque_nm(
    omega_m: float, bend: float, drag_nm: float, mu_per_rad: float, omega_s: float
) -> float:
    """Torque of the casing on the shaft input (opposes omega_m; grows with |bend|)."""
    return -drag_nm * math.exp(mu_per_rad * abs(bend)) * math.tanh(omega_m / omega_s)


def arm_torques(blk: FloatArray, s: State) -> tuple[float, float, float]:
    """(joint 2, joint 3, shaft input) torques: the drag acts on the shaft input only."""
    return 0.0, 0.0, drag_torque_nm(s[S_OMEGA_M], s[S_BEND], blk[0], blk[1], blk[2])


def state_rate(blk: FloatArray, s: State, i: int) -> float:
    """The drag has no state of its own (never called)."""
    return 0.0
