"""The interface of an effect law that acts on the arm's plant through the kernels.

A law module that acts on the simulated arm (not only on a bench's Python model) declares its
kernel parameters and one function of the arm's state; the kernels call it from the passive
callback through a dispatcher generated from the effect registry
(:mod:`fsarm_sim.kernels.dispatch`), so adding such an effect is: its law module, its
``Effect(..., law=module)`` line in :mod:`fsarm_sim.plant.effects.registry`, and its test file.

The arguments are the arm's state as the shaft sees it (all SI): joint 2 (the bend joint) and
joint 3 angles and rates, the shaft input's speed ``omega_m`` (= rotor speed / i_G1), the
shaft twist and its rate, and the bend angle phi_B. The result is three generalized forces: on
joint 2, on joint 3, and on the shaft input theta_m (the kernel applies it to the rotor times
1/i_G1). A law acts on the plant only; the controllers do not know it.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl

FloatArray = npt.NDArray[np.float64]


class ArmEffectLaw(Protocol):
    """What an arm-acting effect module provides; mypy checks every ``Effect.law`` against it."""

    @property
    def KERNEL_PARAMS(self) -> tuple[Decl, ...]:
        """Its parameter block (the layout prepends an on/off slot)."""
        ...

    def arm_torques(
        self,
        blk: FloatArray,
        q2: float,
        q3: float,
        qd2: float,
        qd3: float,
        omega_m: float,
        twist: float,
        twist_rate: float,
        bend: float,
    ) -> tuple[float, float, float]: ...
