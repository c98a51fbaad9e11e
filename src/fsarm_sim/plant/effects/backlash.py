"""Backlash: free play of total width ``w`` in a coupling (dead band, no torque inside it).

Where it is on a bench: the square-drive end fitting that couples a flexible shaft's core to the
encoder shaft / gearhead (series bench), or the joint coupling between the torque sensor and the
bending link (parallel bench). The coupling's driven half is light (its inertia is negligible
against the elastic torque), so it always rests against one flank while torque is transmitted and
jumps across the gap as soon as the torque changes sign. The deflection the elastic element sees
is then the measured deflection minus the play:

    x_eff = x - c - w/2   (x - c >  w/2)
    x_eff = 0             (|x - c| <= w/2)      no torque across the gap
    x_eff = x - c + w/2   (x - c < -w/2)

``c`` is where the gap's middle sits on the measured deflection axis (the encoders are zeroed
wherever the coupling happened to rest). Seed 004 eq. 14-19 describe the same direction-dependent
dead band for a tendon-sheath transmission.

On the arm it is a registry law acting on the twist (:mod:`.base`, hook ``transmitted_twist``):
the play sits between the shaft and joint 3's transmission law, so every transmission's law sees
the twist through it. A zero width is no play (the centre then means nothing).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl

FloatArray = npt.NDArray[np.float64]

# the parameters this law takes in the kernels (layout allocates their slots); 0 width: no play
KERNEL_PARAMS = (
    Decl("width_rad", "rad", 0.0, "total play w on the transmission twist"),
    Decl("center_rad", "rad", 0.0, "middle c of the dead band"),
)
STATES: tuple[Decl, ...] = ()
SIZE = "width_rad"  # at 0 the law acts as nothing (a model with it at 0 is the same run)
# the keys of this law in the effects entry of older run records (records.sidecar)
LEGACY_FIELDS = (("backlash_width_rad", "width_rad"), ("backlash_center_rad", "center_rad"))


def transmitted_deflection_rad(x_rad: float, width_rad: float, center_rad: float) -> float:
    """Deflection reaching the elastic element through the play (the dead-zone law above)."""
    u = x_rad - center_rad
    half = 0.5 * width_rad
    if u > half:
        return u - half
    if u < -half:
        return u + half
    return 0.0


def transmitted_rate(x_rad: float, rate: float, width_rad: float, center_rad: float) -> float:
    """Rate of the transmitted deflection: the input rate in contact, 0 inside the gap."""
    u = x_rad - center_rad
    half = 0.5 * width_rad
    return rate if (u > half or u < -half) else 0.0


def in_contact(x_rad: float, width_rad: float, center_rad: float) -> bool:
    """True while one flank of the coupling touches the other (torque can be transmitted)."""
    return abs(x_rad - center_rad) > 0.5 * width_rad


def transmitted_twist(blk: FloatArray, x: float, rate: float) -> tuple[float, float]:
    """(twist, rate) reaching joint 3's transmission law through the play (the arm's hook;
    unchanged for a zero width)."""
    w = blk[0]
    if w > 0.0:
        c = blk[1]
        return transmitted_deflection_rad(x, w, c), transmitted_rate(x, rate, w, c)
    return x, rate


def twist_for_transmitted(blk: FloatArray, x: float) -> float:
    """The shaft twist at which the law sees the twist ``x`` with the play taken up on the loaded
    flank (a static start: the flank the load presses on; the centre for ``x`` = 0)."""
    w = blk[0]
    if w > 0.0:
        return x + (blk[1] + (0.5 * w if x > 0.0 else -0.5 * w if x < 0.0 else 0.0))
    return x
