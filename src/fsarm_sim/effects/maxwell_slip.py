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
