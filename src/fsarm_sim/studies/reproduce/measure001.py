"""Seed 001: how ours is measured.

* The RTCA transmission (:mod:`fsarm_sim.plant.transmissions.rtca`, seed 001's own shaft model) is
  evaluated where a claim is about the shaft's law (Table 1, μ, dead zone).
* Everything the paper measured on its actuator runs on **seed 001's own bench**
  (:mod:`fsarm_sim.studies.rtca_bench`: its motor, gearbox, encoders and 1 kHz cascade on its
  MasterFlex08, output blocked or driven by the load motor) with the paper's control: a PID
  tuned by Ziegler-Nichols on the bench, the set-point delay calibrated on the 25 ms offset
  (claim 001-torque-tracking-offset, read through ``targets.claim_value``). That is torque
  tracking (Sec. 4.1.1), the torque bandwidth at the paper's radii (Sec. 4.1.2), Fig. 12's
  |T̂_s/θ̇_s| per band (Sec. 4.2.1), the model's NRMSE vs bend (Sec. 3.3) and the bend-angle
  estimate at fixed knee angles (Sec. 5.1, ``φ = L_bend / R``, ``L_bend`` = 255 mm).
* The MasterFlex08 against seed 000's eq. 3: the catalogue's law at 8 mm × 865 mm.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fsarm_sim.studies.reproduce.claims import Context, Measured, MeasureFn

BEND_LENGTH_M = 0.255  # seed 001 Sec. 5.1: L = φ R with the bend length of its knee set-up
R_BANDWIDTH_M = (math.inf, 0.450, 0.300, 0.150)  # Sec. 4.1.2 (results)
R_IMPEDANCE_M = (math.inf, 0.450, 0.200)  # Sec. 4.2.1
R_CHARACTERISATION_M = (math.inf, 0.450, 0.350, 0.250, 0.150)  # Sec. 3.2
# Table 1 as printed (Δθ in degrees): a0, a1, a2, a3, b1, b2, b3, ω ("-" = 0); c = 0.00003
PRINTED_POS = (4.20200, -4.20100, 0.0, 0.0, 0.16220, 0.0, 0.0, 0.03322)
PRINTED_NEG = (-3.10700, 2.33500, 0.74840, 0.02559, -1.48700, 0.36180, 0.19760, 0.04357)
PRINTED_C = 0.00003


def _phi(r_m: float) -> float:
    return 0.0 if math.isinf(r_m) else BEND_LENGTH_M / r_m


def _rtca() -> tuple[Any, Any]:
    from fsarm_sim.plant import transmissions

    tr = transmissions.get("rtca")
    return tr, tr.block()


def _twist_for(tr: Any, block: Any, torque: float, bend: float) -> float:
    """Twist at which the RTCA law gives ``torque`` (bisection; the law rises with the twist)."""
    lo, hi = (0.0, 3.0) if torque > 0 else (-3.0, 0.0)
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if tr.sensor_torque(block, mid, bend) < torque:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def rating_6nm(ctx: Context) -> Measured:
    from fsarm_sim.plant.shaft import load_catalogue

    cat_r = float(load_catalogue().rating_nm(8.0))
    tr, block = _rtca()
    rtca_r = float(tr.rating_nm(block))
    worst = max((cat_r, rtca_r), key=lambda r: abs(r - 6.0))
    return Measured(
        ours=worst,
        text=f"catalogue (D³ rule) {cat_r:.3g} N·m, rtca {rtca_r:.3g} N·m",
        details={"catalogue_8mm": cat_r, "rtca": rtca_r},
    )


def table1_transcribed(ctx: Context) -> Measured:
    from fsarm_sim.plant.transmissions import rtca

    def same(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
        return len(a) == len(b) and all(
            abs(x - y) <= 1e-12 * max(1.0, abs(y)) for x, y in zip(a, b, strict=True)
        )

    tr, block = _rtca()
    names = tr.param_names()
    omega_ok = (
        abs(block[names.index("omega_pos")] - PRINTED_POS[7] * 180.0 / math.pi) < 1e-9
        and abs(block[names.index("omega_neg")] - PRINTED_NEG[7] * 180.0 / math.pi) < 1e-9
        and abs(block[names.index("c")] - PRINTED_C * 180.0 / math.pi) < 1e-12
    )
    rtca_ok = (
        same(tuple(rtca.TABLE1_POS), PRINTED_POS)
        and same(tuple(rtca.TABLE1_NEG), PRINTED_NEG)
        and omega_ok
    )
    try:
        from fsarm_sim.plant.effects import nonlinear_stiffness as ns

        ns_ok = same(tuple(ns.MF08_POS), PRINTED_POS) and same(tuple(ns.MF08_NEG), PRINTED_NEG)
        ns_text = "equal" if ns_ok else "differs"
    except (ImportError, AttributeError):
        ns_ok, ns_text = True, "absent (one implementation only)"
    return Measured(
        ours=[rtca_ok, ns_ok],
        text=f"rtca {'equal' if rtca_ok else 'differs'}; nonlinear_stiffness {ns_text}",
    )


def through_origin(ctx: Context) -> Measured:
    tr, block = _rtca()
    vals = [abs(tr.sensor_torque(block, x, 0.0)) for x in (1e-9, -1e-9, 0.0)]
    v = max(vals)
    return Measured(ours=v, text=f"|T(0±)| ≤ {v:.2g} N·m")


def tol_stiffer(ctx: Context) -> Measured:
    tr, block = _rtca()
    xp = _twist_for(tr, block, 3.0, 0.0)
    xn = _twist_for(tr, block, -3.0, 0.0)
    kp, kn = 3.0 / xp, 3.0 / abs(xn)
    return Measured(
        ours=kp / kn,
        text=f"secant at ±3 N·m: TOL {kp:.3g}, LOL {kn:.3g} N·m/rad",
        details={"x_pos": xp, "x_neg": xn},
    )


def bend_needs_more_twist(ctx: Context) -> Measured:
    tr, block = _rtca()
    pos = [_twist_for(tr, block, 3.0, _phi(r)) for r in R_CHARACTERISATION_M]
    neg = [abs(_twist_for(tr, block, -3.0, _phi(r))) for r in R_CHARACTERISATION_M]
    return Measured(
        ours={"+3 N·m": pos, "−3 N·m": neg},
        text=f"twist for +3 N·m {pos[0]:.3g}→{pos[-1]:.3g} rad, −3 N·m {neg[0]:.3g}→{neg[-1]:.3g}",
        details={"radius_mm": [1000 * r for r in R_CHARACTERISATION_M], "pos": pos, "neg": neg},
    )


def _mu(tr: Any, block: Any, r_m: float, x: float) -> float:
    return float(tr.sensor_torque(block, x, _phi(r_m)) / tr.sensor_torque(block, x, 0.0))


def mu_tol_250(ctx: Context) -> Measured:
    tr, block = _rtca()
    v = _mu(tr, block, 0.250, 0.5)
    return Measured(ours=v, text=f"{v:.4g}", note="T(Δθ, R)/T(Δθ, straight) of the rtca law")


def mu_lol_250(ctx: Context) -> Measured:
    tr, block = _rtca()
    v = _mu(tr, block, 0.250, -0.5)
    return Measured(ours=v, text=f"{v:.4g}", note="T(Δθ, R)/T(Δθ, straight) of the rtca law")


# ------------------------------------------------------------------------- Sec. 4.1.1, 5.1


def deadzone(ctx: Context) -> Measured:
    tr, block = _rtca()
    xs = np.linspace(-0.1, 0.1, 2001)
    zero = [x for x in xs if x != 0.0 and abs(tr.sensor_torque(block, float(x), 0.0)) == 0.0]
    width = (max(zero) - min(zero)) if zero else 0.0
    return Measured(
        ours=[width > 0.0],
        text=f"zero-torque band {math.degrees(width):.2f}° wide" if zero else "no dead zone",
    )


SEC51_SWEEP_S = 10.0  # estimate: the manual knee sweep 0 -> 90 deg (and back) is not timed
SEC51_SWEEP_QUICK_S = 3.0
SEC51_BIN_DEG = 15.0  # Fig. 18's error against the bend angle, read per bin


def _sec51_errors(ctx: Context) -> tuple[float, float, list[dict[str, float]]]:
    """Sec. 5.1's second experiment (Figs. 17-18, where its ±0.35 / 2.8 N·m come from): the ZN
    loop follows 4 N·m at 1 Hz (output blocked) while the knee bends the shaft continuously
    from 0 to 90 deg and back (R = L/φ, L = 255 mm; the law's bend angle per cycle), the
    estimate updated online with μ(φ) (eq. 5); the estimate with μ(φ) and with the straight
    law (T̂/μ) against the torque sensor, the largest error per bend bin."""
    from fsarm_sim.plant.transmissions import rtca
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = _bench(ctx)
    sweep = SEC51_SWEEP_QUICK_S if ctx.quick else SEC51_SWEEP_S

    def run() -> list[dict[str, float]]:
        settle = 1.0
        dt = act.ctrl_dt_s
        t = np.arange(round((settle + 2.0 * sweep) / dt), dtype=np.float64) * dt
        knee = np.radians(90.0) * np.clip(1.0 - np.abs((t - settle) / sweep - 1.0), 0.0, 1.0)
        block = act.shaft_block()
        bend = np.array([rb.bend_of(BEND_LENGTH_M / k, block) if k > 0.0 else 0.0 for k in knee])
        tau_d = 4.0 * np.clip(t / settle, 0.0, 1.0) * np.sin(2.0 * math.pi * t)
        r = rb.run(act, pid, tau_d, bend_rad=bend)
        sel = t >= settle
        est, sens = r.tau_est[sel], r.tau_sensor[sel]
        signs = np.where(est >= 0.0, 1.0, -1.0)
        mu = np.array([rtca.mu_factor(block, x, b) for x, b in zip(signs, bend[sel], strict=True)])
        deg = np.degrees(knee[sel])
        rows = []
        for lo in np.arange(0.0, 90.0, SEC51_BIN_DEG):
            m = (deg >= lo) & (deg <= lo + SEC51_BIN_DEG)
            rows.append(
                {
                    "bend_deg": float(lo + 0.5 * SEC51_BIN_DEG),
                    "with_bend": float(np.max(np.abs(est[m] - sens[m]))),
                    "without_bend": float(np.max(np.abs(est[m] / mu[m] - sens[m]))),
                }
            )
        return rows

    rows = ctx.once("001/bench/sec51", run)
    worst_with = max(r["with_bend"] for r in rows)
    worst_without = max(r["without_bend"] for r in rows)
    return worst_with, worst_without, rows


SEC51_NOTE = (
    "; 4 N·m at 1 Hz while the knee bends the shaft 0 → 90° → 0 (R = 255 mm / φ), "
    f"{SEC51_SWEEP_S:g} s each way (an estimate: the manual sweep is not timed), the "
    "estimate updated online with μ(φ) as in Sec. 5.1's second run (Figs. 17-18)"
)


def bend_compensated_error(ctx: Context) -> Measured:
    w, _, rows = _sec51_errors(ctx)
    return Measured(
        ours=w,
        text=f"max |error| {w:.3g} N·m",
        details={"rows": rows},
        note=BENCH_NOTE + SEC51_NOTE + "; the error is the shaft's bend friction and the "
        "encoders' quantum",
    )


def bend_neglected_error(ctx: Context) -> Measured:
    _, wo, rows = _sec51_errors(ctx)
    return Measured(
        ours=wo,
        text=f"max |error| {wo:.3g} N·m (straight law applied at every bend)",
        details={"rows": rows},
        note="neglecting the bend errs by T (1/μ - 1): at Sec. 5.1's 4 N·m and the smallest μ the "
        "text prints (0.705, TOL at R = 250 mm; the rtca law holds it to R = 162 mm, φ = 90° on "
        "L = 255 mm) that is 1.67 N·m at most; the paper's 2.8 N·m needs μ ≈ 4/(4 + 2.8) = 0.59 "
        "somewhere in 0-90°, lower than any μ in the text (its μ(φ) table is only in Fig. 17-18)",
    )


def bend_compensation_gain(ctx: Context) -> Measured:
    w, wo, _ = _sec51_errors(ctx)
    gain = 100.0 * (1.0 - w / wo) if wo > 0.0 else 0.0
    return Measured(ours=gain, text=f"{gain:.3g} % (max error {wo:.3g} → {w:.3g} N·m)")


# ------------------------------------------------------------------------ MasterFlex08


def _masterflex08_eq3(side: int) -> Measured:
    import importlib

    from fsarm_sim.plant.shaft import load_catalogue

    sel = importlib.import_module("fsarm_sim.studies.shaft_selection")
    k = float(sel.stiffness(load_catalogue(), "series", 8.0, 865.0, 0.0, side))
    return Measured(
        ours=k,
        text=f"{k:.3g} N·m/rad (eq. 3, straight, extrapolated to L = 865 mm)",
        note="eq. 3 is fitted on L 235-535 mm; 865 mm is outside (extrapolated)",
    )


def masterflex08_eq3_tol(ctx: Context) -> Measured:
    return _masterflex08_eq3(1)


def masterflex08_eq3_lol(ctx: Context) -> Measured:
    return _masterflex08_eq3(-1)


def one_table1_curve(ctx: Context) -> Measured:
    tr, block = _rtca()
    curves = {"rtca": lambda x: float(tr.sensor_torque(block, x, 0.0))}
    try:
        from fsarm_sim.plant.effects import nonlinear_stiffness as ns

        curves["nonlinear_stiffness"] = lambda x: float(ns.masterflex08_torque_nm(x, 1.0))
    except (ImportError, AttributeError):
        pass
    if len(curves) < 2:
        return Measured(ours=0.0, text="one implementation of Table 1")
    xs = [float(x) for x in np.radians(np.linspace(-90.0, 90.0, 721)) if abs(x) >= math.radians(3)]
    a, b = (list(curves.values())[i] for i in (0, 1))
    worst, at = 0.0, 0.0
    for x in xs:
        ta, tb = a(x), b(x)
        rel = abs(ta - tb) / max(abs(tb), 0.5)
        if rel > worst:
            worst, at = rel, x
    return Measured(
        ours=worst,
        text=f"largest difference {100 * worst:.1f} % at {math.degrees(at):+.0f}° twist "
        f"({' vs '.join(curves)})",
        details={"twist_deg_at_worst": math.degrees(at)},
    )


def fit_range(ctx: Context) -> Measured:
    tr, block = _rtca()
    names = tr.param_names()
    pos = math.degrees(block[names.index("x_fit_pos")])
    neg = -math.degrees(block[names.index("x_fit_neg")])
    return Measured(
        ours=[abs(pos - 51.9) <= 0.5, abs(neg + 76.0) <= 0.5],
        text=f"linear continuation from {pos:+.2f}° and {neg:+.2f}°",
    )


# ------------------------------------------------------------- seed 001's own bench (Sec. 4)


def _zn(ctx: Context) -> Any:
    """The Ziegler-Nichols procedure on seed 001's bench (once per report)."""
    from fsarm_sim.studies import rtca_bench as rb

    return ctx.once("001/bench/zn", lambda: rb.ziegler_nichols(rb.Rtca001()))


def _bench(ctx: Context) -> tuple[Any, Any]:
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

    act, pid = _bench(ctx)
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
    act, _ = _bench(ctx)
    return Measured(
        ours=tr.offset_ms,
        text=f"{tr.offset_ms:.3g} ms (set-point delay {1000 * act.reference_delay_s:.0f} ms "
        "calibrated on it)",
        note=BENCH_NOTE + "; the calibration holds if this is 25 ms",
    )


def bench_tracking_rmse(ctx: Context) -> Measured:
    tr = _bench_tracking(ctx)
    _, pid = _bench(ctx)
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

    act, pid = _bench(ctx)
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

    act, pid = _bench(ctx)
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
    tr, block = _rtca()
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
    tr, block = _rtca()
    x = SHAFT_SECANT_RAD
    worst, rows = 1.0, []
    for r in fig.rows:
        phi = _phi(r.radius_m)
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
    tr, block = _rtca()
    ok = [_mu(tr, block, 0.150, x) > _mu(tr, block, 0.250, x) + 1e-9 for x in (0.5, -0.5)]
    return Measured(
        ours=ok,
        text=f"μ(150) {_mu(tr, block, 0.150, 0.5):.3g} / {_mu(tr, block, 0.150, -0.5):.3g} vs "
        f"μ(250) {_mu(tr, block, 0.250, 0.5):.3g} / {_mu(tr, block, 0.250, -0.5):.3g} (TOL / LOL)",
        note="the rtca law holds μ at its R = 250 mm values for tighter bends: the text prints μ "
        "only at 250 mm; the 150 mm values are in Fig. 7 only",
    )


def bench_ziegler_nichols(ctx: Context) -> Measured:

    _, pid = _bench(ctx)
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
    _, pid = _bench(ctx)

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

    act, pid = _bench(ctx)

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


MEASURES: dict[str, MeasureFn] = {
    "fig12_shaft_above_peak": fig12_shaft_above_peak,
    "bench_deadzone_error": bench_deadzone_error,
    "bench_tracking_vs_bend": bench_tracking_vs_bend,
    "fit_range": fit_range,
    "rating_6nm": rating_6nm,
    "table1_transcribed": table1_transcribed,
    "through_origin": through_origin,
    "tol_stiffer": tol_stiffer,
    "bend_needs_more_twist": bend_needs_more_twist,
    "mu_tol_250": mu_tol_250,
    "mu_lol_250": mu_lol_250,
    "deadzone": deadzone,
    "bench_bandwidth_trend": bench_bandwidth_trend,
    "bench_bandwidth_fit": bench_bandwidth_fit,
    "bench_tracking_offset": bench_tracking_offset,
    "bench_model_accuracy": bench_model_accuracy,
    "bench_ziegler_nichols": bench_ziegler_nichols,
    "mu_150_vs_250": mu_150_vs_250,
    "bench_tracking_rmse": bench_tracking_rmse,
    "bench_estimate_error": bench_estimate_error,
    "bench_symmetric": bench_symmetric,
    "bench_bandwidth_straight": bench_bandwidth_straight,
    "bench_bandwidth_r450": bench_bandwidth_r450,
    "bench_bandwidth_r300": bench_bandwidth_r300,
    "bench_bandwidth_r150": bench_bandwidth_r150,
    "fig12_transparent_low_f": fig12_transparent_low_f,
    "fig12_rises_with_frequency": fig12_rises_with_frequency,
    "fig12_rises_with_bend": fig12_rises_with_bend,
    "fig12_peak_lower": fig12_peak_lower,
    "bend_compensated_error": bend_compensated_error,
    "bend_neglected_error": bend_neglected_error,
    "bend_compensation_gain": bend_compensation_gain,
    "masterflex08_eq3_tol": masterflex08_eq3_tol,
    "masterflex08_eq3_lol": masterflex08_eq3_lol,
    "one_table1_curve": one_table1_curve,
}
