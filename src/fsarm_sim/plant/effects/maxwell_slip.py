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


# --- the shaft's elements: side- and bend-dependent slip (seed 000: "the positive side has more
# internal friction", "hysteresis increases with the bending angle") ---------------------------
# Element i keeps its spring k_i (the shaft's small-signal stiffness, eq. 3 + sum k_i, still
# falls with the bend as seed 000 measured) while the friction that holds it grows with the bend
# like a rope on a capstan: its deflection band is
#     -r_n g(phi_B) f_i/k_i <= z_i <= g(phi_B) f_i/k_i
# (g: fsarm_sim.plant.effects.bend_friction; r_n < 1: the unwinding side slips earlier). Inside the band
# z_i follows the twist exactly (no drift however long the run); at an edge it slides; if the band
# shrinks under it (the bend falls) it slips back to the new edge within SLIP_RELAX_S - a slip,
# which dissipates. The stored energy k_i z_i^2 / 2 does not depend on the bend.

SLIP_RELAX_S = 1e-3  # how fast an element left outside its shrunk band slips back to its edge (s)


def band_rad(k: float, f: float, unwinding_ratio: float, bend_factor: float) -> tuple[float, float]:
    """(lower, upper) edge of element deflection at this bend; a tiny band when it is off."""
    if k <= 0.0:
        return (-1e-12, 1e-12)
    hi = bend_factor * f / k
    return (-unwinding_ratio * hi, hi)


def banded_rate(z: float, twist_rate: float, lower: float, upper: float) -> float:
    """dz/dt of an element in its band: stick inside, slide at an edge, slip back from outside."""
    if z >= upper:
        return min(twist_rate, 0.0) - (z - upper) / SLIP_RELAX_S
    if z <= lower:
        return max(twist_rate, 0.0) - (z - lower) / SLIP_RELAX_S
    return twist_rate
