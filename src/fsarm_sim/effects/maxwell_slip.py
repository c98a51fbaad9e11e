"""Rate-independent series hysteresis of the shaft: Maxwell-slip elements (seed 000 Sec. V).

Each element is a spring k_i whose deflection z_i follows the twist until its torque reaches the
slip torque f_i; then it slides. With z_i a continuous state (``data.act``) whose rate equals the
twist rate and whose range MuJoCo clamps to +-f_i/k_i (``actrange``), this is exact elasto-slip:

    dz_i/dt = d(twist)/dt,   |z_i| <= f_i / k_i,    tau_i = k_i z_i.

The loops it makes are independent of rate and always enclose positive area (slip dissipates).
"""

from __future__ import annotations


def element_torque_nm(z_rad: float, k_element: float) -> float:
    """Torque of one element (adds to the shaft torque)."""
    return k_element * z_rad


def element_rate(twist_rate: float) -> float:
    """dz/dt before clamping: the element sticks to the twist."""
    return twist_rate


def slip_limit_rad(k_element: float, slip_torque_nm: float) -> float:
    """Largest element deflection; 0 for a disabled element (k = 0)."""
    return slip_torque_nm / k_element if k_element > 0.0 else 0.0


def element_potential_j(z_rad: float, k_element: float) -> float:
    """Energy stored in one element spring."""
    return 0.5 * k_element * z_rad * z_rad


# --- normalized elements with a slip torque that depends on the twist side and the bend ---------
# The shaft's elements (seed 000: "the positive side has more internal friction", "hysteresis
# increases with the bending angle"): element i has pre-sliding stiffness k_i and slip torque
#     f_i(phi_B, side) = f_i0 * (1 on the winding side, r_n < 1 unwinding) * g(phi_B),
# g the route's bend-friction factor (fsarm_sim.effects.bend_friction). Its state is the
# normalized deflection w_i = k_i z_i / f_i in [-1, 1] (a fixed actrange, so MuJoCo's clamp is
# the exact slip however f_i changes):
#     tau_i = f_i w_i,   dw_i/dt = (k_i / f_i) d(twist)/dt,   V_i = f_i^2 w_i^2 / (2 k_i).
# At fixed bend this is the elasto-slip element above; a stuck element's torque scales with its
# slip torque when the bend changes, and V_i's bend dependence gives the -dV/dphi_B reaction on
# joint 2 (energy-consistent, tests/test_energy_check.py).


def side_slip_torque_nm(
    f0_nm: float, w: float, unwinding_ratio: float, bend_factor: float
) -> float:
    """f_i(phi_B, side): the slip torque on the side of the element's deflection."""
    return f0_nm * bend_factor * (1.0 if w >= 0.0 else unwinding_ratio)


def normalized_torque_nm(w: float, f_nm: float) -> float:
    return f_nm * w


def normalized_rate(twist_rate: float, k_element: float, f_nm: float) -> float:
    """dw/dt before MuJoCo's clamp to [-1, 1]: the element sticks to the twist."""
    return twist_rate * k_element / f_nm if f_nm > 0.0 else 0.0


def normalized_potential_j(w: float, k_element: float, f_nm: float) -> float:
    return 0.5 * f_nm * f_nm * w * w / k_element if k_element > 0.0 else 0.0


def normalized_bend_torque_nm(w: float, k_element: float, f_nm: float, df_dbend: float) -> float:
    """-dV_i/dphi_B at fixed w (f's dependence on the bend)."""
    return -f_nm * df_dbend * w * w / k_element if k_element > 0.0 else 0.0
