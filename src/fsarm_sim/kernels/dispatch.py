"""Kernel dispatch, generated from the registries: no hand-written branch per module.

The kernels must call "the transmission whose id is in the parameter vector" and "every arm effect
law that is switched on" without Python objects (Numba compiles them as C callbacks). Each
dispatcher here is plain Python *source* generated at import from
:data:`fsarm_sim.plant.transmissions.MODULES` (a transmission's id is its place there) and from the
effect registry's laws (:func:`fsarm_sim.plant.effects.registry.arm_laws`, parameter blocks from
:data:`fsarm_sim.kernels.layout.ARM_LAW_BLOCKS`), compiled with ``exec`` into this module. The
result is the if-chain one would write by hand, with the ids and slot offsets as literals, so the
Python callbacks run it as is and Numba compiles it like any other kernel (``engine.native``
registers this module's functions). :data:`SOURCE` keeps the generated text for reading and tests.

Adding a transmission or an arm effect therefore never touches this file or ``physics``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.kernels.layout import ARM_LAW_BLOCKS, LawBlock
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.effects.base import TORQUES, TWIST, State, hooks

FloatArray = npt.NDArray[np.float64]

SOURCE: dict[str, str] = {}  # generated function name -> its source

_TR_MODULES = list(transmissions.MODULES.values())
_LAWS = {e.name: e.law for e in registry.arm_laws()}
# the law blocks of each hook (plant.effects.base), registry order: a law is dispatched only where
# it acts (a model-write law never reaches the kernels)
TORQUE_BLOCKS = tuple(b for b in ARM_LAW_BLOCKS if TORQUES in hooks(_LAWS[b.name]))
TWIST_BLOCKS = tuple(b for b in ARM_LAW_BLOCKS if TWIST in hooks(_LAWS[b.name]))


def _compile(name: str, src: str, env: dict[str, Any]) -> Callable[..., Any]:
    """exec ``src`` (defining ``name``) in a namespace of its own holding ``env`` (the modules it
    calls); the function reports this module as its own, so ``engine.native`` compiles it."""
    namespace: dict[str, Any] = {"__name__": __name__, **env}
    exec(compile(src, f"<generated {__name__}.{name}>", "exec"), namespace)
    SOURCE[name] = src
    fn: Callable[..., Any] = namespace[name]
    return fn


def _transmission_dispatch(
    name: str, args: str, method: str, call_args: str, fallback: str | None = None
) -> Callable[..., Any]:
    """``name(kind, <args>)``: the transmission module with id ``int(kind)``'s ``method``
    (its ``fallback`` method when it has no ``method`` and a fallback is given).

    The last registered module is the fallback branch (one return type for Numba); tests check
    that every id reaches its own module.
    """
    lines = [f"def {name}(kind, {args}):", "    k = int(kind)"]
    env = {}
    for i, mod in enumerate(_TR_MODULES):
        env[f"_tr{i}"] = mod
        own = method if fallback is None or hasattr(mod, method) else fallback
        call = f"return _tr{i}.{own}({call_args})"
        if i < len(_TR_MODULES) - 1:
            lines += [f"    if k == {i}:", f"        {call}"]
        else:
            lines.append(f"    {call}")
    return _compile(name, "\n".join(lines) + "\n", env)


def _output_dispatch() -> Callable[..., Any]:
    """``tr_output_torque(kind, tr, theta_s, theta_s_dot)``: the output-side torque of the
    transmissions that have one (``output_side_torque_nm``), else 0."""
    lines = ["def tr_output_torque(kind, tr, theta_s, theta_s_dot):", "    k = int(kind)"]
    env = {}
    for i, mod in enumerate(_TR_MODULES):
        if hasattr(mod, "output_side_torque_nm"):
            env[f"_tr{i}"] = mod
            lines += [
                f"    if k == {i}:",
                f"        return _tr{i}.output_side_torque_nm(tr, theta_s, theta_s_dot)",
            ]
    lines.append("    return 0.0")
    return _compile("tr_output_torque", "\n".join(lines) + "\n", env)


def _has_dispatch(name: str, method: str) -> Callable[..., Any]:
    """``name(kind)``: True when the transmission with id ``int(kind)`` has ``method``."""
    ids = [i for i, mod in enumerate(_TR_MODULES) if hasattr(mod, method)]
    lines = [f"def {name}(kind):", "    k = int(kind)"]
    lines += [f"    if k == {i}:\n        return True" for i in ids]
    lines.append("    return False")
    return _compile(name, "\n".join(lines) + "\n", {})


def _own_state(block: LawBlock) -> str:
    """The named state a law is called with: the shared part ``s`` and its own states from
    ``act`` (a tuple expression; ``s`` itself for a law without any)."""
    if block.n_states == 0:
        return "s"
    own = ", ".join(f"act[a0 + {k}]" for k in range(block.n_states))
    return f"s + ({own},)"


def law_dispatch(blocks: tuple[LawBlock, ...], laws: dict[str, Any]) -> Callable[..., Any]:
    """``arm_law_torques(prm, act, s)``: the sum of the (joint 2, joint 3, shaft input) torques
    of every law in ``blocks`` whose on/off slot is on, each called with the named state ``s``
    (:mod:`fsarm_sim.plant.effects.base`) and its own states appended; ``laws`` maps an effect
    name to its module."""
    lines = ["def arm_law_torques(prm, act, s):", "    t2 = 0.0", "    t3 = 0.0", "    tm = 0.0"]
    env = {}
    for i, b in enumerate(blocks):
        env[f"_law{i}"] = laws[b.name]
        lines.append(f"    if prm[{b.on}] > 0.5:  # {b.name}")
        if b.n_states:
            lines.append(f"        a0 = int(prm[{b.act}])")
        lines += [
            f"        a, b, c = _law{i}.arm_torques(prm[{b.start}:{b.end}], {_own_state(b)})",
            "        t2 += a",
            "        t3 += b",
            "        tm += c",
        ]
    lines.append("    return t2, t3, tm")
    return _compile("arm_law_torques", "\n".join(lines) + "\n", env)


def law_twist_dispatch(blocks: tuple[LawBlock, ...], laws: dict[str, Any]) -> Callable[..., Any]:
    """``arm_law_twist(prm, x, rate)``: the (twist, rate) joint 3's transmission law sees, each
    law in ``blocks`` whose on/off slot is on applied in turn (its ``transmitted_twist``)."""
    lines = ["def arm_law_twist(prm, x, rate):"]
    env = {}
    for i, b in enumerate(blocks):
        env[f"_law{i}"] = laws[b.name]
        lines += [
            f"    if prm[{b.on}] > 0.5:  # {b.name}",
            f"        x, rate = _law{i}.transmitted_twist(prm[{b.start}:{b.end}], x, rate)",
        ]
    lines.append("    return x, rate")
    return _compile("arm_law_twist", "\n".join(lines) + "\n", env)


def law_any_dispatch(blocks: tuple[LawBlock, ...]) -> Callable[..., Any]:
    """``arm_laws_on(prm)``: True when any law in ``blocks`` (the torque laws) is on (the passive
    kernel builds the named state only then)."""
    test = " or ".join(f"prm[{b.on}] > 0.5" for b in blocks) or "False"
    return _compile("arm_laws_on", f"def arm_laws_on(prm):\n    return {test}\n", {})


def law_owner_dispatch(blocks: tuple[LawBlock, ...]) -> Callable[..., Any]:
    """``arm_law_owns(prm, adr)``: True when ``act[adr]`` is an own state of a law that is on
    (the state-rate kernel then asks :func:`law_rate_dispatch`'s function for its rate)."""
    lines = ["def arm_law_owns(prm, adr):"]
    for b in blocks:
        if b.n_states:
            lines += [
                f"    if prm[{b.on}] > 0.5:  # {b.name}",
                f"        a0 = int(prm[{b.act}])",
                f"        if a0 <= adr < a0 + {b.n_states}:",
                "            return True",
            ]
    lines.append("    return False")
    return _compile("arm_law_owns", "\n".join(lines) + "\n", {})


def law_rate_dispatch(blocks: tuple[LawBlock, ...], laws: dict[str, Any]) -> Callable[..., Any]:
    """``arm_law_state_rate(prm, act, s, adr)``: d(act[adr])/dt from the law that owns it
    (:func:`law_owner_dispatch`), called with the named state ``s`` and its own states; 0 for an
    address no law that is on owns."""
    lines = ["def arm_law_state_rate(prm, act, s, adr):"]
    env = {}
    for i, b in enumerate(blocks):
        if not b.n_states:
            continue
        env[f"_law{i}"] = laws[b.name]
        lines += [
            f"    if prm[{b.on}] > 0.5:  # {b.name}",
            f"        a0 = int(prm[{b.act}])",
            f"        if a0 <= adr < a0 + {b.n_states}:",
            f"            return _law{i}.state_rate(prm[{b.start}:{b.end}], {_own_state(b)}, "
            "adr - a0)",
        ]
    lines.append("    return 0.0")
    return _compile("arm_law_state_rate", "\n".join(lines) + "\n", env)


_TR7 = "tr, x, rate, bend, act, a0"
tr_torque: Callable[[float, FloatArray, float, float, float, FloatArray, int], float] = (
    _transmission_dispatch("tr_torque", _TR7, "torque_nm", _TR7)
)
tr_sensor_torque: Callable[[float, FloatArray, float, float], float] = _transmission_dispatch(
    "tr_sensor_torque", "tr, x, bend", "sensor_torque_nm", "tr, x, bend"
)
tr_stiffness: Callable[[float, FloatArray, float, float], float] = _transmission_dispatch(
    "tr_stiffness", "tr, x, bend", "stiffness_nm_per_rad", "tr, x, bend"
)
tr_motor_torque: Callable[[float, FloatArray, float, float, float, FloatArray, int], float] = (
    _transmission_dispatch("tr_motor_torque", _TR7, "motor_torque_nm", _TR7, "torque_nm")
)
# whether a transmission's motor end carries its own torque (else it is tr_torque's, and the
# kernels do not evaluate the law a second time)
tr_has_motor_torque: Callable[[float], bool] = _has_dispatch(
    "tr_has_motor_torque", "motor_torque_nm"
)
tr_state_rate: Callable[
    [float, FloatArray, float, float, float, FloatArray, int, int, float], float
] = _transmission_dispatch("tr_state_rate", _TR7 + ", i, vm", "state_rate", _TR7 + ", i, vm")
tr_potential: Callable[[float, FloatArray, float, float, FloatArray, int], float] = (
    _transmission_dispatch(
        "tr_potential", "tr, x, bend, act, a0", "potential_j", "tr, x, bend, act, a0"
    )
)
tr_bend_torque: Callable[[float, FloatArray, float, float, FloatArray, int], float] = (
    _transmission_dispatch(
        "tr_bend_torque", "tr, x, bend, act, a0", "bend_torque_nm", "tr, x, bend, act, a0"
    )
)
tr_output_torque: Callable[[float, FloatArray, float, float], float] = _output_dispatch()
arm_law_torques: Callable[[FloatArray, FloatArray, State], tuple[float, float, float]] = (
    law_dispatch(TORQUE_BLOCKS, _LAWS)
)
arm_laws_on: Callable[[FloatArray], bool] = law_any_dispatch(TORQUE_BLOCKS)
arm_law_twist: Callable[[FloatArray, float, float], tuple[float, float]] = law_twist_dispatch(
    TWIST_BLOCKS, _LAWS
)
arm_law_owns: Callable[[FloatArray, int], bool] = law_owner_dispatch(ARM_LAW_BLOCKS)
arm_law_state_rate: Callable[[FloatArray, FloatArray, State, int], float] = law_rate_dispatch(
    ARM_LAW_BLOCKS, _LAWS
)
