"""Parallel elasticity of the bent shaft at joint 2 (seed 000 eq. 2, 4, Fig. 9).

The bent shaft pushes the arm back toward upright (phi_B = 0), i.e. it helps lift the gravity load
("imperfect gravity compensation", about 8 N*m for the 9 mm x 450 mm prototype). Fig. 9 is nearly
linear and stiffens at large bends:

    M(phi) = K_b (phi + beta phi^3),   K_b from eq. 4,   restoring torque on joint 2 = -M.
"""

from __future__ import annotations

from fsarm_sim.paramblocks import Decl

# the parameters this law takes in the kernels (layout allocates their slots)
KERNEL_PARAMS = (
    Decl(
        "kb", "N*m/rad", 0.0, "eq. 2/4 bending stiffness K_b of the shaft (catalogue, per D and L)"
    ),
    Decl("beta", "1/rad^2", 0.0, "eq. 2 cubic hardening beta of the bending moment (catalogue)"),
)


def eq4_stiffness_nm_per_rad(q: tuple[float, ...], diameter_mm: float, length_mm: float) -> float:
    """Seed 000 eq. 4: K_b(D, L) = q0 + q1 D + q2 L + q3 D^2 + q4 D L."""
    d, ell = diameter_mm, length_mm
    return q[0] + q[1] * d + q[2] * ell + q[3] * d * d + q[4] * d * ell


def linear_fit_gain(beta: float, amplitude_rad: float) -> float:
    """Slope of eq. 2's linear fit ``M = K phi`` through a sinusoidal bend of ``amplitude_rad``,
    over K_b: least squares of ``K_b (phi + beta phi^3)`` on ``phi = A sin(wt)`` over whole cycles
    gives ``K_b (1 + beta A^2 <sin^4>/<sin^2>) = K_b (1 + 3/4 beta A^2)``."""
    return 1.0 + 0.75 * beta * amplitude_rad * amplitude_rad


def elastic_moment_nm(bend_rad: float, kb: float, beta: float) -> float:
    """Bending moment M(phi) = K_b (phi + beta phi^3), positive for positive bend."""
    # float exponent: CPython computes x**3 as pow(x, 3.0) anyway; written so, Numba also calls
    # pow() (x**3 would be x*x*x there), keeping the native path bit-identical to this one.
    return kb * (bend_rad + beta * bend_rad**3.0)


def potential_j(bend_rad: float, kb: float, beta: float) -> float:
    """Energy of the elastic bending moment: K_b (phi^2/2 + beta phi^4/4)."""
    return kb * (0.5 * bend_rad**2 + 0.25 * beta * bend_rad**4)
