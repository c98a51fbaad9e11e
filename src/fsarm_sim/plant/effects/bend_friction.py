"""Internal friction of a routed shaft that grows with the bend of its route (capstan-like).

A flexible shaft turning inside its conduit, bent around joint 2, presses its coils against each
other and against the conduit harder the more the route wraps: like a rope on a capstan (seed 004
eq. 7-8, ``T_out = T_in e^(mu Theta)`` along a bent sheath), the friction that must be overcome
grows exponentially with the wrap angle ``Theta``. Joint 2's bend adds ``|phi_B|`` to the route's
wrap, so a friction torque ``f_0`` measured straight becomes

    f(phi_B) = f_0 * exp(mu_b * |phi_B|).

This is seed 000's "hysteresis increases with the increase in bending angle ... torsion, bending,
and helical buckling" (Sec. III-B1) and seed 001's loss of torque bandwidth and transparency with
bend (Sec. 6.1-6.2), in one factor. ``mu_b`` is an estimate per shaft: the flexible shaft's from
its coefficient file (``series.maxwell_slip.bend_friction_per_rad``; 0 switches the growth off),
the RTCA's 1.16 /rad from seed 001 Sec. 3.3's model error, 0.32 % straight and 2.3 % at
R = 150 mm (``rtca.BEND_FRICTION_PER_RAD``; ``slip_f = 0`` switches its element off). Both
transmissions routed over joint 2 scale their Maxwell-slip elements' slip torques by it
(:mod:`fsarm_sim.plant.effects.maxwell_slip`).
"""

from __future__ import annotations

import math


def factor(bend_rad: float, mu_per_rad: float) -> float:
    """f(phi_B) / f_0 = exp(mu_b |phi_B|) (1 straight)."""
    return math.exp(mu_per_rad * abs(bend_rad))


def factor_slope(bend_rad: float, mu_per_rad: float) -> float:
    """d(factor)/d(phi_B) (0 at phi_B = 0, where the two sides' slopes cancel)."""
    if bend_rad == 0.0:
        return 0.0
    return mu_per_rad * math.copysign(1.0, bend_rad) * math.exp(mu_per_rad * abs(bend_rad))
