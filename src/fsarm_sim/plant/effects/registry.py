"""Registry of the effects the discrepancy workflow (and ``fsarm synth``) know: name -> module,
variants, parameters with bounds, and how each variant enters each setup.

Effect names are the shared vocabulary of ``specs/measured-data.md``. A *variant* says where the
effect acts; the workflow reports the effect name and, in its parameters, the variant. Bounds are
the search box of the fit and the range ``fsarm synth`` accepts; they are generous on purpose
(records made outside the project) and stated in SI units.

Sources of the bounds (estimates): torques up to the 20 N*m torque-sensor range of the benches
(seed 000 Sec. III-A, DBRK-20); deflections up to the validity range of the shaft (+-120 deg bend,
twist of a few tenths of a rad at rated torque); delays up to 0.1 s (a slow DAQ buffer); time
constants of visco-elastic branches 5 ms .. 20 s (Fig. 9's 0.1-1 Hz bending rates in the middle).
This module holds data and the ``--effect`` text parser only - no fitting code (that is
:mod:`fsarm_sim.discrepancy.candidates`).

How to add an effect that acts on the simulated arm (three files, nothing else changes):

1. its law module in this package (:mod:`.base` says what it declares: ``KERNEL_PARAMS``,
   ``STATES`` and one or more hooks - ``arm_torques(blk, s)`` / ``state_rate(blk, s, i)`` of the
   named state ``s``, ``transmitted_twist`` on the twist ahead of joint 3's transmission, or
   ``MODEL_WRITES`` that MuJoCo applies itself - optionally ``LIMITS``); :mod:`.lugre_friction`
   (torques with a state), :mod:`.shaft_drag` (torques without), :mod:`.backlash` (twist) and
   :mod:`.coulomb_friction` (a model write) are examples;
2. its ``Effect(..., law=module)`` entry below, with an ``ARM`` variant whose parameters are the
   ones the arm diagnosis fits (``fsarm diagnose``) and ``fsarm run --effect`` / ``fsarm synth
   --effect`` take by position;
3. its test file (``tests/test_effects_<module>.py``).

Every effect that acts on the simulated arm is such a law; ``Effects.laws`` (which are on, with
which values) is all a run states about them. The layout, the generated kernel dispatch, the
model's state slots and model writes, the recorded columns, ``SimConfig``, the sidecar,
``fsarm run --effect``, ``fsarm synth`` and the arm diagnosis read them from here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import (
    backlash,
    coulomb_friction,
    lugre_friction,
    motor_thermal,
    payload_error,
    shaft_drag,
    viscous_damping,
)
from fsarm_sim.plant.effects.base import ArmEffectLaw, is_off

SERIES = "series_bench"
PARALLEL = "parallel_bench"
ARM = "arm"


@dataclass(frozen=True)
class Param:
    name: str
    unit: str
    lower: float
    upper: float
    meaning: str
    typical: float = 0.0  # a typical magnitude (fit step scale); 0: 1 % of the bound range

    def scale(self) -> float:
        return self.typical if self.typical > 0.0 else 0.01 * (self.upper - self.lower)


@dataclass(frozen=True)
class Variant:
    key: str  # e.g. "shaft", "load"
    setups: tuple[str, ...]
    enters: str  # how it enters the setups' models
    params: tuple[Param, ...]
    needs_inertia_load: bool = False  # series bench: only when the output drives a load
    fittable: bool = True  # False: a synthetic-truth law only (fsarm synth), never a candidate


@dataclass(frozen=True)
class Effect:
    name: str
    module: str  # fsarm_sim.plant.effects.<module>
    meaning: str
    variants: tuple[Variant, ...] = field(default=())
    # the law that acts on the simulated arm through the kernels (its variant(s) list ARM in
    # their setups); the kernels' dispatch, the parameter layout, SimConfig's Effects.laws and the
    # arm diagnosis all read it from here
    law: ArmEffectLaw | None = None

    def variant(self, key: str) -> Variant:
        for v in self.variants:
            if v.key == key:
                return v
        raise KeyError(f"effect {self.name!r} has no variant {key!r}; known: {self.variant_keys()}")

    def variant_keys(self) -> list[str]:
        return [v.key for v in self.variants]


_F = Param("f_c_nm", "N*m", 0.0, 20.0, "friction torque magnitude")
_B = Param("b_nms", "N*m*s/rad", 0.0, 20.0, "damping coefficient")
_W = Param("width_rad", "rad", 0.0, 0.5, "total play")
_C = Param("center_rad", "rad", -0.25, 0.25, "middle of the gap")

EFFECTS: tuple[Effect, ...] = (
    Effect(
        "coulomb_friction",
        "coulomb_friction",
        "friction torque of constant magnitude opposing motion",
        (
            Variant(
                "shaft",
                (SERIES, PARALLEL),
                "in parallel with the shaft spring: +F sgn(rate of twist / bend) in the measured "
                "torque, as a stiff presliding element (shaft core in its casing, joint bearing "
                "ahead of the torque sensor)",
                (_F,),
            ),
            Variant(
                "load",
                (SERIES,),
                "on the load bearing: -F sgn(load speed), stick while |shaft torque| <= F",
                (_F,),
                needs_inertia_load=True,
            ),
            Variant(
                "q3",
                (ARM,),
                "at joint 3 (bearing, hypoid): F added to q3's dof_frictionloss, MuJoCo's dry "
                "friction (exact stick while the other torques stay below F)",
                (_F,),
            ),
        ),
        law=coulomb_friction,
    ),
    Effect(
        "viscous_damping",
        "viscous_damping",
        "torque proportional to a velocity (twist/bend rate or load speed)",
        (
            Variant(
                "shaft",
                (SERIES, PARALLEL),
                "in parallel with the shaft spring: +b * rate of twist / bend (seed 000 eq. 1 B)",
                (_B,),
            ),
            Variant(
                "load",
                (SERIES,),
                "on the load bearing: -b * load speed",
                (_B,),
                needs_inertia_load=True,
            ),
            Variant(
                "q3",
                (ARM,),
                "extra viscous damping at joint 3: b added to q3's dof_damping (implicit in "
                "MuJoCo's step)",
                (_B,),
            ),
        ),
        law=viscous_damping,
    ),
    Effect(
        "backlash",
        "backlash",
        "dead band / free play in a coupling: no torque across a small angle range",
        (
            Variant(
                "coupling",
                (SERIES, PARALLEL),
                "dead zone of width w centred at c on the measured deflection (twist or bend) "
                "before the elastic law",
                (_W, _C),
            ),
            Variant(
                "twist",
                (ARM,),
                "dead zone of width w centred at c on the shaft twist, ahead of joint 3's "
                "transmission law (every transmission's law sees the twist through it)",
                (_W, _C),
            ),
        ),
        law=backlash,
    ),
    Effect(
        "hysteresis",
        "maxwell_slip / conduit_viscoelastic",
        "multivalued torque-deflection loop not explained by viscous damping",
        (
            Variant(
                "maxwell_slip",
                (SERIES, PARALLEL),
                "rate-independent: elasto-slip elements (k_i, slip deflection delta_i = f_i/k_i) "
                "in parallel with the elastic law (seed 000 Sec. V, effects.maxwell_slip)",
                (
                    Param("k_nm_per_rad", "N*m/rad", 0.0, 500.0, "element stiffness (each)"),
                    Param("delta_rad", "rad", 1e-4, 0.5, "element slip deflection (each)"),
                ),
            ),
            Variant(
                "viscoelastic",
                (SERIES, PARALLEL),
                "rate-dependent: Maxwell branches (k_i, tau_i) in parallel with the elastic law "
                "(seed 000 Fig. 9 conduit, effects.conduit_viscoelastic)",
                (
                    Param("k_nm_per_rad", "N*m/rad", 0.0, 500.0, "branch stiffness (each)"),
                    Param("tau_s", "s", 0.005, 20.0, "branch time constant (each)"),
                ),
            ),
        ),
    ),
    Effect(
        "nonlinear_stiffness",
        "nonlinear_stiffness",
        "torque-deflection curve bending away from the straight lines of eq. 8 / eq. 2",
        (
            Variant(
                "poly",
                (SERIES, PARALLEL),
                "tau = K x + c2 r|r| + c3 r^3, r = x/x_ref, one (c2, c3) for both signs",
                (
                    Param("c2_nm", "N*m", -50.0, 50.0, "quadratic term's torque at x_ref"),
                    Param("c3_nm", "N*m", -50.0, 50.0, "cubic term's torque at x_ref"),
                ),
            ),
            Variant(
                "poly_per_sign",
                (SERIES,),
                "as 'poly' with (c2, c3) per twist sign (eq. 8's two sides)",
                (
                    Param("c2_pos_nm", "N*m", -50.0, 50.0, "quadratic term, twist >= 0"),
                    Param("c3_pos_nm", "N*m", -50.0, 50.0, "cubic term, twist >= 0"),
                    Param("c2_neg_nm", "N*m", -50.0, 50.0, "quadratic term, twist < 0"),
                    Param("c3_neg_nm", "N*m", -50.0, 50.0, "cubic term, twist < 0"),
                ),
            ),
            Variant(
                "masterflex08",
                (SERIES,),
                "the spring law is seed 001 Table 1's measured MasterFlex08 curve at "
                "twist * twist_scale (865 mm / L for the same twist per length); synthetic truth",
                (Param("twist_scale", "1", 0.1, 10.0, "twist scale onto the MasterFlex08"),),
                fittable=False,
            ),
        ),
    ),
    Effect(
        "delay",
        "delay",
        "one channel lags the others by a constant time",
        (
            Variant(
                "input",
                (SERIES, PARALLEL),
                "the model is driven by u(t - d): d > 0 the measured output lags, d < 0 the "
                "recorded input lags",
                (Param("delay_s", "s", -0.1, 0.1, "time shift"),),
            ),
        ),
    ),
    Effect(
        "sensor_offset",
        "sensor_offset",
        "a constant bias on a measured channel",
        (
            Variant(
                "output",
                (SERIES, PARALLEL),
                "constant added to the measured torque / moment",
                (Param("offset_nm", "N*m", -20.0, 20.0, "bias"),),
            ),
            Variant(
                "input",
                (SERIES, PARALLEL),
                "constant added to the recorded deflection input (theta_m or phi_b)",
                (Param("offset_rad", "rad", -0.5, 0.5, "bias"),),
            ),
        ),
    ),
    Effect(
        "payload_error",
        "payload_error",
        "the payload differs from the stated one (arm only)",
        (
            Variant(
                "mass",
                (ARM,),
                "extra mass at the payload's centre of mass: gravity torque on joints 2 and 3",
                (Param("dm_kg", "kg", -15.0, 15.0, "mass error"),),
            ),
        ),
        law=payload_error,
    ),
    Effect(
        "shaft_drag",
        "shaft_drag",
        "the shaft's core drags in its casing, more the more the route bends (arm only)",
        (
            Variant(
                "casing",
                (ARM,),
                "torque -T_0 exp(mu_b |phi_B|) sgn(omega_m) on the shaft input, before the spring",
                (
                    Param("drag_nm", "N*m", 0.0, 2.0, "drag torque straight", 0.02),
                    Param("mu_per_rad", "1/rad", 0.0, 3.0, "growth with |bend|", 0.1),
                ),
            ),
        ),
        law=shaft_drag,
    ),
    Effect(
        "lugre_friction",
        "lugre_friction",
        "friction at joint 3 with a bristle state: presliding, stiction, Stribeck dip (arm only)",
        (
            Variant(
                "q3",
                (ARM,),
                "torque -(sigma_0 z + sigma_1 dz/dt + sigma_2 qd3) on joint 3, z the bristles' "
                "own state (LuGre, Canudas de Wit et al. 1995); sigma_0, sigma_1, v_s as declared",
                (
                    Param("f_c_nm", "N*m", 0.0, 20.0, "Coulomb level F_c", 0.1),
                    Param("f_s_nm", "N*m", 0.0, 20.0, "breakaway level F_s", 0.1),
                ),
            ),
        ),
        law=lugre_friction,
    ),
    Effect(
        "motor_thermal",
        "motor_thermal",
        "joint 3's motor warms with its copper loss and gives less torque per ampere (arm only)",
        (
            Variant(
                "j3_motor",
                (ARM,),
                "rotor torque tau_cmd alpha_kt (T - 25 C), T = 25 C + dT_amb + the winding's rise "
                "(one thermal node heated by R(T) I^2); the other numbers as declared",
                (Param("dtemp_amb_k", "K", -50.0, 150.0, "ambient minus 25 C", 10.0),),
            ),
        ),
        law=motor_thermal,
    ),
)

BY_NAME: dict[str, Effect] = {e.name: e for e in EFFECTS}


def names() -> list[str]:
    """All effect names, in registry order."""
    return [e.name for e in EFFECTS]


def get(name: str) -> Effect:
    """The effect of that name; KeyError lists the known names."""
    if name not in BY_NAME:
        raise KeyError(f"unknown effect {name!r}; known effects: {', '.join(names())}")
    return BY_NAME[name]


def arm_laws() -> list[Effect]:
    """The effects with a kernel law on the arm, in registry order (their kernel ids)."""
    return [e for e in EFFECTS if e.law is not None]


LawValues = tuple[str, tuple[tuple[str, float], ...]]  # (effect, ((parameter, value), ...))


def parse_law(text: str) -> LawValues:
    """``NAME[=V1,V2,...]`` -> (effect, ((parameter, value), ...)) of a registry arm law, the text
    of ``fsarm run --effect``. Values by position are the law's arm variant's parameters, in the
    registry's order (as ``fsarm synth --effect`` reads them); ``KEY=VALUE`` items set any of its
    kernel parameters by name; parameters not given keep the law's declared defaults. Checking
    the values' ranges is :meth:`~fsarm_sim.engine.model.Effects.validate`'s; a malformed text is
    an InvalidParameterError naming what is allowed."""
    name, _, rest = text.strip().partition("=")
    name = name.strip()
    laws = {e.name: e for e in arm_laws()}
    if name not in laws:
        raise InvalidParameterError(
            f"--effect {text!r}: {name!r} is not an arm effect law; known: {', '.join(laws)}"
        )
    law = laws[name].law
    assert law is not None
    declared = [d.name for d in law.KERNEL_PARAMS]
    positional = [p.name for v in laws[name].variants if ARM in v.setups for p in v.params]
    values: dict[str, float] = {}
    named = False
    for i, item in enumerate(x.strip() for x in rest.split(",") if rest.strip()):
        key, eq, value = item.rpartition("=")
        key = key.strip()
        named = named or bool(eq)
        if not eq:
            if named or i >= len(positional):
                raise InvalidParameterError(
                    f"--effect {text!r}: {name} takes at most {len(positional)} values by "
                    f"position ({', '.join(positional)}), before any KEY=VALUE"
                )
            key = positional[i]
        if key not in declared:
            raise InvalidParameterError(
                f"--effect {text!r}: {name} has no parameter {key!r}; its parameters: "
                + ", ".join(declared)
            )
        try:
            values[key] = float(value)
        except ValueError:
            raise InvalidParameterError(
                f"--effect {text!r}: {key} must be a number, got {value!r}"
            ) from None
    return name, tuple(values.items())


def parse_laws(texts: list[str]) -> tuple[LawValues, ...]:
    """:func:`parse_law` of each text (``fsarm run --effect``, repeatable)."""
    return tuple(parse_law(t) for t in texts)


def legacy_fields() -> dict[str, tuple[str, str]]:
    """Key -> (effect, parameter) of the laws' keys in older run records' ``effects`` entries
    (each law's ``LEGACY_FIELDS``)."""
    return {
        key: (e.name, param)
        for e in arm_laws()
        for key, param in getattr(e.law, "LEGACY_FIELDS", ())
    }


def legacy_laws(entry: Mapping[str, object]) -> tuple[LawValues, ...]:
    """The laws an older record's ``effects`` entry switched on through its :func:`legacy_fields`
    keys (other keys are ignored), in registry order: a law is on where its ``SIZE`` (the mass
    error, the play's width, the friction level, the damping) is non-zero, as it acted then;
    its other keys come along. A value that is not a number is an
    InvalidParameterError naming the key."""
    keys = legacy_fields()
    values: dict[str, dict[str, float]] = {}
    for key, value in entry.items():
        if key not in keys:
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InvalidParameterError(f"effects.{key} must be a number, got {value!r}")
        effect, param = keys[key]
        values.setdefault(effect, {})[param] = float(value)
    return tuple(
        (e.name, tuple(values[e.name].items()))
        for e in arm_laws()
        if e.name in values and not is_off(e.law, values[e.name])
    )


def applicable(setup: str, inertia_load: bool) -> list[tuple[str, str]]:
    """Fittable (effect, variant) pairs that can act in a setup (series: blocked or inertia)."""
    out = []
    for e in EFFECTS:
        for v in e.variants:
            if not v.fittable:
                continue
            if setup in v.setups and (inertia_load or not v.needs_inertia_load):
                out.append((e.name, v.key))
    return out
