"""The interface of an effect law that acts on the arm's plant.

A law module that acts on the simulated arm (not only on a bench's Python model) declares its
kernel parameters (``KERNEL_PARAMS``), its own states (``STATES``, possibly none) and acts
through one or more of three hooks, whichever states its physics (:func:`hooks`):

* ``arm_torques(blk, s)`` (and ``state_rate(blk, s, i)`` for its own states): generalized forces
  the kernels add in the passive callback, read from one *named state* ``s``; the kernels call
  them through a dispatcher generated from the effect registry (:mod:`fsarm_sim.kernels.dispatch`);
* ``transmitted_twist(blk, x, rate)`` and its inverse ``twist_for_transmitted(blk, x)``: the law
  sits in the coupling ahead of joint 3's transmission and changes the twist (and its rate) the
  transmission's law sees (:mod:`.backlash`); the kernels apply every such law that is on, in
  registry order, wherever they read the transmitted twist;
* ``MODEL_WRITES``: numbers MuJoCo applies itself, each a :class:`ModelWrite` that adds one of the
  law's parameters to a per-dof field of the compiled model at build (joint 3's Coulomb friction
  as ``dof_frictionloss``: the constraint solver's dry friction, exact stick; its extra viscous
  damping as ``dof_damping``: integrated implicitly by MuJoCo).

A law whose effect vanishes when one parameter is 0 names it ``SIZE`` (the payload's mass error,
the play's width, the friction level, the damping): a law at size 0 is left off (:func:`is_off`),
so a model with it at 0 is the same run as one without it.

How to add an arm effect (three files): its law module in this package, its
``Effect(..., law=module)`` entry in :mod:`fsarm_sim.plant.effects.registry` (with an ``ARM``
variant whose parameters are the ones the diagnosis fits and ``fsarm run --effect`` / ``fsarm
synth --effect`` take by position), and its test file. Nothing else changes: the layout gives it
a parameter block and, while it is switched on, one ``data.act`` slot per declared state; the
recorder writes those states as columns ``<effect>.<state>``.

The named state ``s`` is one flat tuple of floats (all SI), read by index: ``s[S_OMEGA_M]`` is
the shaft input's speed. Indices are module constants (Numba freezes them into the compiled
kernels), so a law reads what it needs and a new quantity is a new index here - never a change
of another law's signature. A law's own states follow the shared ones: ``s[S_OWN + i]`` is its
``STATES[i]``. Every law sees the arm as the shaft does: joint 2 is the bend joint (phi_B = q2 on
the arm), joint 3 the driven joint, theta_m the shaft input (rotor angle / i_G1).

The torques a law returns are generalized forces on joint 2, on joint 3 and on the shaft input
theta_m (the kernel applies the last to the rotor times 1/i_G1). A law acts on the plant only;
the controllers do not know it. Its state rates are what MuJoCo integrates (``mjcb_act_dyn``,
explicit in time): a stiff law returns the rate that makes one step of length ``s[S_TIMESTEP]``
land where the exact solution at frozen inputs does (see :mod:`.lugre_friction`). States start
at their ``Decl.default``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from fsarm_sim.paramblocks import Decl

FloatArray = npt.NDArray[np.float64]
State = tuple[float, ...]

# the shared part of the named state, in order: (name, unit, meaning)
STATE: tuple[tuple[str, str, str], ...] = (
    ("q2", "rad", "joint 2 angle (the bend joint; 0 where there is none)"),
    ("q3", "rad", "joint 3 angle"),
    ("qd2", "rad/s", "joint 2 rate"),
    ("qd3", "rad/s", "joint 3 rate"),
    ("theta_m", "rad", "shaft input angle: rotor angle / i_G1"),
    ("omega_m", "rad/s", "shaft input speed: rotor speed / i_G1"),
    ("twist", "rad", "shaft twist theta_m - theta_s (before any backlash)"),
    ("twist_rate", "rad/s", "its rate"),
    ("bend", "rad", "bend angle phi_B (q2 on the arm, the held bend on a bench)"),
    ("tau_rotor", "N*m", "joint 3 motor's torque command at the rotor (the held output)"),
    ("coef_m", "-", "shaft input angle per rotor angle, 1 / i_G1 (joint 3 motor gearbox)"),
    ("timestep", "s", "the physics timestep h (for laws that integrate stiff states)"),
)
_INDEX = {name: i for i, (name, _, _) in enumerate(STATE)}
S_Q2 = _INDEX["q2"]
S_Q3 = _INDEX["q3"]
S_QD2 = _INDEX["qd2"]
S_QD3 = _INDEX["qd3"]
S_THETA_M = _INDEX["theta_m"]
S_OMEGA_M = _INDEX["omega_m"]
S_TWIST = _INDEX["twist"]
S_TWIST_RATE = _INDEX["twist_rate"]
S_BEND = _INDEX["bend"]
S_TAU_ROTOR = _INDEX["tau_rotor"]
S_COEF_M = _INDEX["coef_m"]
S_TIMESTEP = _INDEX["timestep"]
S_OWN = len(STATE)  # a law's own states: s[S_OWN + i] is its STATES[i]
del _INDEX


@dataclass(frozen=True)
class ModelWrite:
    """``model.<field>[dof of <joint>] += <the law's parameter param>`` at build, while the law
    is on (a per-dof field of ``mujoco.MjModel``: ``dof_frictionloss``, ``dof_damping``)."""

    field: str
    joint: str
    param: str


class ArmEffectLaw(Protocol):
    """What an arm-acting effect module provides; mypy checks every ``Effect.law`` against it.
    It acts through the hooks :func:`hooks` finds (the module docstring)."""

    @property
    def KERNEL_PARAMS(self) -> tuple[Decl, ...]:
        """Its parameter block (the layout prepends an on/off slot and a state-address slot)."""
        ...

    @property
    def STATES(self) -> tuple[Decl, ...]:
        """Its own states (name, unit, initial value, meaning); () for a law without any."""
        ...


TORQUES = "torques"  # arm_torques (+ state_rate): generalized forces from the kernels
TWIST = "twist"  # transmitted_twist / twist_for_transmitted: the coupling ahead of joint 3's law
MODEL = "model"  # MODEL_WRITES: numbers MuJoCo applies itself
_HOOKS = {
    TORQUES: ("arm_torques", "state_rate"),
    TWIST: ("transmitted_twist", "twist_for_transmitted"),
    MODEL: ("MODEL_WRITES",),
}


def hooks(law: Any) -> frozenset[str]:
    """The ways ``law`` acts on the plant (:data:`TORQUES`, :data:`TWIST`, :data:`MODEL`): each
    hook whose members the module defines."""
    return frozenset(h for h, names in _HOOKS.items() if all(hasattr(law, n) for n in names))


def model_writes(law: Any) -> tuple[ModelWrite, ...]:
    """The law's :class:`ModelWrite` declarations (() for a law without any)."""
    writes: tuple[ModelWrite, ...] = getattr(law, "MODEL_WRITES", ())
    return writes


def is_off(law: Any, values: dict[str, float]) -> bool:
    """True when ``values`` (the law's parameters given; the others at their declared defaults)
    put the law's ``SIZE`` at 0: it acts as nothing (False for a law without a size)."""
    size: str | None = getattr(law, "SIZE", None)
    if size is None:
        return False
    default = {d.name: d.default for d in law.KERNEL_PARAMS}[size]
    return values.get(size, default) == 0.0
