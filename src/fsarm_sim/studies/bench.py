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
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from fsarm_sim.controllers.joint3_torque import scheduled_gains, speed_loop, torque_pid
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import (
    Effects,
)
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant.effects import series_stiffness
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, raise_on_warning
from fsarm_sim.studies.bench_model import BLOCKED as BLOCKED
from fsarm_sim.studies.bench_model import DEFAULT_MAX_TIMESTEP_S as DEFAULT_MAX_TIMESTEP_S
from fsarm_sim.studies.bench_model import (
    MAX_SAMPLES,
    WARNING_CHECK_EVERY,
    Array,
    BenchStructure,
    Load,
    bench_spec,
    check_backend,
    checked_bend,
    checked_max_timestep,
    finite_number,
    kinetic_energy,
    parse_load,
    read_bench_structure,
    run_prescribed,
    series_input,
    time_input,
    write_bench_params,
)
from fsarm_sim.studies.bench_model import PARALLEL_COLUMNS as PARALLEL_COLUMNS
from fsarm_sim.studies.bench_model import SERIES_COLUMNS as SERIES_COLUMNS
from fsarm_sim.studies.bench_model import load_from_sidecar as load_from_sidecar

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
            finite_number(name, getattr(self, name), minimum=0.0)
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
        tt = time_input(t)
        th = series_input("theta_m", theta_m, tt.size)
        h = checked_max_timestep(max_timestep_s)
        s0 = float(th[0]) if theta_s0 is None else finite_number("theta_s0", theta_s0)
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
                diag["energy_j"][i] = kinetic_energy(m, d) + physics.shaft_potential(
                    prm, d.qpos, d.act
                )

        with callbacks.active(self.backend):
            run_prescribed(m, d, [(st.rotor_qadr, st.rotor_dof, rotor)], tt, h, record)
        cols = {
            "t": tt.copy(),
            "theta_m": th.copy(),
            "theta_s": out["theta_s"],
            "phi_b": np.full(n, self.bend_rad),
            "tau_s": out["tau_s"],
        }
        cols.update(diag)
        return cols

    def _scheduled_torque_gains(self, g: TorqueLoopGains, twist: float) -> tuple[float, float]:
        """The torque PI's (kp, ki) scheduled on the series stiffness at ``twist`` (eq. 3)."""
        sh = self.shaft
        stiffness = series_stiffness.stiffness_nm_per_rad(
            twist, self.bend_rad, sh.k_pos, sh.s_pos, sh.k_neg, sh.s_neg
        )
        kp, ki, _ = scheduled_gains(
            g.torque_bandwidth_rad_s, g.torque_integral_rad_s, 0.0, stiffness
        )
        return kp, ki

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
        tt = time_input(t)
        td = series_input("tau_d", tau_d, tt.size)
        h_max = checked_max_timestep(max_timestep_s)
        s0 = finite_number("theta_s0", theta_s0)
        st, prm, m = self.structure, self.params, self.model
        dt = g.ctrl_dt_s
        ticks = _control_ticks(tt, dt)
        n = ticks.size
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
                    energy[k] = kinetic_energy(m, d) + physics.shaft_potential(prm, d.qpos, d.act)
                kp, ki = self._scheduled_torque_gains(g, twist)
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
        out = {"t": ticks, "theta_m": cols["theta_m"], "theta_s": cols["theta_s"]}
        out |= {"phi_b": np.full(n, self.bend_rad), "tau_s": cols["tau_s"], "tau_d": tau_ref}
        out["tau_motor"] = cols["tau_motor"]
        return out if energy is None else {**out, "energy_j": energy}


def _control_ticks(tt: Array, dt: float) -> Array:
    """The control ticks ``t[0] + k dt`` up to ``t[-1]``: at least two, at most MAX_SAMPLES."""
    n = math.floor(float(tt[-1] - tt[0]) / dt + 1e-9) + 1
    if n < 2:
        raise InvalidParameterError(
            f"t spans {tt[-1] - tt[0]:g} s, less than one control period {dt:g} s"
        )
    if n > MAX_SAMPLES:
        raise InvalidParameterError(f"at most {MAX_SAMPLES} control ticks per run, got {n}")
    ticks: Array = tt[0] + dt * np.arange(n)
    return ticks


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
    check_backend(backend)
    sh = _default_shaft(shaft)
    inertia = parse_load(load)
    bend = checked_bend(sh, bend_rad)
    damping = finite_number("load_damping_nms", load_damping_nms, minimum=0.0)
    friction = finite_number("load_friction_nm", load_friction_nm, minimum=0.0)
    fx = effects or Effects()
    spec = bench_spec("series_bench", sh)
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
        tt = time_input(t)
        phi = series_input("phi_b", phi_b, tt.size)
        h = checked_max_timestep(max_timestep_s)
        worst = int(np.argmax(np.abs(phi)))
        checked_bend(self.shaft, float(phi[worst]), f"phi_b[{worst}]")
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
            run_prescribed(m, d, prescribed, tt, h, record)
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
    check_backend(backend)
    sh = _default_shaft(shaft)
    twist = finite_number("twist_rad", twist_rad)
    fx = effects or Effects()
    spec = bench_spec("parallel_bench", sh)
    if link_inertia_kgm2 is not None:
        inertia = finite_number("link_inertia_kgm2", link_inertia_kgm2)
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
