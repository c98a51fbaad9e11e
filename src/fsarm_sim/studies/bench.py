"""The two test benches of seed 000 Fig. 5 (Sec. III-A) and their simulation API.

* **Series bench** (``models/bench/series_bench.xml``): motor + 91:1 planetary -> flexible shaft
  held at a bend angle -> 20 N*m torque sensor -> blocked output or a load inertia. The shaft is
  the same fixed tendon, the same state actuators and the same :mod:`fsarm_sim.kernels.physics` kernels as
  on the arm; the bend angle is a parameter (``layout.P_BEND_FIXED``), not a joint.
* **Parallel bench** (``models/bench/parallel_bench.xml``): a 51:1 geared motor turns a joint
  ``bend`` that bends the shaft; the bending moment (eq. 2/4 elastic + stiffening + conduit
  branches) acts on that joint, and a torque sensor between gearhead and joint reads it. The
  shaft input may be held twisted ("with and without torsion").

Replay (the measured-data spec, setups ``series_bench`` and ``parallel_bench``): the recorded
input is *imposed kinematically* - ``theta_m(t)`` on the series bench, ``phi_b(t)`` on the
parallel bench - by writing the prescribed joint's position and velocity before every physics
step (piecewise-linear between samples, velocity = the segment slope, so MuJoCo's semi-implicit
Euler integrates the prescribed joint onto the next sample exactly). Everything else - the load,
the Maxwell-slip and conduit states - is integrated by MuJoCo. Outputs are returned as the spec's
columns (``t, theta_m, theta_s, phi_b, tau_s`` resp. ``t, phi_b, m_b``).

The series bench can also run closed loop (:meth:`SeriesBench.run_torque_control`): a torque
PID on the *measured* shaft torque (torque sensor) commands the shaft-input speed, an EPOS-like
speed loop drives the motor - the bench campaigns' chirps. It runs in Python between physics
steps with ``P_EN_CONTROL = 0``, so the arm's control kernel is never entered.

Parameters live in ``fsarm_params`` (:mod:`fsarm_sim.kernels.layout`) with the bench's structure
indices (absent joints are -1) and ``P_SETUP`` set to the bench.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.controllers.joint3_torque import scheduled_gains, speed_loop, torque_pid
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import (
    ArmStructure,
    Effects,
    SimConfig,
    fixed_tendon,
    model_path,
    write_params,
)
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant.effects import series_stiffness
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.plant.transmissions import flexible_shaft
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, raise_on_warning

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


def _spec(name: str, shaft: ShaftParams) -> mujoco.MjSpec:
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


def _finite_number(name: str, value: Any, *, minimum: float | None = None) -> float:
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


def _check_bend(shaft: ShaftParams, bend_rad: float, what: str = "bend angle") -> float:
    bend = _finite_number(what, bend_rad)
    shaft.check_bend(bend, what)  # the one bend check (shaft.check_bend_rad), as sweeps and runs
    return bend


def _series(name: str, values: Any, n: int | None = None) -> Array:
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


def _time(t: Any) -> Array:
    a = _series("t", t)
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


def _check_backend(backend: Any) -> Backend:
    if backend not in ("python", "native"):
        raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
    return backend


def _max_timestep(value: float) -> float:
    h = _finite_number("max_timestep_s", value)
    if not 0.0 < h <= 0.01:
        raise InvalidParameterError(f"max_timestep_s must be in (0, 0.01] s, got {value!r}")
    return h


# ----------------------------------------------------------------------------------------------
# the stepping loop with prescribed joints

Prescribed = tuple[int, int, Array]  # (qpos address, dof address, position per sample)


def _run_prescribed(
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


def _kinetic_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    mv = np.zeros(model.nv)
    mujoco.mj_mulM(model, data, mv, data.qvel)
    return 0.5 * float(data.qvel @ mv)


# ----------------------------------------------------------------------------------------------
# series bench


@dataclass(frozen=True)
class TorqueLoopGains:
    """Closed-loop torque control of the series bench (the chirp campaigns of Sec. III-A).

    Torque PID on the *measured* shaft torque (the DBRK-20) -> shaft-input speed, then an
    EPOS-like PI speed loop on the motor: the cascade of ``controllers/joint3_torque.py``. The
    torque gains are scheduled on the eq. 8 stiffness at the held bend and the side of the twist
    (``scheduled_gains``, as on the arm), the speed gains on the rotor inertia read from the model,
    so one setting serves all nine shafts. Defaults are estimates (models/bench/README.md,
    "Torque loop"): a torque loop of ~32 Hz so the 0.5-20 Hz chirps of Sec. III-A are followed
    in amplitude (blocked 9 x 450 mm shaft: RMS error 0.9 % of amplitude at 0.5-1.3 Hz, 28 % -
    mostly phase lag - at 8-20 Hz), the speed loop 3x faster.
    """

    ctrl_dt_s: float = 0.001  # 1 kHz (seed 001 ran both loops at 1 kHz)
    torque_bandwidth_rad_s: float = 200.0  # w_t: kp = w_t / K(phi, side)
    torque_integral_rad_s: float = 10.0  # w_i: ki = w_t w_i / K
    speed_bandwidth_rad_s: float = 600.0  # speed kp = I_rotor * w_s
    speed_integral_rad_s: float = 60.0  # speed ki = kp * w_si
    speed_ff: bool = True  # add the measured load speed to the speed command

    def validate(self) -> None:
        for name in (
            "ctrl_dt_s",
            "torque_bandwidth_rad_s",
            "torque_integral_rad_s",
            "speed_bandwidth_rad_s",
            "speed_integral_rad_s",
        ):
            _finite_number(name, getattr(self, name), minimum=0.0)
        if self.ctrl_dt_s <= 0.0:
            raise InvalidParameterError(f"ctrl_dt_s must be > 0, got {self.ctrl_dt_s!r}")


@dataclass
class SeriesBench:
    """A compiled series bench: shaft, load and bend fixed; replay any number of inputs."""

    model: mujoco.MjModel
    structure: BenchStructure
    shaft: ShaftParams
    load_inertia_kgm2: float | None  # None: blocked output
    bend_rad: float
    effects: Effects
    backend: Backend = DEFAULT_BACKEND

    @property
    def params(self) -> Array:
        return self.model.numeric(layout.PARAMS_NAME).data

    def _new_data(self, theta_s0: float) -> mujoco.MjData:
        d = mujoco.MjData(self.model)
        mujoco.mj_resetData(self.model, d)
        if self.structure.load_qadr >= 0:
            d.qpos[self.structure.load_qadr] = theta_s0 / self.structure.coef_s
        return d

    def _offset(self, theta_s0: float) -> float:
        """Blocked output: the rotor angle represents theta_m - theta_s0 (theta_s is constant)."""
        return theta_s0 if self.structure.load_qadr < 0 else 0.0

    def replay(
        self,
        theta_m: Any,
        t: Any,
        *,
        theta_s0: float | None = None,
        max_timestep_s: float = DEFAULT_MAX_TIMESTEP_S,
        diagnostics: bool = False,
    ) -> dict[str, Array]:
        """Impose the recorded shaft input ``theta_m(t)``; return the spec's columns.

        ``theta_s0``: shaft output angle at ``t[0]`` (blocked: its constant value); default
        ``theta_m[0]`` (the shaft starts untwisted). The load starts at rest, slip elements relaxed.
        ``diagnostics=True`` adds ``twist``, ``omega_s`` (load speed), ``energy_j`` (kinetic +
        shaft potential).
        """
        tt = _time(t)
        th = _series("theta_m", theta_m, tt.size)
        h = _max_timestep(max_timestep_s)
        s0 = float(th[0]) if theta_s0 is None else _finite_number("theta_s0", theta_s0)
        st, prm, m = self.structure, self.params, self.model
        d = self._new_data(s0)
        off = self._offset(s0)
        rotor = (th - off) / st.coef_m
        n = tt.size
        out = {k: np.empty(n) for k in ("theta_s", "tau_s")}
        diag = {k: np.empty(n) for k in ("twist", "omega_s", "energy_j")} if diagnostics else {}

        def record(i: int) -> None:
            out["tau_s"][i] = physics.shaft_torque(prm, d.qpos, d.qvel, d.act)
            out["theta_s"][i] = st.coef_s * d.qpos[st.load_qadr] if st.load_qadr >= 0 else s0
            if diagnostics:
                twist, _ = physics.twist_and_rate(prm, d.qpos, d.qvel)
                diag["twist"][i] = twist
                diag["omega_s"][i] = st.coef_s * d.qvel[st.load_dof] if st.load_dof >= 0 else 0.0
                diag["energy_j"][i] = _kinetic_energy(m, d) + physics.shaft_potential(
                    prm, d.qpos, d.act
                )

        with callbacks.active(self.backend):
            _run_prescribed(m, d, [(st.rotor_qadr, st.rotor_dof, rotor)], tt, h, record)
        cols = {
            "t": tt.copy(),
            "theta_m": th.copy(),
            "theta_s": out["theta_s"],
            "phi_b": np.full(n, self.bend_rad),
            "tau_s": out["tau_s"],
        }
        cols.update(diag)
        return cols

    def run_torque_control(
        self,
        tau_d: Any,
        t: Any,
        *,
        gains: TorqueLoopGains | None = None,
        theta_s0: float = 0.0,
        max_timestep_s: float = DEFAULT_MAX_TIMESTEP_S,
        diagnostics: bool = False,
    ) -> dict[str, Array]:
        """Closed-loop torque control of the shaft torque toward ``tau_d(t)`` (bench campaigns).

        The desired torque is interpolated linearly at the control ticks ``t[0] + k ctrl_dt``
        (up to ``t[-1]``); the result has one row per tick with the spec's columns, plus
        ``tau_d`` and ``tau_motor`` (rotor-side motor torque). Motor and load start at rest
        with an untwisted shaft at ``theta_m = theta_s = theta_s0``.
        """
        g = gains or TorqueLoopGains()
        g.validate()
        tt = _time(t)
        td = _series("tau_d", tau_d, tt.size)
        h_max = _max_timestep(max_timestep_s)
        s0 = _finite_number("theta_s0", theta_s0)
        st, prm, m, sh = self.structure, self.params, self.model, self.shaft
        dt = g.ctrl_dt_s
        n = math.floor(float(tt[-1] - tt[0]) / dt + 1e-9) + 1
        if n < 2:
            raise InvalidParameterError(
                f"t spans {tt[-1] - tt[0]:g} s, less than one control period {dt:g} s"
            )
        if n > MAX_SAMPLES:
            raise InvalidParameterError(f"at most {MAX_SAMPLES} control ticks per run, got {n}")
        ticks = tt[0] + dt * np.arange(n)
        tau_ref = np.interp(ticks, tt, td)
        d = self._new_data(s0)
        off = self._offset(s0)
        d.qpos[st.rotor_qadr] = (s0 - off) / st.coef_m
        d.time = float(tt[0])
        n_sub = max(1, math.ceil(dt / h_max - 1e-9))
        m.opt.timestep = dt / n_sub
        cols = {k: np.empty(n) for k in ("theta_m", "theta_s", "tau_s", "tau_motor")}
        energy = np.empty(n) if diagnostics else None
        integ = e_prev = s_integ = 0.0
        init = 0.0
        steps = 0
        omega_max = (st.motor_speed_limit if st.motor_speed_limit > 0 else math.inf) * st.coef_m
        with callbacks.active(self.backend):
            mujoco.mj_forward(m, d)
            dof = st.rotor_dof
            i_rotor = float(d.M[m.M_rowadr[dof] + m.M_rownnz[dof] - 1])
            skp = i_rotor * g.speed_bandwidth_rad_s
            ski = skp * g.speed_integral_rad_s
            for k in range(n):
                tau_meas = physics.shaft_torque(prm, d.qpos, d.qvel, d.act)  # the torque sensor
                twist, _ = physics.twist_and_rate(prm, d.qpos, d.qvel)
                cols["tau_s"][k] = tau_meas
                cols["theta_m"][k] = st.coef_m * d.qpos[st.rotor_qadr] + off
                cols["theta_s"][k] = st.coef_s * d.qpos[st.load_qadr] if st.load_qadr >= 0 else s0
                if energy is not None:
                    energy[k] = _kinetic_energy(m, d) + physics.shaft_potential(prm, d.qpos, d.act)
                stiffness = series_stiffness.stiffness_nm_per_rad(
                    twist, self.bend_rad, sh.k_pos, sh.s_pos, sh.k_neg, sh.s_neg
                )
                kp, ki, _ = scheduled_gains(
                    g.torque_bandwidth_rad_s, g.torque_integral_rad_s, 0.0, stiffness
                )
                omega_ff = (
                    st.coef_s * d.qvel[st.load_dof] if g.speed_ff and st.load_dof >= 0 else 0.0
                )
                omega_d, integ, e_prev, _, _, _ = torque_pid(
                    tau_ref[k], tau_meas, integ, e_prev, init, dt, kp, ki, 0.0, omega_ff, omega_max
                )
                init = 1.0
                tau_mot, s_integ = speed_loop(
                    omega_d / st.coef_m, d.qvel[dof], s_integ, dt, skp, ski, st.motor_limit
                )
                cols["tau_motor"][k] = tau_mot
                if k == n - 1:
                    break
                d.ctrl[st.motor] = tau_mot
                mujoco.mj_step(m, d, nstep=n_sub)
                steps += n_sub
                if steps >= WARNING_CHECK_EVERY:
                    raise_on_warning(d)
                    steps = 0
        raise_on_warning(d)
        out = {
            "t": ticks,
            "theta_m": cols["theta_m"],
            "theta_s": cols["theta_s"],
            "phi_b": np.full(n, self.bend_rad),
            "tau_s": cols["tau_s"],
            "tau_d": tau_ref,
            "tau_motor": cols["tau_motor"],
        }
        if energy is not None:
            out["energy_j"] = energy
        return out


def _default_shaft(shaft: ShaftParams | None) -> ShaftParams:
    return shaft if shaft is not None else load_catalogue().shaft()


def build_series_bench(
    shaft: ShaftParams | None = None,
    load: Load = BLOCKED,
    bend_rad: float = 0.0,
    *,
    effects: Effects | None = None,
    load_damping_nms: float = 0.0,
    load_friction_nm: float = 0.0,
    backend: Backend = DEFAULT_BACKEND,
) -> SeriesBench:
    """Compile the series bench for one shaft, load and held bend angle.

    ``load``: ``"blocked"`` or the load inertia in kg*m^2 (> 0). ``effects``: which shaft effects
    act (``Effects.control`` is ignored: the arm's controller never runs on a bench; bending and
    conduit have no joint to act on here). ``load_damping_nms`` / ``load_friction_nm``: optional
    viscous damping and Coulomb friction (MuJoCo ``frictionloss``) of the load bearing - effects a
    measured bench may have that the nominal model does not state; only with an inertia load.
    """
    _check_backend(backend)
    sh = _default_shaft(shaft)
    inertia = parse_load(load)
    bend = _check_bend(sh, bend_rad)
    damping = _finite_number("load_damping_nms", load_damping_nms, minimum=0.0)
    friction = _finite_number("load_friction_nm", load_friction_nm, minimum=0.0)
    fx = effects or Effects()
    spec = _spec("series_bench", sh)
    if inertia is None:
        if damping > 0.0 or friction > 0.0:
            raise InvalidParameterError(
                "load damping/friction need a load inertia; the blocked output cannot move"
            )
        spec.delete(spec.tendon("shaft_twist"))
        spec.delete(spec.tendon("theta_s"))
        spec.delete(spec.joint("load"))
    else:
        body = spec.body("load_disc")
        body.inertia = [inertia, 0.6 * inertia, 0.6 * inertia]  # only the x (axis) value acts
        body.explicitinertial = True
        joint = spec.joint("load")
        joint.damping = [damping, 0.0, 0.0]  # linear viscous term only
        joint.frictionloss = friction
    with callbacks.suspended():
        model = spec.compile()
    st = read_bench_structure(model)
    if st.twist_tendon >= 0:
        model.tendon_armature[st.twist_tendon] = sh.inertia_kgm2  # eq. 1 J, as on the arm
    write_bench_params(model, st, sh, fx, layout.SETUP_SERIES_BENCH, bend)
    return SeriesBench(
        model=model,
        structure=st,
        shaft=sh,
        load_inertia_kgm2=inertia,
        bend_rad=bend,
        effects=fx,
        backend=backend,
    )


def simulate_series_bench(
    theta_m: Any,
    t: Any,
    shaft: ShaftParams | None = None,
    load: Load = BLOCKED,
    bend_rad: float = 0.0,
    *,
    effects: Effects | None = None,
    theta_s0: float | None = None,
    load_damping_nms: float = 0.0,
    load_friction_nm: float = 0.0,
    max_timestep_s: float = DEFAULT_MAX_TIMESTEP_S,
    backend: Backend = DEFAULT_BACKEND,
    diagnostics: bool = False,
) -> dict[str, Array]:
    """Build the series bench and replay ``theta_m(t)``: columns t, theta_m, theta_s, phi_b, tau_s."""
    bench = build_series_bench(
        shaft,
        load,
        bend_rad,
        effects=effects,
        load_damping_nms=load_damping_nms,
        load_friction_nm=load_friction_nm,
        backend=backend,
    )
    return bench.replay(
        theta_m, t, theta_s0=theta_s0, max_timestep_s=max_timestep_s, diagnostics=diagnostics
    )


# ----------------------------------------------------------------------------------------------
# parallel bench


@dataclass
class ParallelBench:
    """A compiled parallel (bending) bench: shaft and held torsion fixed; replay phi_b(t)."""

    model: mujoco.MjModel
    structure: BenchStructure
    shaft: ShaftParams
    twist_rad: float
    effects: Effects
    backend: Backend = DEFAULT_BACKEND

    @property
    def params(self) -> Array:
        return self.model.numeric(layout.PARAMS_NAME).data

    def replay(
        self,
        phi_b: Any,
        t: Any,
        *,
        max_timestep_s: float = DEFAULT_MAX_TIMESTEP_S,
        diagnostics: bool = False,
    ) -> dict[str, Array]:
        """Impose the recorded bend angle ``phi_b(t)``; return columns t, phi_b, m_b.

        ``m_b`` is what the torque sensor between gearhead and joint reads: the torque the motor
        must apply to the joint, i.e. the shaft's bending moment (elastic + conduit + torsion
        coupling) plus link inertia x the bend acceleration (from central differences of the
        input). The conduit branches start relaxed at ``phi_b[0]``. ``diagnostics=True`` adds
        ``m_elastic``, ``m_conduit``, ``m_inertial`` and ``tau_s`` (torque of the held twist).
        """
        tt = _time(t)
        phi = _series("phi_b", phi_b, tt.size)
        h = _max_timestep(max_timestep_s)
        worst = int(np.argmax(np.abs(phi)))
        _check_bend(self.shaft, float(phi[worst]), f"phi_b[{worst}]")
        st, prm, m = self.structure, self.params, self.model
        d = mujoco.MjData(m)
        mujoco.mj_resetData(m, d)
        for a in st.act_branch:
            if a >= 0:
                d.act[a] = phi[0]
        acc = np.gradient(np.gradient(phi, tt), tt)
        twist = np.full(tt.size, self.twist_rad / st.coef_m)
        n = tt.size
        m_b = np.empty(n)
        names = ("m_elastic", "m_conduit", "m_inertial", "tau_s")
        diag = {k: np.empty(n) for k in names} if diagnostics else {}

        def record(i: int) -> None:
            d.qacc[:] = 0.0
            d.qacc[st.bend_dof] = acc[i]
            mujoco.mj_inverse(m, d)
            m_b[i] = d.qfrc_inverse[st.bend_dof]
            if diagnostics:
                total, conduit = physics.bending_torques(prm, d.qpos, d.qvel, d.act)
                diag["m_elastic"][i] = -(total - conduit)
                diag["m_conduit"][i] = -conduit
                diag["m_inertial"][i] = m_b[i] + total
                diag["tau_s"][i] = physics.shaft_torque(prm, d.qpos, d.qvel, d.act)

        prescribed = [(st.bend_qadr, st.bend_dof, phi), (st.rotor_qadr, st.rotor_dof, twist)]
        with callbacks.active(self.backend):
            _run_prescribed(m, d, prescribed, tt, h, record)
        cols = {"t": tt.copy(), "phi_b": phi.copy(), "m_b": m_b}
        cols.update(diag)
        return cols


def build_parallel_bench(
    shaft: ShaftParams | None = None,
    *,
    twist_rad: float = 0.0,
    effects: Effects | None = None,
    link_inertia_kgm2: float | None = None,
    backend: Backend = DEFAULT_BACKEND,
) -> ParallelBench:
    """Compile the parallel bench for one shaft.

    ``twist_rad``: shaft twist held during bending ("with torsion"; 0: without). Its torque and the
    eq. 8 bend coupling act when ``effects.series`` is on. ``link_inertia_kgm2``: inertia of the
    moving link about the joint (default: the MJCF's estimate, see models/bench/README.md).
    """
    _check_backend(backend)
    sh = _default_shaft(shaft)
    twist = _finite_number("twist_rad", twist_rad)
    fx = effects or Effects()
    spec = _spec("parallel_bench", sh)
    if link_inertia_kgm2 is not None:
        inertia = _finite_number("link_inertia_kgm2", link_inertia_kgm2)
        if inertia <= 0.0:
            raise InvalidParameterError(
                f"link_inertia_kgm2 must be > 0 kg*m^2, got {link_inertia_kgm2!r}"
            )
        body = spec.body("bend_link")
        body.ipos = [0.0, 0.0, 0.0]  # the whole link inertia about the joint axis
        body.inertia = [inertia, inertia, inertia]
        body.explicitinertial = True
    with callbacks.suspended():
        model = spec.compile()
    st = read_bench_structure(model)
    if st.bend_qadr < 0:
        raise ModelStructureError("the parallel bench MJCF needs a joint named 'bend'")
    write_bench_params(model, st, sh, fx, layout.SETUP_PARALLEL_BENCH, 0.0)
    return ParallelBench(
        model=model, structure=st, shaft=sh, twist_rad=twist, effects=fx, backend=backend
    )


def simulate_parallel_bench(
    phi_b: Any,
    t: Any,
    shaft: ShaftParams | None = None,
    *,
    twist_rad: float = 0.0,
    effects: Effects | None = None,
    link_inertia_kgm2: float | None = None,
    max_timestep_s: float = DEFAULT_MAX_TIMESTEP_S,
    backend: Backend = DEFAULT_BACKEND,
    diagnostics: bool = False,
) -> dict[str, Array]:
    """Build the parallel bench and replay ``phi_b(t)``: columns t, phi_b, m_b."""
    bench = build_parallel_bench(
        shaft,
        twist_rad=twist_rad,
        effects=effects,
        link_inertia_kgm2=link_inertia_kgm2,
        backend=backend,
    )
    return bench.replay(phi_b, t, max_timestep_s=max_timestep_s, diagnostics=diagnostics)
