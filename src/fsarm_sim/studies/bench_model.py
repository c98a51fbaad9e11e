"""What both benches of :mod: share: the model's structure and parameters, input checks, and the
stepping loop with prescribed joints.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import (
    ArmStructure,
    Effects,
    SimConfig,
    fixed_tendon,
    model_path,
    write_params,
)
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.plant.transmissions import flexible_shaft
from fsarm_sim.sim.simulation import Backend, raise_on_warning

Array = npt.NDArray[np.float64]
Load = str | float  # "blocked" or a load inertia in kg*m^2

BLOCKED = "blocked"
DEFAULT_MAX_TIMESTEP_S = 1e-3  # the MJCFs' timestep; replay substeps sample intervals to this
MAX_SAMPLES = 20_000_000
WARNING_CHECK_EVERY = 500  # steps
SERIES_COLUMNS = ("t", "theta_m", "theta_s", "phi_b", "tau_s")
PARALLEL_COLUMNS = ("t", "phi_b", "m_b")


# ----------------------------------------------------------------------------------------------
# structure


@dataclass(frozen=True)
class BenchStructure:
    """Indices and ratios read from a compiled bench MJCF (-1: absent)."""

    rotor_qadr: (
        int  # the joint of tendon theta_m (motor rotor, or the parallel bench's input clamp)
    )
    rotor_dof: int
    coef_m: float  # theta_m = coef_m * rotor
    load_qadr: int  # the joint of tendon theta_s (series bench with a load inertia)
    load_dof: int
    coef_s: float  # theta_s = coef_s * load
    bend_qadr: int  # joint "bend" (parallel bench)
    bend_dof: int
    act_slip: int  # first of three consecutive Maxwell-slip states
    act_branch: tuple[int, int]  # conduit branch states
    motor: int  # actuator id of the motor
    motor_gear: float
    motor_limit: float  # |ctrl| limit of the motor actuator (motor-side torque), N*m
    motor_speed_limit: float  # rad/s, rotor side (series bench), 0 if not given
    twist_tendon: int

    def as_arm_structure(self) -> ArmStructure:
        """The arm's structure record with the bench's indices, for :func:`model.write_params`."""
        return ArmStructure(
            qadr=(-1, self.bend_qadr, self.load_qadr, self.rotor_qadr),
            dof=(-1, self.bend_dof, self.load_dof, self.rotor_dof),
            coef_m=self.coef_m,
            coef_s=self.coef_s,
            act_branch=self.act_branch,
            act_slip=self.act_slip,
            ctrl=(-1, -1, self.motor),
            madr=(-1, -1, -1),
            tau_max=(0.0, 0.0, self.motor_limit),
            motor_speed_limit=self.motor_speed_limit,
            twist_tendon=self.twist_tendon,
        )


def _single_joint_tendon(model: mujoco.MjModel, name: str) -> tuple[int, float] | None:
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, name) < 0:
        return None
    wraps = fixed_tendon(model, name)
    if len(wraps) != 1:
        raise ModelStructureError(f"tendon '{name}' of a bench must use exactly one joint")
    (joint, coef), *_ = wraps.items()
    if coef <= 0.0:
        raise ModelStructureError(f"tendon '{name}' must have a positive coefficient, got {coef}")
    return joint, coef


def _optional_id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    return int(mujoco.mj_name2id(model, kind, name))


def read_bench_structure(model: mujoco.MjModel) -> BenchStructure:
    """Find the bench's joints, gear ratios, states and motor by name; check consistency."""
    tm = _single_joint_tendon(model, "theta_m")
    if tm is None:
        raise ModelStructureError("a bench MJCF needs the fixed tendon 'theta_m' (shaft input)")
    rotor, coef_m = tm
    ts = _single_joint_tendon(model, "theta_s")
    load, coef_s = ts if ts is not None else (-1, 1.0)
    twist = _optional_id(model, mujoco.mjtObj.mjOBJ_TENDON, "shaft_twist")
    if ts is not None:
        if twist < 0:
            raise ModelStructureError("a bench with 'theta_s' needs the tendon 'shaft_twist'")
        tw = fixed_tendon(model, "shaft_twist")
        if (
            set(tw) != {rotor, load}
            or abs(tw[rotor] - coef_m) > 1e-12
            or abs(tw[load] + coef_s) > 1e-12
        ):
            raise ModelStructureError("tendon 'shaft_twist' must equal theta_m - theta_s")
    elif twist >= 0:
        raise ModelStructureError("tendon 'shaft_twist' needs a 'theta_s' tendon beside it")
    J, A = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_ACTUATOR
    bend = _optional_id(model, J, "bend")
    slips = [_optional_id(model, A, f"shaft_slip{i}") for i in (1, 2, 3)]
    act_slip = -1
    if any(s >= 0 for s in slips):
        if min(slips) < 0:
            raise ModelStructureError("a bench needs all three shaft_slip actuators or none")
        adr = [int(model.actuator_actadr[s]) for s in slips]
        if adr != [adr[0], adr[0] + 1, adr[0] + 2]:
            raise ModelStructureError("the three shaft_slip actuators must be consecutive")
        act_slip = adr[0]
    branches = [_optional_id(model, A, f"conduit_branch{i}") for i in (1, 2)]
    act_branch = (-1, -1)
    if any(b >= 0 for b in branches):
        if min(branches) < 0:
            raise ModelStructureError("a bench needs both conduit_branch actuators or none")
        act_branch = (
            int(model.actuator_actadr[branches[0]]),
            int(model.actuator_actadr[branches[1]]),
        )
    motor = -1
    for name in ("motor", "bend_motor"):
        motor = _optional_id(model, A, name)
        if motor >= 0:
            break
    if motor < 0:
        raise ModelStructureError("a bench MJCF needs an actuator 'motor' or 'bend_motor'")
    limit = float(np.max(np.abs(model.actuator_ctrlrange[motor])))
    speed = (
        float(model.numeric("motor_speed_limit").data[0])
        if _optional_id(model, mujoco.mjtObj.mjOBJ_NUMERIC, "motor_speed_limit") >= 0
        else 0.0
    )
    return BenchStructure(
        rotor_qadr=int(model.jnt_qposadr[rotor]),
        rotor_dof=int(model.jnt_dofadr[rotor]),
        coef_m=coef_m,
        load_qadr=int(model.jnt_qposadr[load]) if load >= 0 else -1,
        load_dof=int(model.jnt_dofadr[load]) if load >= 0 else -1,
        coef_s=coef_s,
        bend_qadr=int(model.jnt_qposadr[bend]) if bend >= 0 else -1,
        bend_dof=int(model.jnt_dofadr[bend]) if bend >= 0 else -1,
        act_slip=act_slip,
        act_branch=act_branch,
        motor=motor,
        motor_gear=float(model.actuator_gear[motor, 0]),
        motor_limit=limit,
        motor_speed_limit=speed,
        twist_tendon=twist,
    )


def write_bench_params(
    model: mujoco.MjModel,
    st: BenchStructure,
    shaft: ShaftParams,
    effects: Effects,
    setup: float,
    bend_fixed_rad: float,
) -> None:
    """Fill ``fsarm_params`` for a bench (``model.write_params`` + bench overrides).

    Effects whose states or joints the bench lacks are switched off (a kernel would otherwise
    read a state at index -1); the arm's control kernel is always off (``P_EN_CONTROL = 0``).
    """
    write_params(model, st.as_arm_structure(), SimConfig(shaft=shaft, effects=effects), 1)
    p = model.numeric(layout.PARAMS_NAME).data
    p[layout.P_EN_CONTROL] = 0.0
    p[layout.P_SETUP] = setup
    p[layout.P_BEND_FIXED] = bend_fixed_rad
    if st.act_slip < 0:  # no state slots: the shaft's slip elements are off
        p[layout.P_TR + flexible_shaft.I_SLIP_K : layout.P_TR + flexible_shaft.I_SLIP_F] = 0.0
    if st.act_branch[0] < 0 or st.bend_qadr < 0:
        p[layout.P_EN_CONDUIT] = 0.0
    if st.bend_qadr < 0:
        p[layout.P_EN_BEND] = 0.0
        p[layout.P_EN_COUPLING] = 0.0


def bench_spec(name: str, shaft: ShaftParams) -> mujoco.MjSpec:
    """The bench's MjSpec with parameter storage and the slip states' ranges (as model.build_spec)."""
    spec = mujoco.MjSpec.from_file(str(model_path(name)))
    names = {a.name for a in spec.actuators}
    for i in range(3):
        act_name = f"shaft_slip{i + 1}"
        if act_name not in names:
            continue
        act = spec.actuator(act_name)  # normalized element deflections (flexible_shaft)
        act.actlimited = mujoco.mjtLimited.mjLIMITED_TRUE
        block = SimConfig(shaft=shaft).transmission_blocks()[0]
        lim = flexible_shaft.state_limits(block)[i] or (-1e-12, 1e-12)
        act.actrange = [lim[0], lim[1]]
    spec.add_numeric(name=layout.PARAMS_NAME, size=layout.N_PARAMS, data=np.zeros(layout.N_PARAMS))
    spec.add_numeric(name=layout.REF_NAME, size=layout.REF_COLS, data=np.zeros(layout.REF_COLS))
    spec.nuserdata = layout.N_USERDATA
    return spec


# ----------------------------------------------------------------------------------------------
# input checks


def finite_number(name: str, value: Any, *, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InvalidParameterError(f"{name} must be a finite number, got {value!r}")
    if minimum is not None and value < minimum:
        raise InvalidParameterError(f"{name} must be >= {minimum:g}, got {value!r}")
    return float(value)


def parse_load(load: Any) -> float | None:
    """``"blocked"`` -> None; an inertia (kg*m^2, > 0) -> that float; anything else is an error."""
    if isinstance(load, str):
        if load == BLOCKED:
            return None
        raise InvalidParameterError(
            f"unknown load type {load!r}: allowed are 'blocked' or a load inertia in kg*m^2 (> 0)"
        )
    if isinstance(load, bool) or not isinstance(load, int | float):
        raise InvalidParameterError(
            f"load must be 'blocked' or a load inertia in kg*m^2 (> 0), got {load!r}"
        )
    if not math.isfinite(load) or load <= 0.0:
        raise InvalidParameterError(
            f"load inertia must be a finite number > 0 kg*m^2, got {load!r}"
        )
    return float(load)


def load_from_sidecar(load: Mapping[str, Any]) -> Load:
    """The ``load`` object of a series_bench sidecar -> ``"blocked"`` or the inertia (kg*m^2)."""
    if not isinstance(load, Mapping) or "type" not in load:
        raise InvalidParameterError(f"sidecar 'load' must be an object with a 'type', got {load!r}")
    kind = load["type"]
    if kind == BLOCKED:
        return BLOCKED
    if kind == "inertia":
        if "inertia_kgm2" not in load:
            raise InvalidParameterError("sidecar load of type 'inertia' needs 'inertia_kgm2'")
        value = load["inertia_kgm2"]
        parse_load(value)
        return float(value)
    raise InvalidParameterError(
        f"unknown sidecar load type {kind!r}: allowed are 'blocked' and 'inertia'"
    )


def checked_bend(shaft: ShaftParams, bend_rad: float, what: str = "bend angle") -> float:
    bend = finite_number(what, bend_rad)
    shaft.check_bend(bend, what)  # the one bend check (shaft.check_bend_rad), as sweeps and runs
    return bend


def series_input(name: str, values: Any, n: int | None = None) -> Array:
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(f"{name} must be a 1-D array of numbers ({exc})") from exc
    if a.ndim != 1:
        raise InvalidParameterError(f"{name} must be a 1-D array, got shape {a.shape}")
    if n is not None and a.size != n:
        raise InvalidParameterError(f"{name} has {a.size} samples but t has {n}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InvalidParameterError(
            f"{name} contains NaN or infinite values (first at sample {int(bad[0])}); "
            "every sample must be a finite number"
        )
    return np.ascontiguousarray(a)


def time_input(t: Any) -> Array:
    a = series_input("t", t)
    if a.size < 2:
        raise InvalidParameterError(f"t needs at least 2 samples, got {a.size}")
    if a.size > MAX_SAMPLES:
        raise InvalidParameterError(f"at most {MAX_SAMPLES} samples per run, got {a.size}")
    dt = np.diff(a)
    bad = np.flatnonzero(dt <= 0.0)
    if bad.size:
        i = int(bad[0])
        raise InvalidParameterError(
            f"t must be strictly increasing: t[{i + 1}] = {a[i + 1]!r} s follows t[{i}] = {a[i]!r} s"
        )
    return a


def check_backend(backend: Any) -> Backend:
    if backend not in ("python", "native"):
        raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
    return backend


def checked_max_timestep(value: float) -> float:
    h = finite_number("max_timestep_s", value)
    if not 0.0 < h <= 0.01:
        raise InvalidParameterError(f"max_timestep_s must be in (0, 0.01] s, got {value!r}")
    return h


# ----------------------------------------------------------------------------------------------
# the stepping loop with prescribed joints

Prescribed = tuple[int, int, Array]  # (qpos address, dof address, position per sample)


def run_prescribed(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    prescribed: list[Prescribed],
    t: Array,
    max_timestep_s: float,
    record: Callable[[int], None],
) -> None:
    """Step through the samples with each prescribed joint following its series.

    Between samples the joints move piecewise-linearly. Before every physics step the joints'
    positions are set on that line and their velocities to the segment slope. ``record(i)`` is
    called with the state at sample ``i`` (velocities: the slope of the segment that starts
    there; the last sample uses the last segment's slope).
    """
    n = t.size
    data.time = float(t[0])
    steps = 0
    for i in range(n):
        k = i if i < n - 1 else i - 1
        span = t[k + 1] - t[k]
        slopes = [(q[k + 1] - q[k]) / span for _, _, q in prescribed]
        for (qa, da, q), v in zip(prescribed, slopes, strict=True):
            data.qpos[qa] = q[i]
            data.qvel[da] = v
        if i == 0:
            mujoco.mj_forward(model, data)
        record(i)
        if i == n - 1:
            break
        n_sub = max(1, math.ceil(span / max_timestep_s - 1e-9))
        h = span / n_sub
        if model.opt.timestep != h:
            model.opt.timestep = h
        for j in range(n_sub):
            if j:
                for (qa, da, q), v in zip(prescribed, slopes, strict=True):
                    data.qpos[qa] = q[i] + v * h * j
                    data.qvel[da] = v
            mujoco.mj_step(model, data)
        steps += n_sub
        if steps >= WARNING_CHECK_EVERY:
            raise_on_warning(data)
            steps = 0
    raise_on_warning(data)


def kinetic_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    mv = np.zeros(model.nv)
    mujoco.mj_mulM(model, data, mv, data.qvel)
    return 0.5 * float(data.qvel @ mv)
