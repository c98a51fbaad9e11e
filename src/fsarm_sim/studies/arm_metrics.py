"""Arm-level metrics of one configuration (one sweep point).

* **Tracking** - a registered scenario (default ``fig14-sine``, seed 000 Fig. 14) run with
  :func:`fsarm_sim.sim.simulation.run_scenario`: joint RMSE / max error, peak joint-3 motor torque and
  speed, peak shaft torque, peak joint-2 torque. With ``bend_rad`` given, a scenario that holds
  joint 2 still (fig14-sine, step-q3) holds it at that angle instead - the shaft's bend.
* **Joint-3 torque-control bandwidth** (:func:`torque_bandwidth`) - the -3 dB frequency of
  ``tau_shaft / tau_d`` of the Fig. 13 loop (virtual torque sensor eq. 8 -> torque PID -> speed
  loop -> motor -> shaft) on the *held arm*. Method:

  1. The arm is held: every link joint (q1, q2, q3) gets a huge armature (``HOLD_ARMATURE``) and
     gravity is off, so the links do not move measurably (shaft torque x i_G2 / armature ~ 1e-5
     rad/s^2) while the motor rotor is free. Joint 2 holds the bend angle, joint 3 a mid pose.
  2. The outer position loops are off (``wn = 0``), so joint 3's outer loop outputs exactly the
     computed-torque feedforward ``tau_d,joint = M33 * qdd_ref``; ``qdd_ref`` is written as
     ``i_G2 * tau_d(t) / M33`` (M33 read from the compiled, held model). The *unchanged* control
     kernel (:func:`fsarm_sim.kernels.physics.control_tick`) therefore sees ``tau_d(t)`` at the shaft.
  3. ``tau_d`` = a bias (30 % of the shaft's rating, ramped in over ``settle_s``) plus a
     logarithmic chirp of 5 % of the rating from ``f_start`` to ``f_stop``. The bias keeps the
     twist on the winding side, where eq. 8 is linear, so a frequency response is meaningful.
  4. ``H(f) = S_yu / S_uu`` (cross- over auto-spectrum of ``y = tau_shaft`` and ``u = tau_d``,
     both from the run's log) is averaged in log-spaced bands; the bandwidth is the first
     frequency where ``|H|`` falls below ``1/sqrt(2)`` of the loop's static gain, which is 1
     (the torque PID integrates; the measured lowest-band gain is reported as ``low_gain``, it
     exceeds 1 by the PI zero's peaking). Linear interpolation in log f; NaN when ``|H|`` stays
     above the level up to the analysed top (``f_stop / 1.5``).

  ``tests/test_campaign.py`` checks the estimator on a first-order low-pass of known corner.
* **Joint-2 static torque relief** - the elastic bending moment of the shaft at 90 deg bend
  (``ShaftParams.static_relief_nm``; conduit branches relaxed, as in a static hold).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import (
    DEFAULT_BACKEND,
    Backend,
    Simulation,
    check_duration,
    compute_metrics,
    initial_state,
    run_scenario,
)

Array = npt.NDArray[np.float64]
HOLD_ARMATURE = 1.0e6  # kg*m^2 added to q1..q3 to hold the arm (estimate: >> link inertia ~1)
RELIEF_BEND_RAD = math.pi / 2.0  # upper arm horizontal: where gravity torque on joint 2 peaks
BANDS_PER_DECADE = 20


def scenario_holds_joint2(name: str, duration_s: float, ctrl_dt_s: float = 0.001) -> bool:
    """True if the scenario's joint-2 reference is constant (its pose defines the bend)."""
    return _holds_joint2(scenarios.get(name).reference, duration_s, ctrl_dt_s)


@functools.lru_cache(maxsize=256)
def _holds_joint2(reference: Callable[[Array], Array], duration_s: float, ctrl_dt_s: float) -> bool:
    """Cached per reference function (a sweep asks for every point; a scenario registered anew
    under the same name brings a new function, so a new answer)."""
    n = round(duration_s / ctrl_dt_s) + 1
    table = reference(np.arange(n, dtype=np.float64) * ctrl_dt_s)
    return bool(np.ptp(table[:, 1]) == 0.0 and np.all(table[:, 4] == 0.0))


def tracking(
    config: SimConfig,
    scenario: str = "fig14-sine",
    *,
    duration_s: float | None = None,
    payload_kg: float | None = None,
    bend_rad: float | None = None,
    backend: Backend = DEFAULT_BACKEND,
) -> dict[str, float]:
    """Run a scenario and return flat tracking / effort metrics (degrees, N*m, rad/s)."""
    sc = scenarios.get(scenario)
    duration = check_duration(sc.duration_s if duration_s is None else duration_s)
    if bend_rad is None:
        res = run_scenario(
            scenario,
            config,
            duration_s=duration,
            payload_kg=payload_kg,
            backend=backend,
            log_every_ticks=1,
        )
        metrics, cfg = res.metrics, res.config
    else:
        if not scenario_holds_joint2(scenario, duration, config.gains.ctrl_dt_s):
            raise InvalidParameterError(
                f"scenario '{scenario}' moves joint 2, so its bend angle cannot be set; "
                "a bend angle can be given only for scenarios that hold joint 2 (e.g. fig14-sine, step-q3)"
            )
        cfg = config.with_(payload_kg=sc.payload_kg if payload_kg is None else payload_kg)
        n = round(duration / cfg.gains.ctrl_dt_s) + 1
        table = sc.table(n, cfg.gains.ctrl_dt_s)
        table[:, 1] = bend_rad
        sim = Simulation(cfg, table, backend)
        # no rows recorded: the kernel's accumulators cover every physics step, as run_scenario's
        # metrics do (the recorded rows would sample once per control tick)
        cols, wall = sim.run(duration, log_every_ticks=0)
        metrics = compute_metrics(
            cols,
            duration,
            wall,
            sim.structure,
            cfg.rating_nm(),
            acc=sim.data.userdata[layout.U_ACC :],
        )
    rmse, mx = metrics["rmse_deg"], metrics["max_abs_err_deg"]
    assert isinstance(rmse, dict) and isinstance(mx, dict)
    out = {f"{j}_rmse_deg": rmse[j] for j in ("q1", "q2", "q3")}
    out.update({f"{j}_max_abs_err_deg": mx[j] for j in ("q1", "q2", "q3")})
    for key in (
        "peak_motor_torque_nm",
        "peak_motor_speed_rad_s",
        "peak_shaft_torque_nm",
        "peak_twist_rad",
        "peak_tau2_nm",
        "tau_estimate_rmse_nm",
        "motor_energy_j",
    ):
        value = metrics[key]
        assert isinstance(value, float)
        out[key] = value
    out["payload_kg"] = cfg.payload_kg
    return out


@dataclass(frozen=True)
class Bandwidth:
    bandwidth_hz: float  # -3 dB frequency of tau_shaft / tau_d (NaN: none below f_stop / 1.5)
    low_gain: float  # |H| in the lowest analysed band
    freq_hz: Array  # band centres
    gain: Array  # |H| per band
    phase_deg: Array


def log_chirp(t: Array, f_start: float, f_stop: float, duration_s: float) -> Array:
    """sin of a logarithmic sweep: instantaneous frequency f_start (f_stop/f_start)^(t/T)."""
    ratio = f_stop / f_start
    k = math.log(ratio)
    return np.sin(
        2.0 * math.pi * f_start * duration_s / k * (np.power(ratio, t / duration_s) - 1.0)
    )


def frequency_response(
    u: Array,
    y: Array,
    fs_hz: float,
    f_lo: float,
    f_hi: float,
    bands_per_decade: int = BANDS_PER_DECADE,
) -> tuple[Array, Array]:
    """Band-averaged H1 estimate ``sum(Y conj(U)) / sum(|U|^2)`` in log-spaced bands."""
    u = np.asarray(u, dtype=np.float64) - np.mean(u)
    y = np.asarray(y, dtype=np.float64) - np.mean(y)
    win = np.hanning(u.size)
    U = np.fft.rfft(u * win)
    Y = np.fft.rfft(y * win)
    f = np.fft.rfftfreq(u.size, 1.0 / fs_hz)
    n_bands = max(2, math.ceil(math.log10(f_hi / f_lo) * bands_per_decade))
    edges = np.geomspace(f_lo, f_hi, n_bands + 1)
    centres, H = [], []
    for a, b in itertools.pairwise(edges):
        sel = (f >= a) & (f < b)
        suu = float(np.sum(np.abs(U[sel]) ** 2))
        if not np.any(sel) or suu == 0.0:
            continue
        centres.append(math.sqrt(a * b))
        H.append(complex(np.sum(Y[sel] * np.conj(U[sel]))) / suu)
    return np.asarray(centres), np.asarray(H, dtype=np.complex128)


def minus_3db(freq: Array, gain: Array, static_gain: float = 1.0) -> float:
    """First frequency where ``gain`` falls below ``static_gain / sqrt(2)`` (log-f interpolation).

    NaN if it never does, or already does in the first band (the chirp starts too high)."""
    level = static_gain / math.sqrt(2.0)
    below = np.flatnonzero(gain < level)
    if freq.size < 2 or below.size == 0 or below[0] == 0:
        return math.nan
    i = int(below[0])
    la, lb = math.log(freq[i - 1]), math.log(freq[i])
    ga, gb = float(gain[i - 1]), float(gain[i])
    x = (ga - level) / (ga - gb) if ga != gb else 0.0
    return math.exp(la + x * (lb - la))


def smoothstep(t: Array, settle_s: float) -> Array:
    """0 -> 1 over ``settle_s`` with zero slope at both ends (a bumpless fade-in)."""
    ramp = np.clip(t / settle_s, 0.0, 1.0)
    return ramp * ramp * (3.0 - 2.0 * ramp)


def check_band(f_start_hz: float, f_stop_hz: float) -> None:
    if not 0.0 < f_start_hz < f_stop_hz:
        raise InvalidParameterError(
            f"need 0 < f_start < f_stop, got {f_start_hz!r}, {f_stop_hz!r} Hz"
        )


def held_arm(
    config: SimConfig, duration_s: float, bend_rad: float, q3_rad: float, backend: Backend
) -> tuple[Simulation, float, Array, Array]:
    """The arm held for a joint-3 frequency response (steps 1-2 of the module docstring): outer
    position loops off, no payload, gravity off, every link joint on :data:`HOLD_ARMATURE`,
    joint 2 at ``bend_rad`` and joint 3 at ``q3_rad``. Returns the simulation, joint 3's (held)
    inertia M33, the tick times and the reference table (write joint 3's ``qdd_ref`` column
    into the model's reference to command a desired torque)."""
    cfg = config.with_(gains=replace(config.gains, wn_rad_s=(0.0, 0.0, 0.0)), payload_kg=0.0)
    dt = cfg.gains.ctrl_dt_s
    n = round(duration_s / dt) + 1
    t = np.arange(n, dtype=np.float64) * dt
    table = np.zeros((n, layout.REF_COLS))
    table[:, 1] = bend_rad
    table[:, 2] = q3_rad
    sim = Simulation(cfg, table, backend)
    m, d, st = sim.model, sim.data, sim.structure
    m.opt.gravity[:] = 0.0
    for j in range(3):
        m.dof_armature[st.dof[j]] += HOLD_ARMATURE
    initial_state(m, d, st)
    mujoco.mj_forward(m, d)  # no callbacks installed here: only the mass matrix is wanted
    return sim, float(d.M[st.madr[2]]), t, table


def torque_bandwidth(
    config: SimConfig,
    bend_rad: float = math.radians(45.0),
    *,
    q3_rad: float = math.radians(45.0),
    f_start_hz: float = 0.5,
    f_stop_hz: float = 60.0,
    chirp_s: float = 4.0,
    settle_s: float = 0.5,
    bias_fraction: float = 0.3,
    amplitude_fraction: float = 0.05,
    backend: Backend = DEFAULT_BACKEND,
) -> Bandwidth:
    """Joint-3 torque-loop bandwidth on the held arm (method in the module docstring)."""
    for name, v in (("chirp_s", chirp_s), ("settle_s", settle_s)):
        if not math.isfinite(v) or v <= 0.0:
            raise InvalidParameterError(f"{name} must be > 0 s, got {v!r}")
    check_band(f_start_hz, f_stop_hz)
    dt = config.gains.ctrl_dt_s
    if f_stop_hz > 0.25 / dt:
        raise InvalidParameterError(
            f"f_stop {f_stop_hz:g} Hz is above a quarter of the control rate {1.0 / dt:g} Hz"
        )
    check_duration(settle_s + chirp_s)
    rating = config.rating_nm()
    if rating <= 0.0:
        raise InvalidParameterError(
            "joint 3's transmission has no torque rating; cannot size the chirp"
        )
    sim, m33, t, table = held_arm(config, settle_s + chirp_s, bend_rad, q3_rad, backend)
    m, d, st = sim.model, sim.data, sim.structure
    smooth = smoothstep(t, settle_s)
    tc = np.clip(t - settle_s, 0.0, None)
    chirp = np.where(t >= settle_s, log_chirp(tc, f_start_hz, f_stop_hz, chirp_s), 0.0)
    tau_d = rating * (bias_fraction * smooth + amplitude_fraction * chirp)
    table[:, 8] = st.coef_s * tau_d / m33
    ref = m.numeric(layout.REF_NAME).data
    ref[:] = table.ravel()
    initial_state(m, d, st)
    cols, _ = sim.run(settle_s + chirp_s)
    sel = cols["t"] >= settle_s - 1e-12
    u, y = cols["tau_d_shaft"][sel], cols["tau_shaft"][sel]
    if np.any(np.diff(np.sign(cols["twist"][sel])) != 0):
        raise InvalidParameterError(
            "the twist changed sign during the bandwidth chirp (the transmission's law changes "
            "branch there); "
            "lower amplitude_fraction or raise bias_fraction"
        )
    f, H = frequency_response(u, y, 1.0 / dt, f_start_hz * 1.5, f_stop_hz / 1.5)
    gain = np.abs(H)
    return Bandwidth(
        bandwidth_hz=minus_3db(f, gain, 1.0),
        low_gain=float(gain[0]) if gain.size else math.nan,
        freq_hz=f,
        gain=gain,
        phase_deg=np.degrees(np.unwrap(np.angle(H))),
    )


def static_relief_nm(config: SimConfig, bend_rad: float = RELIEF_BEND_RAD) -> float:
    """Joint-2 static torque relief of the bent shaft (elastic moment, conduit relaxed)."""
    return float(config.shaft.static_relief_nm(bend_rad))
