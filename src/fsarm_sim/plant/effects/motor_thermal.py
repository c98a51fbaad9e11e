"""Joint 3's motor warms up: copper loss heats the winding, and a hot motor gives less torque.

One thermal node (winding and housing lumped) with its temperature rise ``dT`` above the ambient
as the law's own state (starts at 0: a motor at ambient temperature):

    C_th d(dT)/dt = P - dT / R_th,      P = R(T) I^2,   I = tau_cmd / k_t0

``tau_cmd`` is the rotor torque the speed loop commands; the drive turns it into the current
``I`` with the torque constant it was configured with, ``k_t0`` (stated at the reference
temperature ``T_ref`` = 25 C). The winding's resistance rises with its temperature and the
magnets' flux falls with it:

    R(T) = R_0 (1 + alpha_Cu (T - T_ref)),    k_t(T) = k_t0 (1 + alpha_kt (T - T_ref)),

with ``T = T_ref + dT_amb + dT``. So the rotor gets ``k_t(T) I = tau_cmd k_t(T) / k_t0``: the
law adds ``tau_cmd alpha_kt (T - T_ref)`` at the rotor (a loss for alpha_kt < 0), i.e. that
times ``i_G1`` at the shaft input. At constant power the rise settles at ``R_th P`` (the steady
state tests check) with the time constant ``R_th C_th``. The controllers do not know the law; the
speed loop's integrator makes up the lost torque.

Numbers (estimates for the maxon EC-i 52-class motor models/fsarm/README.md assumes; the seeds
state none):

* ``k_t0`` 0.1 N*m/A and ``R_0`` 1.0 ohm: the order of a 48 V EC-i 52 winding; with the 0.42 N*m
  continuous need (README) they give P ~ 18 W.
* ``alpha_Cu`` = 0.00393 1/K: copper's resistance temperature coefficient at 20-25 C (standard
  handbook value).
* ``alpha_kt`` = -0.001 1/K: NdFeB magnets' remanence falls by about 0.1 %/K (magnet makers'
  grade tables give -0.09 to -0.12 %/K; the flux and so k_t follow it).
* ``R_th`` 3.5 K/W: winding-to-housing plus housing-to-ambient of such a motor (about 1.5 and
  2 K/W in maxon's catalogue format) in one node; 18 W then settle ~63 K above ambient.
* ``C_th`` 30 J/K: estimate for the winding with the stator iron it is bonded to (~0.1 kg of
  copper, 385 J/(kg K), and ~0.1 kg of iron, 450 J/(kg K)): time constant ~100 s, between the
  catalogue's winding (~30 s) and whole-motor (~1000 s) constants.
* ``dT_amb`` 0 K: ambient at the reference temperature (a hot cabinet: > 0).

The rise is recorded as the column ``motor_thermal.dtemp_k`` while the law is on.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant.effects.base import S_COEF_M, S_OWN, S_TAU_ROTOR, State

FloatArray = npt.NDArray[np.float64]

KERNEL_PARAMS = (
    Decl("dtemp_amb_k", "K", 0.0, "ambient minus the 25 C reference (estimate: 0; fitted)"),
    Decl("r_th_k_per_w", "K/W", 3.5, "thermal resistance winding -> ambient (estimate)"),
    Decl("c_th_j_per_k", "J/K", 30.0, "heat capacity of the node (estimate)"),
    Decl("kt0_nm_per_a", "N*m/A", 0.1, "torque constant at 25 C (estimate, EC-i 52 class)"),
    Decl("r0_ohm", "ohm", 1.0, "winding resistance at 25 C (estimate, EC-i 52 class)"),
    Decl("alpha_cu_per_k", "1/K", 0.00393, "copper's resistance coefficient (handbook)"),
    Decl("alpha_kt_per_k", "1/K", -0.001, "torque constant's coefficient (NdFeB, ~-0.1 %/K)"),
)
# validity of each parameter (engine.model.validate_laws); divisors strictly positive
LIMITS = {
    "dtemp_amb_k": (-50.0, 150.0),
    "r_th_k_per_w": (0.01, 100.0),
    "c_th_j_per_k": (0.1, 1e5),
    "kt0_nm_per_a": (1e-3, 10.0),
    "r0_ohm": (0.0, 100.0),
    "alpha_cu_per_k": (0.0, 0.01),
    "alpha_kt_per_k": (-0.01, 0.0),
}
STATES = (Decl("dtemp_k", "K", 0.0, "winding temperature above ambient (starts at ambient)"),)


def temperature_above_ref_k(dtemp: float, blk: FloatArray) -> float:
    """T - T_ref: the ambient's offset plus the rise."""
    return blk[0] + dtemp


def copper_loss_w(tau_cmd: float, dtemp: float, blk: FloatArray) -> float:
    """P = R(T) I^2 with I = tau_cmd / k_t0 (the drive's current for the commanded torque)."""
    current = tau_cmd / blk[3]
    return blk[4] * (1.0 + blk[5] * temperature_above_ref_k(dtemp, blk)) * current * current


def torque_factor(dtemp: float, blk: FloatArray) -> float:
    """k_t(T) / k_t0."""
    return 1.0 + blk[6] * temperature_above_ref_k(dtemp, blk)


def steady_rise_k(power_w: float, blk: FloatArray) -> float:
    """The rise a constant loss settles at: R_th P."""
    return blk[1] * power_w


def arm_torques(blk: FloatArray, s: State) -> tuple[float, float, float]:
    """(joint 2, joint 3, shaft input): the rotor's torque error, referred to the shaft input."""
    extra_rotor = s[S_TAU_ROTOR] * (torque_factor(s[S_OWN], blk) - 1.0)
    return 0.0, 0.0, extra_rotor / s[S_COEF_M]


def state_rate(blk: FloatArray, s: State, i: int) -> float:
    """d(dT)/dt = (P - dT / R_th) / C_th."""
    dtemp = s[S_OWN]
    return (copper_loss_w(s[S_TAU_ROTOR], dtemp, blk) - dtemp / blk[1]) / blk[2]
