"""A run's configuration as the model builder takes it: controller gains, the effects switched on,
the shaft and payload (SimConfig).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import hysteresis_model
from fsarm_sim.errors import InvalidParameterError, real_number
from fsarm_sim.kernels import layout
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.plant.transmissions.base import Transmission

PAYLOAD_MAX_KG = 15.0  # seed 000 Table III
# A payload is a 15-kg-class block bolted to the flange: a cylinder r = 60 mm, h = 100 mm with its
# centre 50 mm beyond the flange (estimate; gives tau_3 ~ 66 N*m at rated payload with the arm
# horizontal, close to Table III's 67 N*m).
PAYLOAD_COM_OFFSET_M = 0.05
PAYLOAD_RADIUS_M = 0.06
PAYLOAD_HEIGHT_M = 0.10


CONTROLLERS: dict[str, float] = {
    "default": layout.CTRL_DEFAULT,
    "hysteresis-comp": layout.CTRL_HYSTERESIS,
    "dob": layout.CTRL_DOB,
    "paper-pid": layout.CTRL_PAPER_PID,
}


@dataclass(frozen=True)
class Gains:
    """Controller settings. Defaults were tuned on ``fig14-sine`` (README: Tuning)."""

    ctrl_dt_s: float = 0.001  # 1 kHz (seed 001 ran both loops at 1 kHz)
    wn_rad_s: tuple[float, float, float] = (20.0, 20.0, 25.0)  # position loops, natural frequency
    zeta: tuple[float, float, float] = (1.0, 1.0, 1.0)
    # torque PID (Fig. 13), scheduled on the controller's eq. 8 stiffness K(phi_B, side):
    # kp = w_t / K, ki = w_t w_i / K, kd = d / K  (controllers/joint3_torque.py)
    torque_bandwidth_rad_s: float = 60.0  # w_t: well below the speed loop's ~300 rad/s
    torque_integral_rad_s: float = 10.0  # w_i
    torque_derivative: float = 0.0  # d (off: differentiating the encoder twist is noisy)
    speed_kp: float = 0.009  # N*m per rad/s, motor side (EPOS-like speed loop)
    speed_ki: float = 0.3  # N*m per rad
    speed_ff: bool = (
        True  # add measured shaft-output speed to omega_d (see controllers/joint3_torque.py)
    )
    bend_compensation: bool = True  # joint-2 loop adds the modeled elastic bending moment
    # True: torque-PID gains follow the transmission's stiffness at the current twist and bend;
    # False: fixed gains for its stiffness at zero twist, straight (as seed 001's RTCA PID)
    gain_schedule: bool = True
    # joint 3's controller structure (CONTROLLERS): "default" (the above), "hysteresis-comp"
    # (the torque loop on a Maxwell-slip torque estimate, controllers/joint3_hysteresis.py),
    # "dob" (a disturbance observer on joint 3, controllers/joint3_dob.py) or "paper-pid"
    # (seed 000 Fig. 13 as printed: no speed feedforward, whatever speed_ff says)
    controller: str = "default"
    dob_bandwidth_rad_s: float = 20.0  # the observer's Q-filter cut-off w_q (below w_t)
    # the controller's Maxwell-slip model of the shaft, 12 numbers (engine.hysteresis_model.NAMES);
    # empty: the default identified from the catalogue prototype's simulated bench records,
    # scaled to the controller's shaft
    hysteresis_model: tuple[float, ...] = ()

    def validate(self) -> None:
        values = {
            "ctrl_dt_s": self.ctrl_dt_s,
            "torque_bandwidth_rad_s": self.torque_bandwidth_rad_s,
            "torque_integral_rad_s": self.torque_integral_rad_s,
            "torque_derivative": self.torque_derivative,
            "speed_kp": self.speed_kp,
            "speed_ki": self.speed_ki,
            **{f"wn_rad_s[{i}]": v for i, v in enumerate(self.wn_rad_s)},
            **{f"zeta[{i}]": v for i, v in enumerate(self.zeta)},
        }
        for name, v in values.items():
            if not math.isfinite(real_number(v, f"gain {name}")) or v < 0.0:
                raise InvalidParameterError(f"gain {name} must be a finite number >= 0, got {v!r}")
        if self.ctrl_dt_s <= 0.0:
            raise InvalidParameterError(f"ctrl_dt_s must be > 0, got {self.ctrl_dt_s!r}")
        if self.controller not in CONTROLLERS:
            raise InvalidParameterError(
                f"unknown controller {self.controller!r}; known: {', '.join(CONTROLLERS)}"
            )
        wq = self.dob_bandwidth_rad_s
        if not math.isfinite(wq) or wq <= 0.0:
            raise InvalidParameterError(f"dob_bandwidth_rad_s must be > 0, got {wq!r}")
        if self.controller == "dob" and wq > self.torque_bandwidth_rad_s:
            raise InvalidParameterError(
                f"dob_bandwidth_rad_s must be at most the torque-loop bandwidth "
                f"{self.torque_bandwidth_rad_s:g} rad/s (the observer assumes the torque loop "
                f"is ideal below it), got {wq!r}"
            )
        if self.controller == "dob" and wq * self.ctrl_dt_s > 0.5:
            raise InvalidParameterError(
                f"dob_bandwidth_rad_s {wq:g} rad/s is too fast for the control period "
                f"{self.ctrl_dt_s:g} s: w_q * dt must stay <= 0.5"
            )
        hysteresis_model.check(self.hysteresis_model)


@dataclass(frozen=True)
class Effects:
    """Which effects act on the plant: the shaft's own (switches; slip hysteresis also needs
    non-zero element stiffness) and the registry's arm effect laws switched on."""

    series: bool = True
    bending: bool = True
    conduit: bool = True
    slip: bool = True
    coupling: bool = True  # energy-consistency term of eq. 8 on joint 2 (physics.py)
    control: bool = True
    # the registry's arm effect laws switched on (plant.effects.registry, Effect.law), with the
    # values of their kernel parameters: ((effect, ((parameter, value), ...)), ...); parameters
    # not given keep the law's declared default. Each acts on the plant only, the controllers do
    # not know it.
    laws: tuple[tuple[str, tuple[tuple[str, float], ...]], ...] = ()

    def validate(self) -> None:
        validate_laws(self.laws)

    @classmethod
    def from_entry(cls, entry: Mapping[str, object]) -> Effects:
        """The effects of a record's ``effects`` entry (:func:`fsarm_sim.records.sidecar.
        effects_entry`): the switches, ``laws`` as ``{effect: {parameter: value}}``, and the
        keys older records used for some laws (``payload_error_kg``, ``backlash_width_rad``,
        ...: :func:`~fsarm_sim.plant.effects.registry.legacy_laws`); a law given both ways is
        given twice (InvalidParameterError)."""
        legacy = registry.legacy_fields()
        switches = {f.name for f in fields(cls)} - {"laws"}
        kw: dict[str, bool] = {}
        for key, value in entry.items():
            if key in switches:
                if not isinstance(value, bool):
                    raise InvalidParameterError(
                        f"effects.{key} must be true or false, got {value!r}"
                    )
                kw[key] = value
            elif key != "laws" and key not in legacy:
                raise InvalidParameterError(
                    f"unknown key effects.{key!r}; allowed: {', '.join(sorted(switches))}, laws, "
                    + ", ".join(legacy)
                )
        laws_raw = entry.get("laws", {})
        if not isinstance(laws_raw, Mapping) or not all(
            isinstance(v, Mapping) for v in laws_raw.values()
        ):
            raise InvalidParameterError(
                "effects.laws must map each effect to {parameter: value}, got " + repr(laws_raw)
            )
        laws = tuple(
            (
                str(name),
                tuple((str(k), real_number(v, f"effects.laws.{name}.{k}")) for k, v in vs.items()),
            )
            for name, vs in laws_raw.items()
        )
        laws += registry.legacy_laws(entry)
        out = cls(**kw, laws=laws)
        out.validate()
        return out


@dataclass(frozen=True)
class SimConfig:
    """Everything that defines one simulated run except its reference."""

    shaft: ShaftParams = field(default_factory=lambda: load_catalogue().shaft())
    payload_kg: float = 0.0
    gains: Gains = field(default_factory=Gains)
    effects: Effects = field(default_factory=Effects)
    controller_shaft: ShaftParams | None = None  # the controller's eq. 8 model; None: same as shaft
    timestep_s: float | None = None  # None: the MJCF's (1 ms)
    integrator: str | None = None  # "Euler", "RK4", "implicit", "implicitfast"; None: the MJCF's
    joint_damping: bool = True  # harmonic-drive/hypoid/motor viscous damping of the MJCF
    # joint 3's transmission (fsarm_sim.plant.transmissions): name, parameter overrides of its plant
    # law, and of the controller's copy (None: the controller knows the plant's law exactly).
    # The flexible shaft takes its numbers from ``shaft`` / ``controller_shaft`` instead.
    transmission: str = transmissions.DEFAULT
    transmission_params: tuple[tuple[str, float], ...] = ()
    controller_transmission_params: tuple[tuple[str, float], ...] | None = None

    def with_(self, **changes: object) -> SimConfig:
        return replace(self, **changes)  # type: ignore[arg-type]

    def validate(self) -> None:
        real_number(self.payload_kg, "payload_kg")
        if self.timestep_s is not None:
            real_number(self.timestep_s, "timestep_s")
        if not math.isfinite(self.payload_kg) or not 0.0 <= self.payload_kg <= PAYLOAD_MAX_KG:
            raise InvalidParameterError(
                f"payload must be between 0 and {PAYLOAD_MAX_KG:g} kg (seed 000 Table III), got {self.payload_kg!r}"
            )
        self.gains.validate()
        self.effects.validate()
        self.transmission_blocks()  # the transmission's own checks (TransmissionError)
        if self.gains.controller == "hysteresis-comp" and self.transmission != "flexible-shaft":
            raise InvalidParameterError(
                "controller 'hysteresis-comp' models the flexible shaft's hysteresis; joint 3's "
                f"transmission here is {self.transmission!r} (use default, dob or paper-pid)"
            )
        if self.timestep_s is not None and (
            not math.isfinite(self.timestep_s) or self.timestep_s <= 0.0
        ):
            raise InvalidParameterError(f"timestep must be > 0 s, got {self.timestep_s!r}")
        if self.integrator is not None and self.integrator not in INTEGRATORS:
            raise InvalidParameterError(
                f"integrator must be one of {sorted(INTEGRATORS)}, got {self.integrator!r}"
            )

    def transmission_model(self) -> Transmission:
        """Joint 3's transmission (TransmissionError names the known ones)."""
        return transmissions.get(self.transmission)

    def rating_nm(self) -> float:
        """Torque rating of joint 3's transmission (shaft side), N*m."""
        return self.transmission_model().rating_nm(self.transmission_blocks()[0])

    def transmission_blocks(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(plant, controller) parameter blocks of joint 3's transmission (copies: built once
        per config, which is frozen, and kept; a model build asks for them several times)."""
        kept = self.__dict__.get("_blocks")
        if kept is None:
            tr = self.transmission_model()
            plant = tr.run_block(self.shaft, dict(self.transmission_params), self.effects.slip)
            ctrl = tr.run_block(
                self.controller_shaft or self.shaft,
                dict(self.controller_transmission_params or self.transmission_params),
            )
            kept = (plant, ctrl)
            object.__setattr__(self, "_blocks", kept)  # not a field: eq, hash, replace ignore it
        return kept[0].copy(), kept[1].copy()


INTEGRATORS = {
    "Euler": mujoco.mjtIntegrator.mjINT_EULER,
    "RK4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
}


def validate_laws(laws: tuple[tuple[str, tuple[tuple[str, float], ...]], ...]) -> None:
    """Every law a registered arm law, each parameter one it declares, finite and within the
    registry's bounds where the registry states them; else InvalidParameterError."""
    known = {e.name: e for e in registry.arm_laws()}
    seen: set[str] = set()
    for name, values in laws:
        if name not in known:
            raise InvalidParameterError(
                f"unknown arm effect law {name!r}; known: {', '.join(known) or 'none'}"
            )
        if name in seen:
            raise InvalidParameterError(f"arm effect law {name!r} is given twice")
        seen.add(name)
        effect = known[name]
        assert effect.law is not None
        declared = {d.name for d in effect.law.KERNEL_PARAMS}
        # the registry's fit bounds, else the law's own validity range (its LIMITS, if any)
        limits: dict[str, tuple[float, float]] = dict(getattr(effect.law, "LIMITS", {}))
        limits.update({p.name: (p.lower, p.upper) for v in effect.variants for p in v.params})
        for key, value in values:
            if key in getattr(effect.law, "FROM_MODEL", ()):
                raise InvalidParameterError(
                    f"{name}.{key} is read from the compiled MJCF, not given"
                )
            if key not in declared:
                raise InvalidParameterError(
                    f"{name} has no parameter {key!r}; its parameters: {', '.join(sorted(declared))}"
                )
            b = limits.get(key)
            real_number(value, f"{name}.{key}")  # a number, never a boolean
            if not math.isfinite(value) or (b is not None and not b[0] <= value <= b[1]):
                unit = {d.name: d.unit for d in effect.law.KERNEL_PARAMS}[key]
                allowed = f"within [{b[0]:g}, {b[1]:g}] {unit}" if b else "finite"
                raise InvalidParameterError(f"{name}.{key} must be {allowed}, got {value!r}")
