"""Seed 001 on its own bench (Sec. 4, :mod:): torque tracking, torque bandwidth vs bend, Fig. 12
transparency, Ziegler-Nichols.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fsarm_sim.studies.reproduce.claims import Context, Measured

BEND_LENGTH_M = 0.255  # seed 001 Sec. 5.1: L = φ R with the bend length of its knee set-up
R_BANDWIDTH_M = (math.inf, 0.450, 0.300, 0.150)  # Sec. 4.1.2 (results)
R_IMPEDANCE_M = (math.inf, 0.450, 0.200)  # Sec. 4.2.1
R_CHARACTERISATION_M = (math.inf, 0.450, 0.350, 0.250, 0.150)  # Sec. 3.2


def bend_of_radius(r_m: float) -> float:
    return 0.0 if math.isinf(r_m) else BEND_LENGTH_M / r_m


def rtca_law() -> tuple[Any, Any]:
    from fsarm_sim.plant import transmissions

    tr = transmissions.get("rtca")
    return tr, tr.block()


def mu_of(tr: Any, block: Any, r_m: float, x: float) -> float:
    return float(tr.sensor_torque(block, x, bend_of_radius(r_m)) / tr.sensor_torque(block, x, 0.0))


# ------------------------------------------------------------- seed 001's own bench (Sec. 4)


def _zn(ctx: Context) -> Any:
    """The Ziegler-Nichols procedure on seed 001's bench (once per report)."""
    from fsarm_sim.studies import rtca_bench as rb

    return ctx.once("001/bench/zn", lambda: rb.ziegler_nichols(rb.Rtca001()))


def calibrated_bench(ctx: Context) -> tuple[Any, Any]:
    """Seed 001's actuator (:mod:`fsarm_sim.studies.rtca_bench`) with the paper's control: a
    PID tuned by Ziegler-Nichols on the bench (Sec. 4.1.1), the set-point delay calibrated on
    the 25 ms offset (claim 001-torque-tracking-offset)."""
    from fsarm_sim.studies import rtca_bench as rb
    from fsarm_sim.studies.reproduce.targets import claim_value

    def build() -> tuple[Any, Any]:
        act = rb.Rtca001()
        pid = _zn(ctx).pid
        delay = rb.calibrate_reference_delay(act, pid, claim_value("001-torque-tracking-offset"))
        return rb.with_(act, reference_delay_s=delay), pid

    return ctx.once("001/bench", build)


def _bench_tracking(ctx: Context) -> Any:
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = calibrated_bench(ctx)
    return ctx.once("001/bench/track6", lambda: rb.tracking(act, pid, periods=5))


BENCH_NOTE = (
    "seed 001's bench (studies.rtca_bench): EC-4pole 30 + 86:1, 192 rpm / 12 N·m limits, 500 CPT "
    "motor and 2000 CPT shaft encoders, 1 kHz velocity PI and PID torque loop tuned by "
    "Ziegler-Nichols on the bench (Sec. 4.1.1: ultimate gain and period of the P loop, classic "
    "table), output blocked; the set-point reaches the loop later than it is logged by a delay "
    "calibrated on the paper's 25 ms offset (the only number taken from Sec. 4.1)"
)


def bench_tracking_offset(ctx: Context) -> Measured:
    tr = _bench_tracking(ctx)
    act, _ = calibrated_bench(ctx)
    return Measured(
        ours=tr.offset_ms,
        text=f"{tr.offset_ms:.3g} ms (set-point delay {1000 * act.reference_delay_s:.0f} ms "
        "calibrated on it)",
        note=BENCH_NOTE + "; the calibration holds if this is 25 ms",
    )


def bench_tracking_rmse(ctx: Context) -> Measured:
    tr = _bench_tracking(ctx)
    _, pid = calibrated_bench(ctx)
    return Measured(
        ours=tr.rmse_nm,
        text=f"RMSE {tr.rmse_nm:.4g} N·m (NRMSE {tr.nrmse_pct:.3g} %), offset "
        f"{tr.offset_ms:.3g} ms",
        details={
            "nrmse_pct": tr.nrmse_pct,
            "offset_ms": tr.offset_ms,
            "pid": [pid.kp, pid.ki, pid.kd],
            "saturated": tr.saturated,
        },
        note=BENCH_NOTE + "; RMSE of the set-point vs the torque sensor over 5 periods",
    )


def bench_estimate_error(ctx: Context) -> Measured:
    tr = _bench_tracking(ctx)
    return Measured(
        ours=tr.estimate_error_nm,
        text=f"mean |estimate − sensor| {tr.estimate_error_nm:.3g} N·m",
        note=BENCH_NOTE + "; the estimate from the quantised encoders, the truth the shaft's "
        "law plus its unmodelled residual (0.32 % NRMSE straight, Sec. 3.3) read by the "
        "16-bit torque channel",
    )


def bench_symmetric(ctx: Context) -> Measured:
    tr = _bench_tracking(ctx)
    rp, rn = tr.rmse_pos_nm, tr.rmse_neg_nm
    asym = abs(rp / rn - 1.0) if rn > 0.0 else math.inf
    return Measured(
        ours=asym,
        text=f"tracking RMSE {rp:.3g} (τ > 0) vs {rn:.3g} N·m (τ < 0)",
        details={"rmse_pos": rp, "rmse_neg": rn},
        note=BENCH_NOTE,
    )


def _bench_bandwidths(ctx: Context) -> list[Any]:
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = calibrated_bench(ctx)
    m = 2 if ctx.quick else 4
    return ctx.once(
        "001/bench/bw",
        lambda: [rb.torque_bandwidth(act, pid, radius_m=r, realizations=m) for r in R_BANDWIDTH_M],
    )


def _bench_bandwidth(ctx: Context, i: int) -> Measured:
    bws = _bench_bandwidths(ctx)
    b = bws[i]
    return Measured(
        ours=b.bandwidth_hz,
        text=f"{b.bandwidth_hz:.3g} Hz (second-order fit {b.fit_pct:.0f} %, velocity set-point "
        f"saturated {100 * b.saturated:.0f} % of the time)",
        details={
            "radius_mm": [1000 * r for r in R_BANDWIDTH_M],
            "bandwidth_hz": [x.bandwidth_hz for x in bws],
            "fit_pct": [x.fit_pct for x in bws],
            "saturated": [x.saturated for x in bws],
        },
        note=BENCH_NOTE + "; multisine 0.1-10 Hz, peak 5 N·m, random phases (estimate), best "
        "linear approximation over 4 phase draws (2 in --quick), G = T_est/T_des fitted with 2 "
        "poles + 1 zero, -3 dB of the fit; the same gains at every R. Where ours departs (a "
        "smaller fall with bend): the loop sees the bend only through μ (≥ 0.705 in the text, "
        "held below R = 250 mm, so the loop gain falls by 30 % at most) and the 5 N·m multisine "
        "holds the motor at its 192 rpm limit about 70 % of the time, which sets much of the "
        "response whatever the bend",
    )


def bench_bandwidth_straight(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 0)


def bench_bandwidth_r450(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 1)


def bench_bandwidth_r300(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 2)


def bench_bandwidth_r150(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 3)


def bench_bandwidth_trend(ctx: Context) -> Measured:
    bws = _bench_bandwidths(ctx)
    bw = [b.bandwidth_hz for b in bws]
    return Measured(
        ours=bw,
        text=" → ".join(f"{v:.3g}" for v in bw)
        + f" Hz (R = ∞, 450, 300, 150 mm): falls {100 * (1 - bw[-1] / bw[0]):.0f} %",
        details={"radius_mm": [1000 * r for r in R_BANDWIDTH_M], "bandwidth_hz": bw},
        note=BENCH_NOTE + "; the same ZN gains at every R, as the paper's 'same PID gains'. "
        "Where ours departs (14 % against the paper's 31 %): the loop sees the bend only "
        "through μ (≥ 0.705, held below R = 250 mm) and runs at the motor's 192 rpm limit about "
        "70 % of the time",
    )


def bench_bandwidth_fit(ctx: Context) -> Measured:
    fits = [b.fit_pct for b in _bench_bandwidths(ctx)]
    worst = max(fits, key=lambda v: abs(v - 80.0))
    return Measured(
        ours=worst,
        text="fit " + ", ".join(f"{v:.0f}" for v in fits) + " % (R = ∞, 450, 300, 150 mm)",
        details={"fit_pct": fits},
        note=BENCH_NOTE + "; ours is the fit farthest from 80 %; MATLAB's fit measure, 2 poles "
        "+ 1 zero. The 5 N·m multisine drives the motor into its 192 rpm limit most of the time "
        "(a 5 N·m swing at 10 Hz needs ~60 rad/s of twist rate), which a linear model cannot fit",
    )


R_FIG12_M = R_IMPEDANCE_M
FIG12_NOTE = (
    "seed 001's bench with the Ziegler-Nichols PID (integral action, as printed); the load motor "
    "(DCX35L, 113:1, position mode) as a speed-limited position servo (7000 rpm / 113, 20 Hz: "
    "estimates) moves the output through a 20° log chirp 0.1-10 Hz over 60 s (also in --quick), "
    "torque set-point 0; Z = T̂_s/θ̇_s as the paper defines it (Sec. 4.2.1), per fifth-of-a-"
    "decade band (bands start where the analysed sweep starts); the peak from tenth-decade bands"
)


def _fig12(ctx: Context) -> Any:
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = calibrated_bench(ctx)
    return ctx.once(
        "001/bench/fig12",
        lambda: rb.fig12(act, {"PID": pid}, R_FIG12_M, load=rb.LoadServo()),
    )


def _fig12_details(fig: Any) -> dict[str, Any]:
    return {
        "radius_mm": [1000 * r.radius_m for r in fig.rows],
        "freq_hz": [float(f) for f in fig.rows[0].freq_hz],
        "magnitude": [[float(m) for m in r.magnitude] for r in fig.rows],
        "peak_hz": [r.peak_hz for r in fig.rows],
    }


def fig12_transparent_low_f(ctx: Context) -> Measured:
    """Obs. 1: |Z| in the lowest band against the shaft's own impedance there (the motor
    held: T̂/θ̇_s = K/(jω), K the law's small-signal stiffness straight)."""
    fig = _fig12(ctx)
    tr, block = rtca_law()
    k = abs(tr.sensor_torque(block, 0.2, 0.0) / 0.2)  # secant over the first 0.2 rad
    worst = 0.0
    for r in fig.rows:
        w = 2.0 * math.pi * float(r.freq_hz[0])
        worst = max(worst, float(r.magnitude[0]) / (k / w))
    return Measured(
        ours=worst,
        text=f"|Z| at {fig.rows[0].freq_hz[0]:.2g} Hz ≤ {100 * worst:.2g} % of the held shaft's "
        f"K/ω (K = {k:.3g} N·m/rad) at every bend",
        details=_fig12_details(fig),
        note=FIG12_NOTE,
    )


def fig12_rises_with_frequency(ctx: Context) -> Measured:
    """Obs. 2: |Z| rises from the lowest band to the peak (the smallest ratio over the bends)."""
    fig = _fig12(ctx)
    ratios = []
    for r in fig.rows:
        below = r.side(below=True)
        top = float(np.max(r.magnitude[below])) if below.size else float(r.magnitude[0])
        ratios.append(top / float(r.magnitude[0]))
    return Measured(
        ours=min(ratios),
        text="|Z| below the peak / |Z| lowest band: " + ", ".join(f"{v:.3g}" for v in ratios),
        details=_fig12_details(fig),
        note=FIG12_NOTE + ". The P loop alone (the option, calibrated to 25 ms) falls with "
        "frequency instead (T̂/θ̇_s = μK/(s + μK·Kp)): see fsarm rtca-fig12",
    )


def fig12_rises_with_bend(ctx: Context) -> Measured:
    """Obs. 3: per band below every bend's peak, |Z| over straight, 450, 200 mm."""
    fig = _fig12(ctx)
    bands = fig.rise_below_peak("PID")
    return Measured(
        ours=bands,
        text="; ".join(
            f"{b}: " + " → ".join(f"{v:.3g}" for v in z) + f" ({100 * (z[-1] / z[0] - 1):+.0f} %)"
            for b, z in bands.items()
        ),
        details=_fig12_details(fig),
        note=FIG12_NOTE + ". Every band below the peak must rise. Where ours departs: the "
        "lowest bands' T̂ is at the estimate's quantum (8000 counts/turn: 0.8 mrad, ~4 mN·m of "
        "T̂, against |Z|·|θ̇_s| ≈ 1 mN·m at 0.3 Hz) and scatters either way; the band just below "
        "the peak falls with the peak's height (the resonance flattens when bent); in between "
        "|Z| rises 2-3 % per band. Linear theory with a velocity-sourced motor: T̂/θ̇_s = "
        "1/(s/(μK) + C(s)e^(-sτ)): a smaller μ raises it below the peak only with integral "
        "action (a P loop lowers it), and only by a few %: the paper's friction cause is not "
        "seen by T̂ (studies.rtca_bench, friction_site)",
    )


def fig12_peak_lower(ctx: Context) -> Measured:
    """Obs. 4: the frequency of the largest |Z| at each bend."""
    fig = _fig12(ctx)
    peaks = [r.peak_hz for r in fig.rows]
    return Measured(
        ours=peaks,
        text="peak " + " → ".join(f"{v:.3g}" for v in peaks) + " Hz (straight, 450, 200 mm)",
        details=_fig12_details(fig),
        note=FIG12_NOTE,
    )


SHAFT_SECANT_RAD = 0.2  # the held shaft's K: the law's secant over ±0.2 rad (as obs. 1)


def fig12_shaft_above_peak(ctx: Context) -> Measured:
    """Sec. 4.2.1: from the resonance on, |Z| is the shaft's own: per band above each bend's
    peak, |Z| against the held shaft's K/ω there (K the law's secant over ±0.2 rad at the bend,
    both twist signs averaged: μ is applied); ours is the ratio farthest from 1."""
    fig = _fig12(ctx)
    tr, block = rtca_law()
    x = SHAFT_SECANT_RAD
    worst, rows = 1.0, []
    for r in fig.rows:
        phi = bend_of_radius(r.radius_m)
        k = 0.5 * (abs(tr.sensor_torque(block, x, phi)) + abs(tr.sensor_torque(block, -x, phi))) / x
        above = r.side(below=False)
        ratios = [
            float(r.magnitude[i]) / (k / (2.0 * math.pi * float(r.freq_hz[i]))) for i in above
        ]
        if not ratios:
            worst = math.inf
        for q in ratios:
            if abs(math.log(q)) > abs(math.log(worst)):
                worst = q
        rows.append((r, k, ratios))
    text = "; ".join(
        f"{'straight' if math.isinf(r.radius_m) else f'R = {1000 * r.radius_m:g} mm'} "
        f"(K {k:.3g} N·m/rad, peak {r.peak_hz:.3g} Hz): "
        + (", ".join(f"{q:.2f}" for q in ratios) or "no band above the peak")
        for r, k, ratios in rows
    )
    return Measured(
        ours=worst,
        text="|Z| / (K/ω) above the peak: " + text,
        details={**_fig12_details(fig), "ratios": [q for _, _, q in rows]},
        note=FIG12_NOTE,
    )


def bench_deadzone_error(ctx: Context) -> Measured:
    """Sec. 4.1.1: the 1 Hz, 6 N·m tracking run; the sensor torque moved back by the loop's
    measured offset; RMS error where |T_des| < 1 N·m over RMS error elsewhere."""
    tr = _bench_tracking(ctx)
    r = tr.run
    dt = float(r.t[1] - r.t[0])
    shift = round(tr.offset_ms / 1000.0 / dt)
    n = len(r.t) - shift
    err = r.tau_sensor[shift : shift + n] - r.tau_des[:n]
    des = r.tau_des[:n]
    near = np.abs(des) < DEADZONE_BAND_NM
    settled = r.t[:n] >= r.t[0] + 1.0  # the run's first second settles (rtca_bench.tracking)
    e_near = float(np.sqrt(np.mean(err[near & settled] ** 2)))
    e_far = float(np.sqrt(np.mean(err[~near & settled] ** 2)))
    ratio = e_near / e_far if e_far > 0.0 else math.inf
    return Measured(
        ours=ratio,
        text=f"RMS error {e_near:.3g} N·m where |T_des| < {DEADZONE_BAND_NM:g} N·m vs "
        f"{e_far:.3g} N·m elsewhere (×{ratio:.2f}; offset {tr.offset_ms:.3g} ms removed)",
        details={"near_nm": e_near, "far_nm": e_far, "shift_samples": shift},
        note=BENCH_NOTE + "; the dead zone is Table 1's own (001-deadzone)",
    )


DEADZONE_BAND_NM = 1.0  # "torques close to 0 Nm" (estimate, written with the claim)


def mu_150_vs_250(ctx: Context) -> Measured:
    tr, block = rtca_law()
    ok = [mu_of(tr, block, 0.150, x) > mu_of(tr, block, 0.250, x) + 1e-9 for x in (0.5, -0.5)]
    return Measured(
        ours=ok,
        text=f"μ(150) {mu_of(tr, block, 0.150, 0.5):.3g} / {mu_of(tr, block, 0.150, -0.5):.3g} vs "
        f"μ(250) {mu_of(tr, block, 0.250, 0.5):.3g} / {mu_of(tr, block, 0.250, -0.5):.3g} (TOL / LOL)",
        note="the rtca law holds μ at its R = 250 mm values for tighter bends: the text prints μ "
        "only at 250 mm; the 150 mm values are in Fig. 7 only",
    )


def bench_ziegler_nichols(ctx: Context) -> Measured:

    _, pid = calibrated_bench(ctx)
    zn = _zn(ctx)
    classic = (
        abs(pid.kp - 0.6 * zn.ultimate_gain) < 1e-9 * zn.ultimate_gain
        and abs(pid.ki - pid.kp / (zn.ultimate_period_s / 2.0)) < 1e-9 * pid.ki
        and abs(pid.kd - pid.kp * zn.ultimate_period_s / 8.0) < 1e-9 * pid.kd
    )
    return Measured(
        ours=[pid.ki > 0.0, classic],
        text=f"Ku {zn.ultimate_gain:.3g} rad/s per N·m, Tu {1000 * zn.ultimate_period_s:.3g} ms → "
        f"Kp {pid.kp:.3g}, Ki {pid.ki:.3g}, Kd {pid.kd:.3g}",
    )


def bench_model_accuracy(ctx: Context) -> Measured:
    """Sec. 3.2-3.3 on the MasterFlex08 of seed 001's bench: output blocked, the motor drives
    the twist through a slow ±5 N·m sweep; NRMSE of eq. 3 (the estimate, no quantisation)
    against the shaft's torque (law + its friction) over the span, per bend radius."""
    from fsarm_sim.studies import rtca_bench as rb

    act = rb.with_(rb.Rtca001(), shaft_cpt=2**20)  # the model's error, not the encoders'
    _, pid = calibrated_bench(ctx)

    def one(r: float) -> float:
        tr = rb.tracking(act, pid, amplitude_nm=5.0, freq_hz=0.5, periods=2, radius_m=r).run
        sel = tr.t >= tr.t[-1] - 4.0
        e = tr.tau_est[sel] - tr.tau_true[sel]
        return 100.0 * float(np.sqrt(np.mean(e**2))) / float(np.ptp(tr.tau_true[sel]))

    radii = R_CHARACTERISATION_M[::2] if ctx.quick else R_CHARACTERISATION_M
    nrmse = ctx.once("001/bench/nrmse", lambda: [one(r) for r in radii])
    mm = ", ".join("∞" if math.isinf(r) else f"{1000 * r:g}" for r in radii)
    return Measured(
        ours=nrmse,
        text="NRMSE " + " → ".join(f"{v:.3g}" for v in nrmse) + f" % (R = {mm} mm)",
        details={"radius_mm": [1000 * r for r in radii], "nrmse_pct": nrmse},
        note="seed 001's MasterFlex08 on its bench: eq. 3 against the shaft's torque including "
        "its bend friction (sized from these two NRMSE values: a calibration), ±5 N·m at 0.5 Hz",
    )


def bench_tracking_vs_bend(ctx: Context) -> Measured:
    """Sec. 4.1.1's 1 Hz, 6 N*m tracking (same ZN gains and set-point delay) at the bandwidth
    test's bends, straight to R = 150 mm; the RMSE of the set-point vs the torque sensor."""
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = calibrated_bench(ctx)

    def track(r: float) -> Any:
        return ctx.once(
            f"001/bench/track6/{r}", lambda: rb.tracking(act, pid, periods=5, radius_m=r)
        )

    runs = [_bench_tracking(ctx)] + [track(r) for r in R_BANDWIDTH_M[1:]]
    rmse = [t.rmse_nm for t in runs]
    labels = ["straight"] + [f"R = {1000 * r:.0f} mm" for r in R_BANDWIDTH_M[1:]]
    return Measured(
        ours=rmse,
        text="RMSE "
        + ", ".join(
            f"{lab} {x:.4g} N·m ({t.offset_ms:.3g} ms)"
            for lab, x, t in zip(labels, rmse, runs, strict=True)
        ),
        details={
            "radius_mm": [1000 * r for r in R_BANDWIDTH_M],
            "rmse_nm": rmse,
            "offset_ms": [t.offset_ms for t in runs],
        },
        note=BENCH_NOTE + "; the bend acts through μ(R) and the shaft's bend-dependent residual "
        "friction; the error is mostly the calibrated set-point delay, and the measured lag (the "
        "offset in brackets) shrinks as the shaft bends, so the RMSE falls where the paper's "
        "accuracy fell",
    )
