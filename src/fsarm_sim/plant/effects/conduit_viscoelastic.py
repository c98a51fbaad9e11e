"""Rate-dependent hysteresis of the rubber conduit at joint 2 (seed 000 Fig. 9, Sec. V).

Generalized-Maxwell (Prony) branches in parallel with the elastic bending moment: a spring k_i in
series with a dashpot whose internal deflection z_i is a continuous state (``data.act``):

    M_i = k_i (phi - z_i),        dz_i/dt = (phi - z_i) / tau_i.

Each branch stores 0.5 k_i (phi - z_i)^2 and dissipates k_i (phi - z_i)^2 / tau_i >= 0, so the
loop area is positive and depends on the bending rate (it vanishes for slow or static bends).
"""

from __future__ import annotations

import math

from fsarm_sim.paramblocks import Decl

# the parameters this law takes in the kernels (layout allocates their slots)
KERNEL_PARAMS = (
    Decl("k1", "N*m/rad", 0.0, "branch 1 stiffness (catalogue conduit.k_fraction x K_b)"),
    Decl("tau1", "s", 0.0, "branch 1 relaxation time (catalogue conduit.tau_s)"),
    Decl("k2", "N*m/rad", 0.0, "branch 2 stiffness (catalogue conduit.k_fraction x K_b)"),
    Decl("tau2", "s", 0.0, "branch 2 relaxation time (catalogue conduit.tau_s)"),
)


def storage_fraction(tau_s: float, period_s: float) -> float:
    """In-phase (storage) stiffness of a branch in a sinusoidal bend of ``period_s``, over its k_i:
    ``(w tau)^2 / (1 + (w tau)^2)``, w = 2 pi / period. It is what the branch adds to the slope of
    a linear fit ``M = K phi`` over whole cycles (the out-of-phase part makes the loop)."""
    wt = 2.0 * math.pi * tau_s / period_s
    return wt * wt / (1.0 + wt * wt)


def branch_moment_nm(bend_rad: float, z_rad: float, k_branch: float) -> float:
    """Moment carried by one branch (positive resists positive bend)."""
    return k_branch * (bend_rad - z_rad)


def branch_rate(bend_rad: float, z_rad: float, tau_s: float) -> float:
    """dz/dt of one branch."""
    return (bend_rad - z_rad) / tau_s


def branch_potential_j(bend_rad: float, z_rad: float, k_branch: float) -> float:
    """Energy stored in one branch spring."""
    return 0.5 * k_branch * (bend_rad - z_rad) ** 2


def branch_dissipation_w(bend_rad: float, z_rad: float, k_branch: float, tau_s: float) -> float:
    """Power dissipated in one branch dashpot (never negative)."""
    return k_branch * (bend_rad - z_rad) ** 2 / tau_s
