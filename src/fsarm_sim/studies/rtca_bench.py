"""Seed 001's own actuator on a single-joint bench: motor, gearbox, encoders and cascade.

Source: /work/shared/seeds/001_874b1e7feae8d04a.txt (Rodriguez-Cianca et al., RTCA,
Mechatronics 2019). The arm's joint-3 loop answers a different question (a faster controller
on a different motor); this bench is the RTCA as the paper built and ran it, so its torque
tracking (Sec. 4.1.1), torque bandwidth vs bend (Sec. 4.1.2) and output transparency (Sec. 4.2)
can be compared number to number. It is an ODE integrated here (no MuJoCo: one rotor, one shaft,
a blocked or position-driven output), referred to the gearbox output, with semi-implicit Euler
steps (``substeps`` per 1 ms control cycle; the rotor-on-shaft mode is at about 2.5 Hz, the
velocity loop at ``velocity_bw_hz``).

Experiments: :func:`tracking` (Sec. 4.1.1, Fig. 9), :func:`torque_bandwidth` (Sec. 4.1.2,
Fig. 10), :func:`output_impedance` and :func:`fig12` (Sec. 4.2.1, Fig. 12, per band),
:func:`ziegler_nichols`, :func:`calibrate_reference_delay` and :func:`calibrate_kp` (the
control). ``fsarm reproduce --paper 001`` runs them; ``fsarm rtca-fig12`` prints Fig. 12.

What the paper gives (Sec. 2.2, 2.3, 4.1.1):

* motor + gearbox: Maxon EC-4pole 30 (200 W) with an 86:1 GP 32HP; "continuous torque of up to
  8 Nm at a continuous speed of 192 rpm, with intermittent torques up to 12 Nm" - the velocity
  set-point is limited to 192 rpm and the motor torque to 12 N*m (gearbox output);
* sensing: a 500 CPT encoder on the motor (the EPOS3's velocity feedback) and two 2000 CPT
  optical encoders (US Digital E6) on both ends of the shaft: ``Δθ = θ_m - θ_s``; the DRBK20
  torque sensor (20 N*m range, read by a +-10 V EL3102) measures the truth the estimate is
  compared with;
* the cascade (Fig. 8): an EPOS3 velocity loop at 1 kHz and an outer PID torque loop at the same
  1 kHz on the estimate ``T̂_s(Δθ, R)`` of eq. 3; the outer loop runs on the EtherCAT master and
  sends the velocity set-point to the EPOS3 over the bus;
* the shaft: Table 1's law with the bend scaling mu of eq. 3
  (:mod:`fsarm_sim.plant.transmissions.rtca`, the simulator's one implementation of it).

What it does not give, and the estimates used here (each a field of :class:`Rtca001`):

* quadrature: CPT is counted per channel (maxon, US Digital); the EPOS3 and the EL5101 decode
  4 edges per count, so 2000 and 8000 increments per turn (**estimate**, the usual decoding);
* rotor inertia: 33.3 g*cm² (EC-4pole 30, 200 W, maxon catalogue) + 0.8 g*cm² (GP 32 HP
  three-stage): **estimate, recalled catalogue values** (the paper gives none); 86² times that at
  the gearbox output;
* EPOS3 velocity loop: a PI on the encoder-differenced rotor speed, tuned for a closed-loop
  bandwidth ``velocity_bw_hz`` (**estimate**; the paper does not print its gains);
* the bus: the set-point computed in one 1 ms cycle acts in the next (**estimate**: one EtherCAT
  cycle between master and drive); ``transport_delay_s`` adds dead time there (0 by default);
* PID gains: "manually tuned using the Ziegler-Nichols method" (Sec. 4.1.1), not printed. The
  paper's procedure runs on the bench (:func:`ziegler_nichols`: raise a P gain until the loop
  keeps oscillating, then the classic table 0.6 Ku, Ti = Tu/2, Td = Tu/8) - the gains are a
  result of the procedure, not chosen (:func:`paper_controllers`);
* the 25 ms offset (Sec. 4.1.1): the ZN loop itself lags < 1 ms at 1 Hz, and dead time inside
  the loop does not make it lag (ZN re-tuned with 5-25 ms of transport delay: the offset stays
  at -1 to +4 ms while the RMSE grows to 0.9 N*m). The paper's estimate and sensor agree to
  0.0456 N*m, so both lag the set-point alike: the delay is between the logged set-point and the
  loop (``reference_delay_s``: the set-point reaches the torque loop that much after it is
  logged), outside the feedback. It is **calibrated** on the 25 ms
  (:func:`calibrate_reference_delay`: 26 ms with the ZN gains). A pure 25 ms delay of a 6 N*m,
  1 Hz sine alone is 0.666 N*m RMSE; the RMSE (0.7334), the estimate error, the symmetry and
  the bandwidths are then predictions. The earlier P loop calibrated on the offset
  (:func:`calibrate_kp`, :data:`CALIBRATION`) stays as an option ("P" in Fig. 12's table);
* the load motor of Sec. 4.2 (Maxon DCX35L GBKL, 18 V, 80 W, 113:1) in position mode:
  :class:`LoadServo`, a speed-limited first-order position servo (113:1 from the paper; the
  motor's speed, 7000 rpm, and its 20 Hz position bandwidth are **estimates**: 6.5 rad/s at the
  output, while the 20° chirp needs 21.9 rad/s at 10 Hz - and the RTCA's own motor 20.1 rad/s,
  Sec. 2.2's 192 rpm); ``load=None`` is an ideal position source;
* the multisine of Sec. 4.1.2 (lines, phases, period) and the chirp of Sec. 4.2.1 (sweep law,
  duration): **estimates**, named in :func:`multisine`, :func:`torque_bandwidth` and
  :func:`output_impedance` (the load motor: :class:`LoadServo`);
* the shaft's unmodelled residual: the paper's model misses the measured torque by NRMSE 0.32 %
  straight and 2.3 % at R = 150 mm (Sec. 3.3; over the +-5 N*m characterisation span). The true
  shaft carries it as the RTCA transmission's own bend-dependent friction element (a Maxwell-slip
  state, slip torque ``0.032 N*m * exp(1.16 |phi_B|)``: see
  :mod:`fsarm_sim.plant.transmissions.rtca`); the estimate does not see it - the paper's
  "friction increase within the internal layers" (Sec. 3.1, 6.1). ``residual_friction=False``
  switches it off. Where it acts (``friction_site``):

  - ``"twist"`` (default): across the twist, end to end, as the transmission has it on the arm;
  - ``"core"``: the core rubbing on its casing. The core is ``core_segments`` equal segments
    (2 by default; each the law at that many times its twist) joined at nodes that share its
    inertia (``core_inertia_kgm2``: a solid 8 mm steel core 865 mm long, 2.7e-6 kg*m²,
    **estimate**, an upper bound for a wound core) and its friction against the casing (ground),
    twice the transmission's slip torque in all (the output end carries about half of it: the
    same residual at the sensor); more segments need more ``substeps`` (4 segments: 20), and a
    run that diverges is a :class:`BenchError`. The encoders see the core's twist end to end.
    Measured: the load feels the friction (ZN PID, 20° sine at 1.2 s: 0.028 -> 0.053 N*m RMS
    straight -> R = 200 mm) but T̂ does not follow (0.0037 -> 0.0038 N*m): with a velocity-
    sourced motor T̂ is set by the loop and the output's motion, wherever the friction sits
    (the knee walking profile, default gains: max |T̂| 0.078 -> 0.081 N*m straight -> 200 mm with
    the friction across the twist, on 2 or on 4 core segments alike, while the sensor's max
    reads 0.109 -> 0.116, 0.085 -> 0.202 and 0.083 -> 0.181 N*m);
    and its stick-slip sets the ZN probe's oscillation (Tu 25 ms instead of 72 ms) - so it is an
    option, not the default.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim.studies.rtca_actuator import NRMSE_R150 as NRMSE_R150
from fsarm_sim.studies.rtca_actuator import NRMSE_STRAIGHT as NRMSE_STRAIGHT
from fsarm_sim.studies.rtca_actuator import Array, CArray
from fsarm_sim.studies.rtca_actuator import BenchError as BenchError
from fsarm_sim.studies.rtca_actuator import Pid as Pid
from fsarm_sim.studies.rtca_actuator import Rtca001 as Rtca001
from fsarm_sim.studies.rtca_actuator import bend_of as bend_of
from fsarm_sim.studies.rtca_actuator import run as run
from fsarm_sim.studies.rtca_actuator import with_ as with_
from fsarm_sim.studies.rtca_tracking import CALIBRATION as CALIBRATION
from fsarm_sim.studies.rtca_tracking import LoadServo as LoadServo
from fsarm_sim.studies.rtca_tracking import Tracking as Tracking
from fsarm_sim.studies.rtca_tracking import ZieglerNichols as ZieglerNichols
from fsarm_sim.studies.rtca_tracking import calibrate_kp as calibrate_kp
from fsarm_sim.studies.rtca_tracking import calibrate_reference_delay as calibrate_reference_delay
from fsarm_sim.studies.rtca_tracking import load_motion as load_motion
from fsarm_sim.studies.rtca_tracking import tracking as tracking
from fsarm_sim.studies.rtca_tracking import ziegler_nichols as ziegler_nichols


def multisine(
    t: Array,
    peak_nm: float,
    f_lo: float = 0.1,
    f_hi: float = 10.0,
    period_s: float = 10.0,
    seed: int = 1,
) -> Array:
    """Sec. 4.1.2's set-point: a flat-spectrum multisine, ``f_lo``..``f_hi``, scaled to ``peak``.

    Lines every ``1 / period_s``; random phases (the paper gives neither; **estimate**: MATLAB
    idinput's multisine uses random phases)."""
    f = np.arange(1, round(f_hi * period_s) + 1) / period_s
    f = f[f >= f_lo - 1e-12]
    ph = np.random.default_rng(seed).uniform(0.0, 2.0 * math.pi, f.size)
    x = np.zeros_like(t)
    for fk, p in zip(f, ph, strict=True):
        x += np.cos(2.0 * math.pi * fk * t + p)
    return peak_nm * x / float(np.max(np.abs(x)))


@dataclass(frozen=True)
class TorqueBandwidth:
    freq_hz: Array
    response: CArray  # complex T_est / T_des at the multisine's lines
    fit: tuple[float, ...]  # (b1, b0, a1, a0): G(s) = (b1 s + b0) / (s^2 + a1 s + a0)
    fit_pct: float  # 100 (1 - ||H - G|| / ||H - mean H||), MATLAB's "fit" measure
    bandwidth_hz: float  # -3 dB of the fitted G below its static gain
    saturated: float


def fit_second_order(
    w: Array, h: CArray, iterations: int = 20
) -> tuple[tuple[float, float, float, float], float]:
    """Least-squares fit of ``(b1 s + b0) / (s^2 + a1 s + a0)`` to ``h`` at ``s = j w``
    (Sanathanan-Koerner iterations); returns the coefficients and the fit in %."""
    s = 1j * w
    weight = np.ones_like(w)
    theta = np.zeros(4)
    for _ in range(iterations):
        # h (s^2 + a1 s + a0) = b1 s + b0  ->  linear in (b1, b0, a1, a0)
        cols = np.stack([s, np.ones_like(s), -h * s, -h], axis=1) / weight[:, None]
        rhs = h * s**2 / weight
        a = np.vstack([cols.real, cols.imag])
        b = np.concatenate([rhs.real, rhs.imag])
        theta = np.linalg.lstsq(a, b, rcond=None)[0]
        weight = np.abs(s**2 + theta[2] * s + theta[3])
        weight = np.maximum(weight, 1e-9)
    b1, b0, a1, a0 = (float(v) for v in theta)
    g = (b1 * s + b0) / (s**2 + a1 * s + a0)
    fit = 100.0 * (1.0 - float(np.linalg.norm(h - g) / np.linalg.norm(h - np.mean(h))))
    return (b1, b0, a1, a0), fit


def _fitted_bandwidth(coef: tuple[float, ...], f_max: float = 100.0) -> float:
    b1, b0, a1, a0 = coef
    f = np.linspace(0.0, f_max, 100001)
    s = 2j * math.pi * f
    g = np.abs((b1 * s + b0) / (s**2 + a1 * s + a0))
    below = np.flatnonzero(g < g[0] / math.sqrt(2.0))
    return float(f[below[0]]) if below.size else math.inf


def torque_bandwidth(
    act: Rtca001,
    pid: Pid,
    *,
    radius_m: float = math.inf,
    peak_nm: float = 5.0,
    periods: int = 2,
    period_s: float = 10.0,
    realizations: int = 4,
) -> TorqueBandwidth:
    """Sec. 4.1.2: multisine 0.1-10 Hz of peak ``peak_nm`` on the torque loop, output blocked;
    ``G(s) = T_est(s) / T_des(s)`` fitted with a second-order transfer function (the paper's
    'second order transfer functions ... MATLAB's system identification toolbox'); the
    bandwidth is its -3 dB point.

    The response is the best linear approximation over ``realizations`` random-phase multisines
    (seeds 1..M; the sum of ``Y conj(U)`` over the sum of ``|U|²`` at each line), so that it
    does not hang on one draw of phases; in each run the first period is discarded."""
    if periods < 2 or realizations < 1:
        raise BenchError("at least two periods (the first is discarded) and one realization")
    dt = act.ctrl_dt_s
    n = round(period_s / dt)
    t: Array = np.arange(periods * n, dtype=np.float64) * dt
    k = (periods - 1) * np.arange(1, round(10.0 * period_s) + 1)  # FFT bins of the lines
    lines = k / ((periods - 1) * n * dt)
    keep = lines >= 0.1 - 1e-9
    syu = np.zeros(int(np.sum(keep)), dtype=np.complex128)
    suu = np.zeros(int(np.sum(keep)))
    sat = 0.0
    for seed in range(1, realizations + 1):
        u = multisine(t, peak_nm, period_s=period_s, seed=seed)
        r = run(act, pid, u, radius_m=radius_m)
        spec_u, spec_y = np.fft.rfft(u[n:]), np.fft.rfft(r.tau_est[n:])
        syu += spec_y[k[keep]] * np.conj(spec_u[k[keep]])
        suu += np.abs(spec_u[k[keep]]) ** 2
        sat += r.saturated / realizations
    h = syu / suu
    f = lines[keep]
    coef, fit = fit_second_order(2.0 * math.pi * f, h)
    return TorqueBandwidth(f, h, coef, fit, _fitted_bandwidth(coef), sat)


def _band_response(
    u: Array, y: Array, dt: float, f_lo: float, f_hi: float, per_decade: int = 10
) -> tuple[Array, Array]:
    """Band-averaged ``sum(Y conj U) / sum(|U|^2)`` in log-spaced bands, no window (a chirp
    sweeps its band once: a window would cut its first and last frequencies out)."""
    spec_u, spec_y = np.fft.rfft(u), np.fft.rfft(y)
    freq = np.fft.rfftfreq(u.size, dt)
    edges = np.geomspace(f_lo, f_hi, max(2, math.ceil(math.log10(f_hi / f_lo) * per_decade)) + 1)
    centres, out = [], []
    for a, b in itertools.pairwise(edges):
        sel = (freq >= a) & (freq < b)
        suu = float(np.sum(np.abs(spec_u[sel]) ** 2))
        if suu > 0.0:
            centres.append(math.sqrt(a * b))
            out.append(complex(np.sum(spec_y[sel] * np.conj(spec_u[sel]))) / suu)
    return np.asarray(centres), np.asarray(out, dtype=np.complex128)


def _peak_hz(f: Array, mag: Array) -> float:
    """Frequency of the largest ``mag``: a parabola through log|Z| over log f at the largest
    band and its two neighbours (the bands are a tenth of a decade wide)."""
    i = int(np.argmax(mag))
    if i == 0 or i == mag.size - 1:
        return float(f[i])
    x = np.log(f[i - 1 : i + 2])
    y = np.log(mag[i - 1 : i + 2])
    c2, c1, _ = np.polyfit(x, y, 2)
    return float(math.exp(-c1 / (2.0 * c2))) if c2 < 0.0 else float(f[i])


def _check_output_amplitude(amplitude_rad: float, name: str) -> None:
    """The load's motion imposed on the output: finite, in (0, pi] rad."""
    if not (math.isfinite(amplitude_rad) and 0.0 < amplitude_rad <= math.pi):
        raise BenchError(f"{name} must be in (0, pi] rad, got {amplitude_rad!r}")


@dataclass(frozen=True)
class OutputImpedance:
    freq_hz: Array
    magnitude: Array  # |Z| = |T_est / theta_s'|, N*m*s/rad
    level: float  # geometric mean of |Z| over the bands
    peak_hz: float  # frequency of the largest |Z| (interpolated between bands)
    interaction_rms_nm: float  # RMS of the sensor torque the load feels
    saturated: float


def output_impedance(
    act: Rtca001,
    pid: Pid,
    *,
    radius_m: float = math.inf,
    amplitude_rad: float = math.radians(20.0),
    f_lo: float = 0.1,
    f_hi: float = 10.0,
    duration_s: float = 60.0,
    load: LoadServo | None = None,
    per_decade: int = 10,
) -> OutputImpedance:
    """Sec. 4.2.1 / Fig. 11-12: the load motor (position mode: ``load``, ideal if None) moves
    the output through a chirp of 20° from 0.1 to 10 Hz; the torque loop holds 0 N*m; the paper's
    ``Z(s) = T̂_s(s) / θ̇_s(s)`` from the estimate and the output speed. The sweep is
    logarithmic over ``duration_s`` (**estimate**: the paper gives neither the sweep law nor the
    duration; a log sweep spends as long on each decade, so 0.1-1 Hz is resolved too)."""
    _check_output_amplitude(amplitude_rad, "chirp amplitude")
    if not 2 <= per_decade <= 50:
        raise BenchError(f"per_decade must be 2-50 bands per decade, got {per_decade!r}")
    if not (0.0 < f_lo < f_hi) or not math.isfinite(f_hi) or duration_s < 2.0 / f_lo:
        raise BenchError("need 0 < f_lo < f_hi and a duration of at least two periods of f_lo")
    dt = act.ctrl_dt_s
    t: Array = np.arange(round(duration_s / dt), dtype=np.float64) * dt
    rate = math.log(f_hi / f_lo) / duration_s
    phase = 2.0 * math.pi * f_lo * np.expm1(rate * t) / rate
    fade = np.clip(t / (1.0 / f_lo), 0.0, 1.0)
    ths = load_motion(load, amplitude_rad * fade * np.sin(phase), dt)
    r = run(act, pid, np.zeros_like(t), radius_m=radius_m, theta_s=ths)
    vel = np.gradient(ths, dt)  # the output encoder's speed: what the load really did
    t_fade = 1.0 / f_lo
    sel = t >= t_fade
    # the bands start where the analysed part of the sweep starts (the fade-in is cut away, and
    # the sweep has passed f_lo by then): a band below it holds only leakage
    f_start = f_lo * math.exp(rate * t_fade)
    f, h = _band_response(vel[sel], r.tau_est[sel], dt, 1.2 * f_start, f_hi / 1.2, per_decade)
    mag = np.abs(h)
    # the peak from tenth-decade bands whatever the table's width (a parabola needs neighbours)
    f10, h10 = _band_response(vel[sel], r.tau_est[sel], dt, 1.2 * f_start, f_hi / 1.2, 10)
    return OutputImpedance(
        freq_hz=f,
        magnitude=mag,
        level=float(np.exp(np.mean(np.log(mag)))),
        peak_hz=_peak_hz(f10, np.abs(h10)),
        interaction_rms_nm=float(np.sqrt(np.mean(r.tau_sensor[sel] ** 2))),
        saturated=r.saturated,
    )


@dataclass(frozen=True)
class Interaction:
    felt_rms_nm: float  # RMS of the torque sensor: what the load feels
    estimate_rms_nm: float  # RMS of T̂_s: what the loop (and Z = T̂/θ̇_s) sees


def interaction(
    act: Rtca001,
    pid: Pid,
    *,
    radius_m: float = math.inf,
    amplitude_rad: float = math.radians(20.0),
    period_s: float = 1.2,
    periods: int = 4,
    load: LoadServo | None = None,
) -> Interaction:
    """The torque between load and actuator in transparent mode (set-point 0) while the load
    moves the output through a sine of ``period_s`` (Sec. 4.2.2 imposes human joint profiles at
    1.2 s per stride; the profiles are only in a figure, so this is a stand-in of the stride's
    period and the chirp's 20°, **not** the paper's motion). The first period is faded in and
    not analysed."""
    _check_output_amplitude(amplitude_rad, "amplitude")
    if not (math.isfinite(period_s) and 0.1 <= period_s <= 100.0) or periods < 2:
        raise BenchError("period must be in [0.1, 100] s, and at least two periods run")
    dt = act.ctrl_dt_s
    t: Array = np.arange(round(periods * period_s / dt), dtype=np.float64) * dt
    ref = amplitude_rad * np.clip(t / period_s, 0.0, 1.0) * np.sin(2.0 * math.pi * t / period_s)
    r = run(act, pid, np.zeros_like(t), radius_m=radius_m, theta_s=load_motion(load, ref, dt))
    sel = t >= period_s
    return Interaction(
        felt_rms_nm=float(np.sqrt(np.mean(r.tau_sensor[sel] ** 2))),
        estimate_rms_nm=float(np.sqrt(np.mean(r.tau_est[sel] ** 2))),
    )


# ------------------------------------------------------------------------ Fig. 12 per band


@dataclass(frozen=True)
class Fig12Row:
    """One controller at one bend: ``|T̂_s/θ̇_s|`` per band (the paper's Z, Sec. 4.2.1)."""

    controller: str
    radius_m: float
    freq_hz: Array
    magnitude: Array  # N*m*s/rad per band
    peak_hz: float
    saturated: float

    def side(self, below: bool) -> npt.NDArray[np.intp]:
        """Indices of the bands below (or above) this row's peak."""
        return np.flatnonzero(self.freq_hz < self.peak_hz if below else self.freq_hz > self.peak_hz)


@dataclass(frozen=True)
class Fig12:
    """Seed 001 Fig. 12 on the bench: rows per controller and bend, the same bands in each."""

    rows: tuple[Fig12Row, ...]

    def by(self, controller: str) -> list[Fig12Row]:
        return [r for r in self.rows if r.controller == controller]

    def rise_below_peak(self, controller: str) -> dict[str, list[float]]:
        """``{band: |Z| at each bend}`` for the bands below the straight shaft's peak that lie
        below every bend's peak (the paper's 'transparency decreased as the bend radius was
        reduced', read band by band)."""
        rows = self.by(controller)
        top = min(r.peak_hz for r in rows)
        f = rows[0].freq_hz
        return {
            f"{fk:.2g} Hz": [float(r.magnitude[i]) for r in rows]
            for i, fk in enumerate(f)
            if fk < top
        }

    def table(self) -> str:
        """The table as text: one column per controller and bend, one line per band."""
        head = ["f [Hz]"] + [
            f"{r.controller} {'straight' if math.isinf(r.radius_m) else f'{1000 * r.radius_m:g}'}"
            for r in self.rows
        ]
        lines = [" | ".join(f"{h:>12}" for h in head)]
        for i, fk in enumerate(self.rows[0].freq_hz):
            lines.append(
                " | ".join([f"{fk:>12.3g}"] + [f"{r.magnitude[i]:>12.4f}" for r in self.rows])
            )
        lines.append(
            " | ".join([f"{'peak [Hz]':>12}"] + [f"{r.peak_hz:>12.2f}" for r in self.rows])
        )
        return "\n".join(lines)


def fig12(
    act: Rtca001,
    controllers: dict[str, Pid],
    radii_m: tuple[float, ...] = (math.inf, 0.450, 0.200),
    *,
    load: LoadServo | None = None,
    duration_s: float = 60.0,
    per_decade: int = 5,
    f_lo: float = 0.1,
    f_hi: float = 10.0,
) -> Fig12:
    """Seed 001 Fig. 12: ``|T̂_s/θ̇_s|`` of each controller at each bend radius, per band
    (``per_decade`` log bands), from :func:`output_impedance`'s 20° chirp driven by ``load``."""
    if not controllers or not radii_m:
        raise BenchError("Fig. 12 needs at least one controller and one bend radius")
    rows = []
    for name, pid in controllers.items():
        for r in radii_m:
            z = output_impedance(
                act,
                pid,
                radius_m=r,
                load=load,
                duration_s=duration_s,
                per_decade=per_decade,
                f_lo=f_lo,
                f_hi=f_hi,
            )
            rows.append(Fig12Row(name, r, z.freq_hz, z.magnitude, z.peak_hz, z.saturated))
    return Fig12(tuple(rows))


def paper_controllers(target_offset_ms: float | None = None) -> tuple[Rtca001, dict[str, Pid]]:
    """The bench with seed 001's control (Sec. 4.1.1) and the P option.

    ``PID``: the classic Ziegler-Nichols table from the bench's ultimate gain and period, with
    the set-point delay calibrated so that the 1 Hz run lags ``target_offset_ms``; ``P``: the
    P gain calibrated on the same offset without a set-point delay (:func:`calibrate_kp`). The
    returned bench carries the PID's set-point delay (it does not act when the set-point is 0,
    as in Fig. 12). ``None``: the offset of calibration claim 001-torque-tracking-offset."""
    if target_offset_ms is None:
        from fsarm_sim.studies.reproduce.targets import claim_value

        target_offset_ms = claim_value("001-torque-tracking-offset")
    act = Rtca001()
    pid = ziegler_nichols(act).pid
    delay = calibrate_reference_delay(act, pid, target_offset_ms)
    p = Pid(calibrate_kp(act, target_offset_ms), 0.0, 0.0)
    return with_(act, reference_delay_s=delay), {"P": p, "PID": pid}
