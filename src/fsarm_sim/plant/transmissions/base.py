"""The transmission interface: what an elastic/remote transmission at joint 3 must provide.

Joint 3's motor turns its gearbox output ``theta_m = rotor / i_G1``; the joint side of the
transmission is ``theta_s = i_G2 q3`` (ahead of the 10:1 hypoid). Every transmission sits between
the two, on the twist ``x = theta_m - theta_s`` (rad) and its rate, and may read the bend angle
``phi_B = q2`` when it is routed over joint 2. It gives back one torque ``tau`` (N*m, positive for
positive twist), applied as ``-tau / i_G1`` on the rotor and ``+i_G2 tau`` on q3 - exactly the
place of the flexible shaft (seed 000 Fig. 1), so every transmission runs on the same arm, the
same controller cascade and the same scenarios.

A transmission module (``fsarm_sim.plant.transmissions.<name>``) holds

* **kernels** - plain ``math`` functions the callbacks run (compiled by :mod:`fsarm_sim.engine.native`
  exactly like the effect kernels: no numpy allocation, no Python objects). ``tr`` is the
  module's parameter block (a float64 array of :data:`N_TR`, order = ``PARAMS``), ``act`` MuJoCo's
  ``data.act`` and ``a0`` the index of the transmission's first of :data:`N_STATES` state slots:

  - ``torque_nm(tr, x, xdot, bend, act, a0) -> float``      the true transmitted torque;
  - ``sensor_torque_nm(tr, x, bend) -> float``              the virtual torque sensor: what the
    controller computes from the two encoders with the transmission's elastic law;
  - ``stiffness_nm_per_rad(tr, x, bend) -> float``          d(sensor_torque)/dx (may be <= 0
    where the law has negative stiffness; the gain scheduler floors it);
  - ``state_rate(tr, x, xdot, bend, act, a0, i, vm) -> float``  d(act[a0 + i])/dt,
    i < N_STATES (0.0 for slots the transmission does not use); ``vm`` is the motor-side
    (transmission input) speed ``d theta_m/dt``, for laws whose friction follows the sliding
    direction of a tendon in its sheath rather than the twist rate (seed 004); laws that do not
    read it give it the default 0.0;
  - optionally ``motor_torque_nm(tr, x, xdot, bend, act, a0) -> float``: the torque at the motor
    end when it differs from the joint end (a capstan: friction along the sheath takes the
    difference, the motor pays it); without it the motor end carries ``torque_nm``.
  - ``potential_j(tr, x, bend, act, a0) -> float``          stored elastic energy;
  - ``bend_torque_nm(tr, x, bend, act, a0) -> float``       -d(potential_j)/d(bend): the torque
    on joint 2 that keeps a routed, bend-dependent law energy-consistent (0.0 when the law does
    not read the bend).

* **Python data** - ``NAME``, ``TITLE``, ``SOURCE`` (seed, equations, tables), ``PARAMS`` (a
  tuple of :class:`Param`, each with its published value, where it comes from, and its allowed
  range with the reason - :class:`Bounds`), optionally ``validate(tr)`` (checks across
  parameters, e.g. ``sigma_min < sigma_max``, raising :class:`TransmissionError`), ``STATES``
  (names of the state slots used, at most :data:`N_STATES`), ``ROUTED_OVER_JOINT2`` (True when
  the transmission is a shaft/sheath bent by joint 2: the flexible shaft's bending moment on
  joint 2 then also acts), ``TWIST_RANGE_RAD`` (the range of twist its law is valid for, used for
  stiffness bounds and checks; ``valid_twist_rad(tr)`` when it depends on the parameters), and
  optionally ``state_limits(tr) -> list[tuple[float, float] |
  None]``, ``initial_states(tr, x, bend) -> list[float]`` and ``rating_nm(tr) -> float``.

A transmission whose model has torques on its *output* against the frame (seed 003 model F:
bearing friction, eccentric mass) gets them applied on q3 through ``physics.tr_output_torque``.

"What the encoders see" is the same for all: the motor encoder (``theta_m``) and the joint
encoder (``q3``, hence ``theta_s``); a transmission with play or a position law between them
says so in ``sensor_torque_nm``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError

FloatArray = npt.NDArray[np.float64]

N_TR = 26  # parameters of one transmission block (the largest law's PARAMS fit)
N_STATES = 3  # continuous state slots (data.act) a transmission may use: the shaft_slip slots


@dataclass(frozen=True)
class Bounds:
    """The values a parameter may take: ``lo``..``hi``, each end open or closed, and why.

    Checked for every parameter of every block at build time (:func:`fill_block`); a value
    outside is a :class:`TransmissionError` naming the transmission, the parameter, the value,
    the range and this reason.
    """

    lo: float
    hi: float
    why: str
    lo_open: bool = False  # True: lo itself is not allowed
    hi_open: bool = False

    def contains(self, value: float) -> bool:
        if not math.isfinite(value):
            return False
        above = value > self.lo if self.lo_open else value >= self.lo
        below = value < self.hi if self.hi_open else value <= self.hi
        return above and below

    def text(self) -> str:
        """Interval notation, e.g. ``(0, 1]`` or ``[0, inf)``."""
        lo = "-inf" if self.lo == -math.inf else f"{self.lo:.6g}"
        hi = "inf" if self.hi == math.inf else f"{self.hi:.6g}"
        left = "(" if self.lo_open or self.lo == -math.inf else "["
        right = ")" if self.hi_open or self.hi == math.inf else "]"
        return f"{left}{lo}, {hi}{right}"

    def just_outside(self) -> tuple[float, ...]:
        """Values just outside each finite end (an open end itself, and a step beyond)."""
        out: list[float] = []
        for end, is_open, direction in (
            (self.lo, self.lo_open, -1.0),
            (self.hi, self.hi_open, 1.0),
        ):
            if not math.isfinite(end):
                continue
            if is_open:
                out.append(end)
            out.append(end + direction * max(1e-6 * abs(end), 1e-9))
        return tuple(out)


def positive(why: str, hi: float = math.inf, *, hi_open: bool = False) -> Bounds:
    """``(0, hi]``: a length, a time constant, a stiffness - zero or negative has no meaning."""
    return Bounds(0.0, hi, why, lo_open=True, hi_open=hi_open)


def non_negative(why: str, hi: float = math.inf, *, hi_open: bool = False) -> Bounds:
    """``[0, hi]``: a magnitude (friction, damping, play) that may be absent."""
    return Bounds(0.0, hi, why, hi_open=hi_open)


def any_finite(why: str) -> Bounds:
    """Any finite number: a fitted coefficient whose sign the fit decides (the law's shape is
    checked across parameters in the module's ``validate``)."""
    return Bounds(-math.inf, math.inf, why)


@dataclass(frozen=True)
class Param:
    """One parameter of a transmission law: published/default value, unit, source, valid range."""

    name: str
    value: float
    unit: str
    source: str
    bounds: Bounds


class TransmissionError(FsarmError, ValueError):
    """A transmission name, parameter or value that is not allowed."""


def out_of_range(
    transmission: str, p: Param, value: float, error: type[TransmissionError] = TransmissionError
) -> TransmissionError:
    """The error for ``p`` set to ``value`` outside its bounds (names all of it)."""
    unit = "" if p.unit in ("-", "") else f" {p.unit}"
    return error(
        f"transmission {transmission!r}: parameter {p.name} = {value!r}{unit} is outside its "
        f"allowed range {p.bounds.text()}{unit} ({p.bounds.why}); "
        f"default {p.value:.6g}{unit}, set with --tr-param {p.name}=VALUE"
    )


def check_bounds(
    transmission: str,
    params: tuple[Param, ...],
    tr: FloatArray,
    error: type[TransmissionError] = TransmissionError,
) -> None:
    """The generic range check: every parameter of block ``tr`` within its :class:`Bounds`."""
    for i, p in enumerate(params):
        v = float(tr[i])
        if not p.bounds.contains(v):
            raise out_of_range(transmission, p, v, error)


def fill_block(
    name: str,
    params: tuple[Param, ...],
    overrides: dict[str, float] | None = None,
    *,
    validate: Callable[[FloatArray], None] | None = None,
    error: type[TransmissionError] = TransmissionError,
) -> FloatArray:
    """A parameter block: ``params``' values in order, ``overrides`` by name, each value checked
    against its :class:`Bounds` (:func:`check_bounds`), then ``validate`` (cross-parameter)."""
    names = [p.name for p in params]
    if len(names) > N_TR:
        raise error(f"{name}: {len(names)} parameters, at most {N_TR}")
    out = np.zeros(N_TR)
    for i, p in enumerate(params):
        out[i] = p.value
    for key, value in (overrides or {}).items():
        if key not in names:
            raise error(
                f"transmission {name!r} has no parameter {key!r}; allowed: {', '.join(names)}"
            )
        try:
            v = float(value)
        except (TypeError, ValueError):
            v = math.nan
        if not math.isfinite(v):
            p = params[names.index(key)]
            raise error(
                f"transmission {name!r}: parameter {key} must be a finite number, got {value!r}; "
                f"allowed range {p.bounds.text()} ({p.bounds.why})"
            )
        out[names.index(key)] = v
    check_bounds(name, params, out, error)
    if validate is not None:
        validate(out)
    return out


class TransmissionModule(Protocol):
    """What a transmission module must provide (see the module docstring): checked by mypy on
    every registered module (``transmissions/__init__.py`` assigns each to this type)."""

    NAME: str
    TITLE: str
    SOURCE: str
    PARAMS: tuple[Param, ...]
    STATES: tuple[str, ...]
    ROUTED_OVER_JOINT2: bool
    TWIST_RANGE_RAD: float
    CONSERVATIVE: dict[str, float]

    def torque_nm(
        self, tr: FloatArray, x: float, xdot: float, bend: float, act: FloatArray, a0: int
    ) -> float: ...

    def sensor_torque_nm(self, tr: FloatArray, x: float, bend: float) -> float: ...

    def stiffness_nm_per_rad(self, tr: FloatArray, x: float, bend: float) -> float: ...

    def state_rate(
        self,
        tr: FloatArray,
        x: float,
        xdot: float,
        bend: float,
        act: FloatArray,
        a0: int,
        i: int,
        vm: float,
    ) -> float: ...

    def potential_j(
        self, tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int
    ) -> float: ...

    def bend_torque_nm(
        self, tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int
    ) -> float: ...


@dataclass(frozen=True)
class Transmission:
    """A registered transmission: its kernel module and Python-side data."""

    name: str
    kind: int  # the id the kernels dispatch on (layout.P_TRANS)
    module: TransmissionModule

    @property
    def title(self) -> str:
        return str(self.module.TITLE)

    @property
    def source(self) -> str:
        return str(self.module.SOURCE)

    @property
    def params(self) -> tuple[Param, ...]:
        return tuple(self.module.PARAMS)

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(self.module.STATES)

    @property
    def routed_over_joint2(self) -> bool:
        return bool(self.module.ROUTED_OVER_JOINT2)

    @property
    def twist_range_rad(self) -> float:
        return float(self.module.TWIST_RANGE_RAD)

    def valid_twist_rad(self, tr: FloatArray) -> float:
        """Twist range of the law for these parameters: the module's ``valid_twist_rad(tr)``
        when it depends on them (e.g. the QA-Joint's end stops at +-sigma), else
        ``TWIST_RANGE_RAD``."""
        fn = getattr(self.module, "valid_twist_rad", None)
        return float(fn(tr)) if fn is not None else self.twist_range_rad

    def param_names(self) -> list[str]:
        return [p.name for p in self.params]

    @property
    def takes_shaft(self) -> bool:
        """True when its parameters come from the run's catalogue shaft (``params_from_shaft``)."""
        return hasattr(self.module, "params_from_shaft")

    def run_block(
        self, shaft: Any, overrides: dict[str, float], hysteresis: bool = True
    ) -> FloatArray:
        """The block of one run: the module's values for the run's catalogue shaft (if it takes
        one: ``params_from_shaft``), then ``overrides``, then - with ``hysteresis`` False - the
        module's ``HYSTERESIS_OFF`` values."""
        fn = getattr(self.module, "params_from_shaft", None)
        values = dict(fn(shaft)) if fn is not None else {}
        values.update(overrides)
        if not hysteresis:
            values.update(getattr(self.module, "HYSTERESIS_OFF", {}))
        return self.block(values)

    def block(self, overrides: dict[str, float] | None = None) -> FloatArray:
        """The parameter block (length N_TR): published values, with ``overrides`` applied and
        checked by the module's ``validate(tr)`` if it has one."""
        return fill_block(
            self.name, self.params, overrides, validate=getattr(self.module, "validate", None)
        )

    def state_limits(self, tr: FloatArray) -> list[tuple[float, float] | None]:
        fn = getattr(self.module, "state_limits", None)
        limits: list[tuple[float, float] | None] = list(fn(tr)) if fn else []
        return (limits + [None] * N_STATES)[:N_STATES]

    def initial_states(self, tr: FloatArray, x: float, bend: float) -> list[float]:
        fn = getattr(self.module, "initial_states", None)
        values: list[float] = list(fn(tr, x, bend)) if fn else []
        return (values + [0.0] * N_STATES)[:N_STATES]

    # --- evaluated from the kernels (Python side) ---
    def sensor_torque(self, tr: FloatArray, x: float, bend: float) -> float:
        return float(self.module.sensor_torque_nm(tr, x, bend))

    def stiffness(self, tr: FloatArray, x: float, bend: float) -> float:
        return float(self.module.stiffness_nm_per_rad(tr, x, bend))

    def rating_nm(self, tr: FloatArray) -> float:
        """Torque the transmission is rated for (sizes test signals, flags overloads).

        The module's ``rating_nm(tr)`` if it states one; otherwise the smaller torque of the two
        sides at half the valid twist range, straight (an estimate of a usable range).
        """
        fn = getattr(self.module, "rating_nm", None)
        if fn is not None:
            return float(fn(tr))
        half = 0.5 * self.valid_twist_rad(tr)
        return min(abs(self.sensor_torque(tr, half, 0.0)), abs(self.sensor_torque(tr, -half, 0.0)))

    def max_stiffness(self, tr: FloatArray, bend_max_rad: float = 2.1) -> float:
        """Largest stiffness over the valid twist range and bends up to ``bend_max_rad`` (the
        module's ``max_stiffness(tr)`` when it states one, e.g. with parallel elements)."""
        fn = getattr(self.module, "max_stiffness", None)
        if fn is not None:
            return float(fn(tr))
        r = self.valid_twist_rad(tr)
        xs = np.linspace(-r, r, 401)
        bends = np.linspace(-bend_max_rad, bend_max_rad, 9) if self.routed_over_joint2 else [0.0]
        return max(self.stiffness(tr, float(x), float(b)) for x in xs for b in bends)

    def twist_for_torque(self, tr: FloatArray, tau: float, bend: float) -> float:
        """The twist whose sensor torque equals ``tau`` on the stable branch through zero.

        Walks out from zero twist while the law rises (stops at a stiffness peak: a torque the
        transmission cannot hold statically raises TransmissionError), then bisects.
        """
        if tau == 0.0:
            return 0.0
        fn = getattr(self.module, "twist_for_torque", None)
        if fn is not None:  # the module inverts its own law (e.g. a linear one, exactly)
            return float(fn(tr, tau, bend))
        sign = 1.0 if tau > 0.0 else -1.0
        r = self.valid_twist_rad(tr)
        n = 2000
        prev_x, prev_t = 0.0, self.sensor_torque(tr, 0.0, bend)
        for i in range(1, n + 1):
            x = sign * r * i / n
            t = self.sensor_torque(tr, x, bend)
            if sign * t < sign * prev_t:  # past the peak: unstable beyond
                break
            if sign * t >= abs(tau):
                lo, hi = prev_x, x
                for _ in range(80):
                    mid = 0.5 * (lo + hi)
                    if sign * self.sensor_torque(tr, mid, bend) >= abs(tau):
                        hi = mid
                    else:
                        lo = mid
                return 0.5 * (lo + hi)
            prev_x, prev_t = x, t
        raise TransmissionError(
            f"transmission {self.name!r} cannot hold {tau:.3g} N*m statically at bend "
            f"{bend:.3g} rad (its largest stable torque on that side is {prev_t:.3g} N*m)"
        )

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "title": self.title,
            "source": self.source,
            "states": list(self.states),
            "routed_over_joint2": self.routed_over_joint2,
            "params": [
                {
                    "name": p.name,
                    "value": p.value,
                    "unit": p.unit,
                    "source": p.source,
                    "range": p.bounds.text(),
                    "range_reason": p.bounds.why,
                }
                for p in self.params
            ],
        }
