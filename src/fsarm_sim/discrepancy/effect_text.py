"""The effect text of ``fsarm synth --effect``, one parser for every setup: ``NAME[:VARIANT]=v1[,v2...]``
read against the effect registry (:mod:`fsarm_sim.plant.effects.registry`) through the setup's table
of variants (:mod:`.variants`).

* NAME is a registry effect; VARIANT one of the setup's variants of it (default: the first; the
  arm's recording effects ``sensor_offset`` and ``delay`` need theirs, the recorded channel).
* The values are the variant's registry parameters in order, each within the registry's bounds;
  a variant whose parameters come one per element (hysteresis) takes groups
  (``k1,d1,k2,d2,...``); a setup may give trailing parameters a default (the arm's backlash
  centre, 0).
* The benches' polynomial stiffness also stores its reference deflection (``x_ref``, the
  caller's: the input amplitude).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from fsarm_sim.discrepancy import variants
from fsarm_sim.discrepancy.benchmodel import EffectInstance, element_wise, uses_x_ref
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.effects.registry import Variant


@dataclass(frozen=True)
class Rules:
    """How a setup reads effect texts."""

    setup: str
    variants: Mapping[str, tuple[Variant, ...]]  # effect -> the setup's variants, default first
    max_elements: int | None = None  # element-wise parameters: at most this many groups
    defaults: Mapping[tuple[str, str], float] = field(default_factory=dict)  # (effect, param)
    needs_variant: frozenset[str] = frozenset()  # effects whose variant must be named


def rules(setup: str) -> Rules:
    """The effect-text rules of a setup."""
    if setup == registry.ARM:
        return Rules(
            setup,
            variants.of(setup),
            max_elements=variants.ARM_MAX_ELEMENTS,
            defaults=variants.ARM_DEFAULTS,
            needs_variant=variants.ARM_RECORDING,
        )
    return Rules(setup, variants.of(setup))


def split_effect_text(text: str, what: str = "effect") -> tuple[str, str, list[float]]:
    """``NAME[:VARIANT]=v1[,v2...]`` -> (name, variant or "", numbers); named errors."""
    if "=" not in text:
        raise InvalidParameterError(f"{what} {text!r}: expected NAME[:VARIANT]=VALUES")
    head, vals = text.split("=", 1)
    name, _, variant = (part.strip() for part in head.partition(":"))
    try:
        nums = [float(v) for v in vals.split(",") if v.strip()]
    except ValueError:
        raise InvalidParameterError(f"{what} {text!r}: values must be numbers") from None
    return name, variant, nums


def _variant(text: str, name: str, key: str, r: Rules) -> Variant:
    try:
        eff = registry.get(name)
    except KeyError as exc:
        raise InvalidParameterError(str(exc.args[0])) from None
    known = r.variants.get(eff.name, ())
    keys = [v.key for v in known]
    if not known:
        raise InvalidParameterError(
            f"effect {text!r} not understood: {eff.name} does not act in setup {r.setup!r}; "
            f"its effects: {', '.join(r.variants)}"
        )
    if not key:
        if eff.name in r.needs_variant:
            raise InvalidParameterError(
                f"effect {text!r} not understood: {eff.name} in setup {r.setup!r} needs its variant "
                f"({eff.name}:VARIANT=...), one of {', '.join(keys)}"
            )
        return known[0]
    for v in known:
        if v.key == key:
            return v
    raise InvalidParameterError(f"effect {eff.name!r} has no variant {key!r}; known: {keys}")


def _values(text: str, name: str, var: Variant, nums: list[float], r: Rules) -> dict[str, Any]:
    label = f"{name}[{var.key}]"
    names = [p.name for p in var.params]
    if element_wise(var):
        n = len(names)
        top = r.max_elements
        if not nums or len(nums) % n or (top is not None and len(nums) > n * top):
            most = f"1 to {top}" if top is not None else "one or more"
            raise InvalidParameterError(
                f"effect {text!r} not understood: {label} takes {most} groups of "
                f"({', '.join(names)})"
            )
        return {p: nums[i::n] for i, p in enumerate(names)}
    need = len(names)
    while need > 0 and (name, names[need - 1]) in r.defaults:
        need -= 1
    if not need <= len(nums) <= len(names):
        count = f"{need}-{len(names)}" if need < len(names) else f"{len(names)}"
        raise InvalidParameterError(
            f"effect {text!r} not understood: {label} takes {count} value(s): {', '.join(names)}"
        )
    vals = {p: (nums[i] if i < len(nums) else r.defaults[(name, p)]) for i, p in enumerate(names)}
    return vals


def parse_effect(text: str, setup: str, x_ref: float | None = None) -> EffectInstance:
    """``NAME[:VARIANT]=v1[,v2...]`` -> the effect of a setup with its registry parameters in
    order (module docstring). ``x_ref``: the reference deflection a bench's polynomial stiffness
    stores (required for it)."""
    r = rules(setup)
    name, key, nums = split_effect_text(text)
    var = _variant(text, name, key, r)
    name = registry.get(name).name
    if setup not in var.setups:
        raise InvalidParameterError(f"{name}[{var.key}] does not act in a {setup}")
    params: dict[str, Any] = _values(text, name, var, nums, r)
    for p in var.params:
        vv = params[p.name]
        for v in vv if isinstance(vv, list) else [vv]:
            if not p.lower <= v <= p.upper:
                raise InvalidParameterError(
                    f"{name}[{var.key}].{p.name} = {v:g} outside [{p.lower:g}, {p.upper:g}] "
                    f"{p.unit}"
                )
    if uses_x_ref(name, var.key):
        if x_ref is None:
            raise InvalidParameterError(f"{name}[{var.key}] needs a reference deflection x_ref")
        params["x_ref_rad"] = x_ref
    return EffectInstance(name, var.key, params)
