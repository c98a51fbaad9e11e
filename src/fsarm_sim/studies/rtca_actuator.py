"""Seed 001's actuator as an ODE (motor, gearbox, encoders, cascade) and one bench run of it; the
experiments on it and the model's sources ("module docstring" below) are in
:mod:`fsarm_sim.studies.rtca_bench`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import maxwell_slip
from fsarm_sim.plant.transmissions import rtca
from fsarm_sim.plant.transmissions.base import N_STATES

Array = npt.NDArray[np.float64]
CArray = npt.NDArray[np.complex128]

RPM = 2.0 * math.pi / 60.0
# Sec. 3.3 (text): NRMSE of eq. 3 straight and at the tightest bend, over the +-5 N*m span
NRMSE_STRAIGHT = 0.0032
NRMSE_R150 = 0.023


FRICTION_SITES = ("core", "twist")
# the core-site friction is twice the transmission's element: the sensor at the output end
# carries half of what the core's middle takes from the casing (module docstring)
CORE_FRICTION_FACTOR = 2.0


class BenchError(InvalidParameterError):
    """A seed-001 bench parameter or experiment setting outside what the bench can run."""


@dataclass(frozen=True)
class Pid:
    """The outer torque loop (Fig. 8): output velocity set-point [rad/s] from the torque error."""

    kp: float  # rad/s per N*m
    ki: float  # rad/s per N*m*s
    kd: float  # rad/s per N*m/s
    d_filter_hz: float = 100.0  # first-order filter of the derivative (estimate)


@dataclass(frozen=True)
class Rtca001:
    """Seed 001's actuator (module docstring: sources and estimates)."""

    gear_ratio: float = 86.0  # Sec. 2.2: GP 32HP 86:1
    motor_cpt: int = 500  # Sec. 2.2: integrated 500 CPT encoder
    shaft_cpt: int = 2000  # Sec. 2.2: two US Digital E6, 2000 CPT
    quadrature: int = 4  # estimate: 4 edges per count (EPOS3, EL5101)
    rotor_inertia_kgm2: float = 34.1e-7  # estimate: 33.3 (motor) + 0.8 (gearhead) g*cm²
    speed_limit_rad_s: float = 192.0 * RPM  # Sec. 2.2: continuous speed 192 rpm (output)
    torque_limit_nm: float = 12.0  # Sec. 2.2: intermittent torque 12 N*m (output)
    velocity_bw_hz: float = 30.0  # estimate: EPOS3 velocity loop bandwidth
    ctrl_dt_s: float = 1e-3  # Sec. 4.1.1: both loops at 1 kHz
    bus_delay_cycles: int = 1  # estimate: one EtherCAT cycle master -> drive
    transport_delay_s: float = 0.0  # further dead time master -> motor (module docstring)
    reference_delay_s: float = 0.0  # set-point logged -> reaching the torque loop (docstring)
    substeps: int = 5  # physics steps per control cycle
    residual_friction: bool = True  # the shaft's unmodelled residual (module docstring)
    friction_site: str = "twist"  # "twist": end to end; "core": core on its casing (docstring)
    core_inertia_kgm2: float = 2.7e-6  # estimate: solid 8 mm steel core, 865 mm (docstring)
    core_segments: int = 2  # "core": the core's equal segments, friction at the joints between
    sensor_lsb_nm: float = 40.0 / 2**16  # EL3102 (16 bit, +-10 V) on the DRBK20's +-20 N*m
    block: tuple[float, ...] = field(default_factory=lambda: tuple(rtca.default_block()))

    def check(self) -> None:
        checks = (
            ("gear_ratio", self.gear_ratio > 0.0),
            ("motor_cpt", self.motor_cpt > 0),
            ("shaft_cpt", self.shaft_cpt > 0),
            ("quadrature", self.quadrature in (1, 2, 4)),
            ("rotor_inertia_kgm2", self.rotor_inertia_kgm2 > 0.0),
            ("speed_limit_rad_s", self.speed_limit_rad_s > 0.0),
            ("torque_limit_nm", self.torque_limit_nm > 0.0),
            ("velocity_bw_hz", 0.0 < self.velocity_bw_hz < 0.25 / self.ctrl_dt_s),
            ("ctrl_dt_s", 0.0 < self.ctrl_dt_s <= 0.01),
            ("bus_delay_cycles", 0 <= self.bus_delay_cycles <= 10),
            ("transport_delay_s", 0.0 <= self.transport_delay_s <= 0.2),
            ("reference_delay_s", 0.0 <= self.reference_delay_s <= 0.2),
            ("core_inertia_kgm2", self.core_inertia_kgm2 > 0.0),
            ("substeps", 1 <= self.substeps <= 100),
            (
                "core_segments",
                isinstance(self.core_segments, int) and 2 <= self.core_segments <= 16,
            ),
            ("sensor_lsb_nm", self.sensor_lsb_nm >= 0.0),
        )
        if self.friction_site not in FRICTION_SITES:
            raise BenchError(
                f"seed-001 bench: friction_site = {self.friction_site!r}; allowed: "
                + ", ".join(FRICTION_SITES)
            )
        for name, ok in checks:
            value = getattr(self, name)
            if not (ok and math.isfinite(float(value))):
                raise BenchError(
                    f"seed-001 bench: {name} = {value!r} is out of range (positive and finite; "
                    "quadrature 1, 2 or 4; the velocity bandwidth below a quarter of the control "
                    "rate; 0-10 bus cycles; delays 0-0.2 s; 1-100 substeps)"
                )

    @property
    def delay_cycles(self) -> int:
        """Control cycles between the torque loop's output and the drive acting on it."""
        return self.bus_delay_cycles + round(self.transport_delay_s / self.ctrl_dt_s)

    @property
    def inertia_out_kgm2(self) -> float:
        """Rotor + gearhead inertia seen at the gearbox output."""
        return self.rotor_inertia_kgm2 * self.gear_ratio**2

    def shaft_block(self) -> Array:
        """The RTCA block the bench's shaft runs: ``block`` with the friction element switched
        off when ``residual_friction`` is False."""
        tr = np.array(self.block, dtype=float)
        if not self.residual_friction:
            tr[rtca.I_SLIP_F] = 0.0
        rtca.validate(tr)
        return tr

    def residual_nm(self, radius_m: float) -> float:
        """Half-width of the shaft's friction loop at bend radius R: the transmission's element
        (module docstring), ``scale f_0 exp(mu_b phi)`` held beyond R = 150 mm."""
        tr = self.shaft_block()
        return float(
            tr[rtca.I_SCALE] * rtca.slip_band_rad(tr, bend_of(radius_m, tr))[1] * rtca.slip_k(tr)
        )


def bend_of(radius_m: float, block: npt.ArrayLike) -> float:
    """The rtca law's bend angle for the paper's bend radius R: ``L_bend / R`` (0 straight)."""
    if math.isnan(radius_m) or radius_m <= 0.0:
        raise BenchError(f"bend radius must be > 0 m (inf = straight), got {radius_m!r}")
    tr = np.asarray(block, dtype=float)
    return 0.0 if math.isinf(radius_m) else float(tr[rtca.I_L_BEND] / radius_m)


@dataclass(frozen=True)
class BenchRun:
    """One run, sampled at the control rate."""

    t: Array
    tau_des: Array  # torque set-point, N*m
    tau_est: Array  # T̂_s(Δθ, R) from the quantised encoders (the loop's feedback)
    tau_true: Array  # torque at the shaft's output (eq. 1/3 with c, + residual friction)
    tau_sensor: Array  # the torque sensor's reading of tau_true
    theta_m: Array  # gearbox output angle, rad (all signals at the start of each cycle)
    theta_s: Array  # shaft output angle, rad
    omega_cmd: Array  # velocity set-point, rad/s at the gearbox output
    saturated: float  # fraction of cycles with the velocity set-point at its limit


def _quantise(x: float, step: float) -> float:
    return math.floor(x / step) * step


def _checked_inputs(
    act: Rtca001,
    pid: Pid,
    tau_des: Array,
    theta_s: Array | None,
    bend_rad: Array | None,
) -> tuple[Array, Array, Array | None]:
    """(tau_des, output angle per cycle, bend per cycle or None), checked."""
    act.check()
    tau_des = np.asarray(tau_des, dtype=float)
    n = tau_des.size
    if n < 2 or not np.all(np.isfinite(tau_des)):
        raise BenchError("tau_des must hold at least two finite samples")
    out = np.zeros(n) if theta_s is None else np.asarray(theta_s, dtype=float)
    if out.shape != tau_des.shape or not np.all(np.isfinite(out)):
        raise BenchError("theta_s must be finite and as long as tau_des")
    for name, v in (("kp", pid.kp), ("ki", pid.ki), ("kd", pid.kd)):
        if not math.isfinite(v) or v < 0.0:
            raise BenchError(f"PID {name} must be finite and >= 0, got {v!r}")
    if bend_rad is None:
        return tau_des, out, None
    bends = np.asarray(bend_rad, dtype=float)
    if bends.shape != tau_des.shape or not np.all(np.isfinite(bends)) or np.any(bends < 0):
        raise BenchError("bend_rad must be finite, >= 0 and as long as tau_des")
    return tau_des, out, bends


class _Cascade:
    """The controllers: the outer PID torque loop (EtherCAT master), its delay, and the EPOS3
    velocity PI that gives the motor torque."""

    def __init__(self, act: Rtca001, pid: Pid) -> None:
        self.pid, self.dt = pid, act.ctrl_dt_s
        j, wv = act.inertia_out_kgm2, 2.0 * math.pi * act.velocity_bw_hz
        self.kpv, self.kiv = j * wv, j * wv * wv / 4.0  # PI: crossover ~ wv, zero at wv/4 (est.)
        self.a_d = math.exp(-2.0 * math.pi * pid.d_filter_hz * self.dt)
        self.w_lim, self.t_lim = act.speed_limit_rad_s, act.torque_limit_nm
        self.integ_v = self.integ_t = 0.0
        self.e_prev, self.d_f = 0.0, 0.0
        self.queue = [0.0] * (act.delay_cycles + 1)
        self.n_sat = 0

    def velocity_command(self, k: int, e: float) -> float:
        """The PID's output velocity set-point for the torque error ``e`` of cycle ``k``."""
        pid, dt = self.pid, self.dt
        d_raw = (e - self.e_prev) / dt if k > 0 else 0.0
        self.e_prev = e
        self.d_f = self.a_d * self.d_f + (1.0 - self.a_d) * d_raw
        cmd = pid.kp * e + self.integ_t + pid.kd * self.d_f
        if abs(cmd) >= self.w_lim:
            cmd = math.copysign(self.w_lim, cmd)
            self.n_sat += 1
        else:
            self.integ_t += pid.ki * e * dt  # no wind-up while saturated
        return cmd

    def motor_torque(self, cmd: float, om_meas: float) -> float:
        """The velocity PI's torque on the delayed set-point (``cmd`` enters the delay line)."""
        self.queue.append(cmd)
        ev = self.queue.pop(0) - om_meas
        tm = self.kpv * ev + self.integ_v
        if abs(tm) >= self.t_lim:
            tm = math.copysign(self.t_lim, tm)
        else:
            self.integ_v += self.kiv * ev * self.dt
        return tm


class _Drive:
    """The output-referred rotor on the shaft: its states and its motion through one cycle.

    ``core``: the friction acts on the casing at the joints between the core's equal segments
    (rotor - segment - joint - ... - segment - output, each segment the law at n times the
    twist); else across the twist (the transmission's element)."""

    def __init__(self, act: Rtca001, bend: float) -> None:
        tr = act.shaft_block()
        self.tr, self.core = tr, act.friction_site == "core"
        self.law = tr.copy()
        if self.core:
            self.law[rtca.I_SLIP_F] = 0.0  # the friction acts on the core, not across the twist
        k_fr = rtca.slip_k(tr) * tr[rtca.I_SCALE] * (CORE_FRICTION_FACTOR if self.core else 1.0)
        self.banded = self.core and tr[rtca.I_SLIP_F] > 0.0
        self.bend = bend
        self.band = rtca.slip_band_rad(tr, bend if self.banded else 0.0)
        self.j, self.substeps, self.h = (
            act.inertia_out_kgm2,
            act.substeps,
            act.ctrl_dt_s / act.substeps,
        )
        self.n_seg, n_node = float(act.core_segments), act.core_segments - 1
        # each joint: its share of the core's inertia and friction
        self.jn, self.kn = act.core_inertia_kgm2 / n_node, k_fr / n_node
        self.st = np.zeros(N_STATES)  # the rtca transmission's states: st[0] its friction element
        self.th, self.om = 0.0, 0.0  # gearbox output angle, speed
        # the joints between the core's segments: angle, speed, friction deflection
        self.thc, self.omc, self.z = [0.0] * n_node, [0.0] * n_node, [0.0] * n_node

    def set_bend(self, bend: float) -> None:
        self.bend = bend
        if self.banded:
            self.band = rtca.slip_band_rad(self.tr, bend)

    def segment(self, y: float, yd: float) -> float:
        """Torque of one core segment (1/n of the length: the law at n times the twist)."""
        return rtca.torque_nm(self.law, self.n_seg * y, self.n_seg * yd, self.bend, self.st, 0)

    def output_torque(self, ths: float, v_s: float) -> float:
        """The torque the output end carries (what the sensor measures)."""
        if self.core:
            return self.segment(self.thc[-1] - ths, self.omc[-1] - v_s)  # the output segment
        return rtca.torque_nm(self.tr, self.th - ths, self.om - v_s, self.bend, self.st, 0)

    def advance(self, tm: float, ths: float, v_s: float) -> None:
        """One control cycle under motor torque ``tm``, the output moving from ``ths`` at ``v_s``."""
        if self.core:
            self._advance_core(tm, ths, v_s)
        else:
            self._advance_twist(tm, ths, v_s)

    def _advance_twist(self, tm: float, ths: float, v_s: float) -> None:
        h, j, tr, st, bend = self.h, self.j, self.tr, self.st, self.bend
        th, om = self.th, self.om
        for i in range(self.substeps):
            x = th - (ths + v_s * h * i)
            xd = om - v_s
            tq = rtca.torque_nm(tr, x, xd, bend, st, 0)  # eq. 1 with c x', + friction
            rate = rtca.state_rate(tr, x, xd, bend, st, 0, 0)
            om += h * (tm - tq) / j
            th += om * h
            st[0] += rate * h
        self.th, self.om = th, om

    def _advance_core(self, tm: float, ths: float, v_s: float) -> None:
        h, j, jn, kn, band = self.h, self.j, self.jn, self.kn, self.band
        th, om, thc, omc, z = self.th, self.om, self.thc, self.omc, self.z
        nodes = range(len(z))
        for i in range(self.substeps):
            # rotor - segment - joint (friction on the casing) - ... - segment - output
            ang, spd = [th, *thc, ths + v_s * h * i], [om, *omc, v_s]
            seg = [
                self.segment(ang[m] - ang[m + 1], spd[m] - spd[m + 1]) for m in range(len(z) + 1)
            ]
            rates = [maxwell_slip.banded_rate(z[m], omc[m], band[0], band[1]) for m in nodes]
            om += h * (tm - seg[0]) / j
            for m in nodes:
                omc[m] += h * (seg[m] - seg[m + 1] - kn * z[m]) / jn
            th += om * h
            for m in nodes:
                thc[m] += omc[m] * h
                z[m] += rates[m] * h
        self.th, self.om = th, om


def run(
    act: Rtca001,
    pid: Pid,
    tau_des: Array,
    *,
    radius_m: float = math.inf,
    theta_s: Array | None = None,
    bend_rad: Array | None = None,
) -> BenchRun:
    """Run the cascade on ``tau_des`` (one value per control cycle, as logged: the loop acts on
    it ``reference_delay_s`` later).

    ``theta_s``: the output angle per cycle (what the load motor delivers: :func:`load_motion`
    turns its chirp into that, Sec. 4.2); ``None`` blocks the output (Fig. 4A, Sec. 4.1).
    ``bend_rad``: the law's bend angle per cycle (Sec. 5.1: the knee bending the shaft while it
    works; the estimate reads it as the knee encoder does); ``None`` holds ``radius_m``'s.
    """
    tau_des, out, bends = _checked_inputs(act, pid, tau_des, theta_s, bend_rad)
    n = tau_des.size
    drive = _Drive(act, bend_of(radius_m, act.shaft_block()))
    cascade = _Cascade(act, pid)
    dt = act.ctrl_dt_s
    q_m = 2.0 * math.pi / (act.motor_cpt * act.quadrature)  # rotor increment
    q_s = 2.0 * math.pi / (act.shaft_cpt * act.quadrature)  # shaft-end increment
    lsb = act.sensor_lsb_nm
    n_ref = round(act.reference_delay_s / dt)
    ref = np.concatenate([np.zeros(n_ref), tau_des[: n - n_ref]]) if n_ref else tau_des
    rotor_prev = 0.0
    res = {k: np.empty(n) for k in ("est", "true", "sens", "thm", "cmd")}
    try:
        with np.errstate(over="raise", invalid="raise"):
            for k in range(n):
                if bends is not None and bends[k] != drive.bend:
                    drive.set_bend(float(bends[k]))
                ths = out[k]  # the output angle at the start of cycle k
                ths_next = out[k + 1] if k + 1 < n else ths
                v_s = (ths_next - ths) / dt
                th = drive.th
                if not (math.isfinite(th) and math.isfinite(drive.om)):
                    raise FloatingPointError
                # ---- sensing (start of the cycle): encoders and torque sensor at the same instant
                dth_meas = _quantise(th, q_s) - _quantise(ths, q_s)
                est = rtca.sensor_torque_nm(drive.tr, dth_meas, drive.bend)
                true = drive.output_torque(ths, v_s)
                res["thm"][k] = th
                rotor = _quantise(th * act.gear_ratio, q_m)
                om_meas = (rotor - rotor_prev) / dt / act.gear_ratio
                rotor_prev = rotor
                cmd = cascade.velocity_command(k, ref[k] - est)
                # ---- physics (output-referred rotor on the shaft), the output moving to out[k + 1]
                drive.advance(cascade.motor_torque(cmd, om_meas), ths, v_s)
                res["est"][k] = est
                res["true"][k] = true
                res["sens"][k] = round(true / lsb) * lsb if lsb > 0.0 else true
                res["cmd"][k] = cmd
    except (FloatingPointError, OverflowError):
        raise BenchError(
            f"seed-001 bench diverged at t = {k * dt:.3g} s (substeps = {act.substeps}, "
            f"core_segments = {act.core_segments}): raise substeps (1-100)"
        ) from None
    t: Array = np.arange(n, dtype=np.float64) * dt
    return BenchRun(
        t=t,
        tau_des=tau_des,
        tau_est=res["est"],
        tau_true=res["true"],
        tau_sensor=res["sens"],
        theta_m=res["thm"],
        theta_s=out,
        omega_cmd=res["cmd"],
        saturated=cascade.n_sat / n,
    )


def with_(act: Rtca001, **changes: object) -> Rtca001:
    """A copy of ``act`` with fields changed (checked)."""
    new = replace(act, **changes)  # type: ignore[arg-type]
    new.check()
    return new
