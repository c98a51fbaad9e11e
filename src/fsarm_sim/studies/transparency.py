"""Joint-3 torque-control bandwidth and output impedance vs bend, for any transmission.

Seed 001 (RTCA) characterises a remote compliant actuator by (i) the bandwidth of its torque loop
(Sec. 4.1.2: 6.22 Hz straight, falling to ~4.3 Hz at tight bends with fixed PID gains) and (ii)
its transparency: how little torque the output feels when a user moves it while the actuator is
commanded to zero torque (Sec. 4.2). Both are frequency responses of the simulated arm here:

* **Bandwidth** - :func:`fsarm_sim.studies.arm_metrics.torque_bandwidth` (held arm, log chirp of the
  desired shaft torque, H1 estimate, -3 dB point), repeated over bend angles.
* **Output impedance** - the arm is held as for the bandwidth (links on a huge armature, gravity
  off, outer position loops off, so joint 3's desired torque is exactly zero), and joint 3 is
  *moved from outside*: a generalized force ``M33 * qdd(t)`` on q3 imposes a log chirp of small
  amplitude (the transmission torque changes that acceleration by ~1e-5 relative). The
  impedance is the H1 estimate of ``Z(f) = tau_out / q3`` with ``tau_out = i_G2 tau`` the torque
  the transmission puts on the joint, in N*m/rad: its low-frequency value is the residual
  stiffness the torque loop leaves, ideally 0 (perfectly transparent); without control it is the
  transmission's own stiffness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import physics
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, check_duration
from fsarm_sim.studies.arm_metrics import (
    Bandwidth,
    check_band,
    frequency_response,
    held_arm,
    log_chirp,
    smoothstep,
    torque_bandwidth,
)

Array = npt.NDArray[np.float64]
DEFAULT_BENDS_DEG = (0.0, 30.0, 60.0, 90.0, 120.0)


@dataclass(frozen=True)
class Impedance:
    freq_hz: Array
    magnitude_nm_per_rad: Array  # |tau_out / q3| per band
    phase_deg: Array
    low_freq_nm_per_rad: float  # |Z| in the lowest band
    passive_nm_per_rad: float  # the transmission's own stiffness at the operating point, joint side


def chirp_motion(t: Array, amplitude: float, f0: float, f1: float, settle_s: float) -> Array:
    """Position offset: a log chirp over the whole of ``t``, faded in over ``settle_s``."""
    duration = float(t[-1]) if t.size > 1 else 1.0
    return amplitude * smoothstep(t, settle_s) * log_chirp(t, f0, f1, duration)


def output_impedance(
    config: SimConfig,
    bend_rad: float = math.radians(45.0),
    *,
    q3_rad: float = math.radians(45.0),
    f_start_hz: float = 0.5,
    f_stop_hz: float = 20.0,
    duration_s: float = 6.0,
    amplitude_rad: float = math.radians(1.0),
    control: bool = True,
    backend: Backend = DEFAULT_BACKEND,
) -> Impedance:
    """Joint-3 output impedance with the torque loop commanding zero torque (module docstring)."""
    check_band(f_start_hz, f_stop_hz)
    if not math.isfinite(amplitude_rad) or not 0.0 < amplitude_rad <= math.radians(10.0):
        raise InvalidParameterError(
            f"amplitude must be in (0, 10 deg] (a small-signal test), got {amplitude_rad!r} rad"
        )
    check_duration(duration_s)
    cfg = config.with_(effects=replace(config.effects, control=control))
    sim, m33, t, _ = held_arm(cfg, duration_s, bend_rad, q3_rad, backend)
    m, d, st = sim.model, sim.data, sim.structure
    dt = cfg.gains.ctrl_dt_s
    n = t.size
    settle = min(1.0, 0.2 * duration_s)
    pos = chirp_motion(t, amplitude_rad, f_start_hz, f_stop_hz, settle)
    acc = np.gradient(np.gradient(pos, dt), dt)
    steps = round(dt / m.opt.timestep)
    q3 = np.empty(n)
    tau = np.empty(n)
    prm = sim.params
    with callbacks.active(backend):
        for k in range(n):
            q3[k] = d.qpos[st.qadr[2]]
            tau[k] = physics.shaft_torque(prm, d.qpos, d.qvel, d.act)
            d.qfrc_applied[st.dof[2]] = m33 * acc[k]
            mujoco.mj_step(m, d, nstep=steps)
    sel = t >= settle
    tau_out = st.coef_s * tau
    f, H = frequency_response(q3[sel], tau_out[sel], 1.0 / dt, f_start_hz * 1.5, f_stop_hz / 1.5)
    mag = np.abs(H)
    tr = cfg.transmission_model()
    twist0 = float(np.mean(d.qpos[st.qadr[3]] * st.coef_m - st.coef_s * q3[sel]))
    k_passive = tr.stiffness(cfg.transmission_blocks()[0], twist0, bend_rad) * st.coef_s**2
    return Impedance(
        freq_hz=f,
        magnitude_nm_per_rad=mag,
        phase_deg=np.degrees(np.unwrap(np.angle(H))),
        low_freq_nm_per_rad=float(mag[0]) if mag.size else math.nan,
        passive_nm_per_rad=float(k_passive),
    )


@dataclass(frozen=True)
class BendPoint:
    bend_deg: float
    bandwidth: Bandwidth
    impedance: Impedance


def bend_note(config: SimConfig, bends_deg: tuple[float, ...]) -> str:
    """Why rows of a bend table repeat, where the transmission's law holds the bend's effect
    flat beyond some bend (the RTCA's mu, :func:`fsarm_sim.plant.transmissions.rtca.
    bend_held_from_rad`) and the table reaches past it; empty otherwise."""
    tr = config.transmission_model()
    held = getattr(tr.module, "bend_held_from_rad", None)
    if held is None:
        return ""
    limit_deg = math.degrees(held(tr.block(dict(config.transmission_params))))
    beyond = sorted(b for b in bends_deg if abs(b) >= limit_deg)
    if not beyond:
        return ""
    return (
        f"note: {tr.name}'s bend scaling mu (eq. 3-5) falls linearly with the curvature up to "
        f"|φ_B| = {limit_deg:.1f}° (R = 250 mm, the largest published loss) and is held there, "
        f"not extrapolated: the rows at {', '.join(f'{b:g}' for b in beyond)}° differ only by "
        "the bend-dependent friction and the arm's pose"
    )


def versus_bend(
    config: SimConfig,
    bends_deg: tuple[float, ...] = DEFAULT_BENDS_DEG,
    *,
    backend: Backend = "native",
    chirp_s: float = 4.0,
) -> list[BendPoint]:
    """Bandwidth and output impedance at each bend angle (joint 2 holds the bend)."""
    out = []
    for b in bends_deg:
        if not math.isfinite(b) or abs(b) > 120.0:
            raise InvalidParameterError(f"bend angles must be within +-120 deg, got {b!r}")
        rad = math.radians(b)
        bw = torque_bandwidth(config, rad, backend=backend, chirp_s=chirp_s)
        z = output_impedance(config, rad, backend=backend)
        out.append(BendPoint(b, bw, z))
    return out
