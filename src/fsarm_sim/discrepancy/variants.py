"""Each setup's variants of the registry's effects: where an effect acts in that setup, with the
registry's parameters and bounds (:mod:`fsarm_sim.plant.effects.registry`).

The benches use the registry's variants as they are. The arm's are the registry's laws with their
``ARM`` variants (payload error, Coulomb friction and viscous damping at joint 3, a dead band on
the shaft twist, and every other arm law), the shaft's own Maxwell-slip elements, and - on the
recording, not the plant - a bias or a lag of one recorded channel (the ``input`` variants' laws
on ``q3``, ``theta_m`` or ``q2``). One table for the arm's candidates,
its model file and the effect text of ``fsarm synth --setup arm``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.effects.registry import Variant

ARM_CHANNELS = ("q3", "theta_m", "q2")  # the arm's recorded channels the replay compares


def _on_arm(effect: str, law: str, key: str, enters: str) -> Variant:
    """The registry's variant ``effect[law]`` (parameters, bounds) acting on the arm as ``key``."""
    base = registry.get(effect).variant(law)
    return dataclasses.replace(base, key=key, setups=(registry.ARM,), enters=enters)


PAYLOAD = registry.get("payload_error").name
COULOMB = registry.get("coulomb_friction").name
VISCOUS = registry.get("viscous_damping").name
BACKLASH = registry.get("backlash").name
HYSTERESIS = registry.get("hysteresis").name
OFFSET = registry.get("sensor_offset").name
DELAY = registry.get("delay").name
NONLINEAR = registry.get("nonlinear_stiffness").name

ARM: dict[str, tuple[Variant, ...]] = {  # effect -> its arm variants (candidate order)
    PAYLOAD: (registry.get(PAYLOAD).variant("mass"),),
    COULOMB: (registry.get(COULOMB).variant("q3"),),
    VISCOUS: (registry.get(VISCOUS).variant("q3"),),
    BACKLASH: (registry.get(BACKLASH).variant("twist"),),
    HYSTERESIS: (
        _on_arm(HYSTERESIS, "maxwell_slip", "maxwell_slip", "the shaft's elasto-slip elements"),
    ),
    OFFSET: tuple(
        _on_arm(OFFSET, "input", ch, f"constant bias on the recorded {ch}") for ch in ARM_CHANNELS
    ),
    DELAY: tuple(
        _on_arm(DELAY, "input", ch, f"the recorded {ch} lags the others") for ch in ARM_CHANNELS
    ),
}
# the registry's arm effect laws (Effect.law) act on the arm as the registry states them
ARM_LAWS = tuple(e.name for e in registry.arm_laws() if e.name not in ARM)
for _law in ARM_LAWS:
    ARM[_law] = tuple(v for v in registry.get(_law).variants if registry.ARM in v.setups)
ARM_RECORDING = frozenset({OFFSET, DELAY})  # the arm's effects on the recording, not the plant
# the arm's plant effects that are registry laws (Effects.laws of a model), in table order
ARM_PLANT_LAWS = tuple(name for name in ARM if registry.get(name).law is not None)
ARM_MAX_ELEMENTS = 3  # hysteresis elements on the arm (ShaftParams' slots)
ARM_DEFAULTS = {(BACKLASH, "center_rad"): 0.0}  # (effect, parameter): value when not given


def of(setup: str) -> Mapping[str, tuple[Variant, ...]]:
    """Effect name -> the variants a setup knows (default first). The benches': all the
    registry's (whether each acts in the setup is the variant's ``setups``)."""
    if setup == registry.ARM:
        return ARM
    return {e.name: e.variants for e in registry.EFFECTS}


def pairs(setup: str) -> list[tuple[str, str]]:
    """(effect, variant key) of every variant a setup knows, in table order."""
    return [(name, v.key) for name, vs in of(setup).items() for v in vs]
