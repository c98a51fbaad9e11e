"""Seed 001: how ours is measured.

* The RTCA transmission (:mod:`fsarm_sim.plant.transmissions.rtca`, seed 001's own shaft model) is
  evaluated where a claim is about the shaft's law (Table 1, μ, dead zone).
* Torque tracking (Sec. 4.1.1), the torque bandwidth at the paper's radii (Sec. 4.1.2) and the
  output impedance of the RTCA (Sec. 4.2.1) run on **seed 001's own actuator**
  (:mod:`fsarm_sim.studies.rtca_bench`: its motor, gearbox, encoders and 1 kHz cascade on a
  blocked or load-driven output), the P gain calibrated once to the paper's 25 ms offset.
* The bend-angle estimate (Sec. 5.1) runs on the *held arm* (as
  :func:`fsarm_sim.studies.arm_metrics.torque_bandwidth` holds it: links on a huge armature, gravity off,
  outer loops off) with our joint-3 cascade following a desired shaft torque ``A sin(2 pi f t)``;
  the estimate is the controller's virtual torque sensor (``tau_model``), the truth the
  transmission's torque (``tau_shaft``, what seed 001's torque sensor reads).
* Bandwidth (Sec. 4.1.2) and output impedance (Sec. 4.2.1): :func:`fsarm_sim.studies.arm_metrics.
  torque_bandwidth` and :func:`fsarm_sim.studies.transparency.output_impedance` with **fixed** torque-PID
  gains ("the same PID gains for all spatial conditions"), at the paper's bend radii converted
  with ``φ = L_bend / R`` (``L_bend`` = 255 mm, Sec. 5.1). This is *our* controller, not seed
  001's (that comparison is ``not_implemented``), so only the trend is claimed.
* The flexible shaft's model accuracy vs bend (Sec. 3.3): the seed-000 series bench (eq. 8 fitted
  per side and bend, the analogue of seed 001's μ fitted per radius and sign).
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
BENDS_SEC51_DEG = (0.0, 20.0, 40.0, 60.0, 70.0, 80.0, 90.0)  # Sec. 5.1 fixed knee angles
BENDS_SEC51_QUICK_DEG = (0.0, 45.0, 90.0)
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


def model_accuracy_vs_bend(ctx: Context) -> Measured:
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import campaign as cp

    s = cp.BenchSettings(backend=ctx.backend, chirp_s=4.0 if ctx.quick else 10.0)
    shaft = load_catalogue().shaft()
    nrmse = []
    for r in R_CHARACTERISATION_M:
        b = _phi(r)
        cols = cp.series_test(shaft, b, s)
        f = cp.fit_series(cols, math.degrees(b))
        rms = math.sqrt((f.n_pos * f.rmse_pos**2 + f.n_neg * f.rmse_neg**2) / (f.n_pos + f.n_neg))
        span = float(np.max(cols["tau_s"]) - np.min(cols["tau_s"]))
        nrmse.append(100.0 * rms / span)
    return Measured(
        ours=nrmse,
        text="NRMSE " + " → ".join(f"{v:.3g}" for v in nrmse) + " %",
        details={"radius_mm": [1000 * r for r in R_CHARACTERISATION_M], "nrmse_pct": nrmse},
        note="our flexible shaft (9×450 prototype) on the series bench, eq. 8 fitted per side "
        "and bend (seed 001: μ fitted per radius and sign)",
    )


# ------------------------------------------------------------------------------ held arm


def held_torque_run(
    ctx: Context, transmission: str, bend_rad: float, amplitude_nm: float, duration_s: float
) -> dict[str, Any]:
    """Our joint-3 loop following ``amplitude sin(2 pi t)`` (1 Hz) of shaft torque, arm held."""
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.kernels import layout as L
    from fsarm_sim.sim.simulation import initial_state
    from fsarm_sim.studies.arm_metrics import held_arm, smoothstep

    cfg = SimConfig(transmission=transmission)
    sim, m33, t, table = held_arm(cfg, duration_s, bend_rad, math.radians(45.0), ctx.backend)
    m, d, st = sim.model, sim.data, sim.structure
    tau_d = amplitude_nm * smoothstep(t, 0.5) * np.sin(2.0 * math.pi * t)
    table[:, 8] = st.coef_s * tau_d / m33
    m.numeric(L.REF_NAME).data[:] = table.ravel()
    initial_state(m, d, st)
    cols, _ = sim.run(duration_s)
    cols = dict(cols)
    cols["controller_block"] = cfg.transmission_blocks()[1]
    return cols


def deadzone(ctx: Context) -> Measured:
    tr, block = _rtca()
    xs = np.linspace(-0.1, 0.1, 2001)
    zero = [x for x in xs if x != 0.0 and abs(tr.sensor_torque(block, float(x), 0.0)) == 0.0]
    width = (max(zero) - min(zero)) if zero else 0.0
    return Measured(
        ours=[width > 0.0],
        text=f"zero-torque band {math.degrees(width):.2f}° wide" if zero else "no dead zone",
    )


def _bend_runs(ctx: Context) -> list[dict[str, Any]]:
    bends = BENDS_SEC51_QUICK_DEG if ctx.quick else BENDS_SEC51_DEG
    return ctx.once(
        "001/sec51",
        lambda: [
            {"bend_deg": b, "cols": held_torque_run(ctx, "rtca", math.radians(b), 4.0, 2.5)}
            for b in bends
        ],
    )


def _sec51_errors(ctx: Context) -> tuple[float, float, list[dict[str, float]]]:
    tr, _ = _rtca()
    worst_with = worst_without = 0.0
    rows = []
    for run in _bend_runs(ctx):
        c = run["cols"]
        sel = c["t"] >= 1.0
        true = c["tau_shaft"][sel]
        with_bend = float(np.max(np.abs(c["tau_model"][sel] - true)))
        straight = np.array(
            [tr.sensor_torque(c["controller_block"], float(x), 0.0) for x in c["twist"][sel]]
        )
        without = float(np.max(np.abs(straight - true)))
        worst_with, worst_without = max(worst_with, with_bend), max(worst_without, without)
        rows.append({"bend_deg": run["bend_deg"], "with_bend": with_bend, "without_bend": without})
    return worst_with, worst_without, rows


def bend_compensated_error(ctx: Context) -> Measured:
    w, _, rows = _sec51_errors(ctx)
    return Measured(
        ours=w,
        text=f"max |error| {w:.3g} N·m",
        details={"rows": rows},
        note="rtca, our loop following 4 N·m at 1 Hz, held at each of Sec. 5.1's knee angles",
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


# ------------------------------------------------------------------------- bandwidth, Z


def _fixed_gains(transmission: str) -> Any:
    from fsarm_sim.engine.model import Gains, SimConfig

    return SimConfig(transmission=transmission, gains=Gains(gain_schedule=False))


def bandwidth_hz(cfg: Any, bend_rad: float, ctx: Context) -> float:
    """:func:`fsarm_sim.studies.arm_metrics.torque_bandwidth`; when the -3 dB point lies above its
    default chirp (60 Hz, analysed to 40 Hz) the chirp is widened to 200 Hz."""
    from fsarm_sim.studies.arm_metrics import torque_bandwidth

    for f_stop in (60.0, 200.0):
        bw = float(
            torque_bandwidth(cfg, bend_rad, backend=ctx.backend, f_stop_hz=f_stop).bandwidth_hz
        )
        if math.isfinite(bw):
            return bw
    raise ValueError(f"no -3 dB point below 133 Hz at bend {math.degrees(bend_rad):.0f} deg")


def _bandwidths(ctx: Context, transmission: str) -> Measured:
    cfg = _fixed_gains(transmission)
    bw = [bandwidth_hz(cfg, _phi(r), ctx) for r in R_BANDWIDTH_M]
    return Measured(
        ours=bw,
        text=" → ".join(f"{v:.3g}" for v in bw) + " Hz (R = ∞, 450, 300, 150 mm)",
        details={"radius_mm": [1000 * r for r in R_BANDWIDTH_M], "bandwidth_hz": bw},
        note=f"our joint-3 loop, torque-PID gains fixed at the straight stiffness; "
        f"φ = {BEND_LENGTH_M * 1000:g} mm / R",
    )


def bandwidth_rtca(ctx: Context) -> Measured:
    return _bandwidths(ctx, "rtca")


def bandwidth_flexible_shaft(ctx: Context) -> Measured:
    return _bandwidths(ctx, "flexible-shaft")


def _impedances(ctx: Context, transmission: str) -> list[Any]:
    from fsarm_sim.studies.transparency import output_impedance

    cfg = _fixed_gains(transmission)
    return ctx.once(
        f"001/Z/{transmission}",
        lambda: [output_impedance(cfg, _phi(r), backend=ctx.backend) for r in R_IMPEDANCE_M],
    )


def _level(z: Any) -> float:
    """The Bode magnitude's level: geometric mean of |Z| over the analysed band."""
    return float(np.exp(np.mean(np.log(z.magnitude_nm_per_rad))))


def _impedance_trend(ctx: Context, transmission: str) -> Measured:
    zs = _impedances(ctx, transmission)
    level = [_level(z) for z in zs]
    low = [float(z.low_freq_nm_per_rad) for z in zs]
    return Measured(
        ours=level,
        text="|Z| level "
        + " → ".join(f"{v:.3g}" for v in level)
        + " N·m/rad; low-f "
        + " → ".join(f"{v:.3g}" for v in low),
        details={"radius_mm": [1000 * r for r in R_IMPEDANCE_M], "level": level, "low_f": low},
        note="joint-side |Z| = |τ_out/q3| with the torque loop at 0 N·m (fixed gains); level = "
        "geometric mean over 0.75-13 Hz",
    )


def impedance_flexible_shaft(ctx: Context) -> Measured:
    return _impedance_trend(ctx, "flexible-shaft")


def transparent_low_f(ctx: Context) -> Measured:
    worst = 0.0
    for name in ("flexible-shaft", "rtca"):
        for z in _impedances(ctx, name):
            worst = max(worst, float(z.low_freq_nm_per_rad / z.passive_nm_per_rad))
    return Measured(ours=worst, text=f"|Z(low f)| ≤ {100 * worst:.2g} % of the passive stiffness")


def impedance_vs_frequency(ctx: Context) -> Measured:
    ratios = []
    for name in ("flexible-shaft", "rtca"):
        for z in _impedances(ctx, name):
            mag = z.magnitude_nm_per_rad
            ratios.append(float(mag[-1] / mag[0]))
    worst = min(ratios)
    return Measured(
        ours=worst, text=f"|Z(top)|/|Z(bottom)| ≥ {worst:.3g}", details={"ratios": ratios}
    )


# ------------------------------------------------------------------------ MasterFlex08


def _masterflex08_eq3(side: int) -> Measured:
    import importlib

    from fsarm_sim.plant.shaft import load_catalogue

    try:
        sel = importlib.import_module("fsarm_sim.studies.shaft_selection")
    except ImportError:
        sel = importlib.import_module("fsarm_sim.studies.selection")
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


def _bench(ctx: Context) -> tuple[Any, Any]:
    """Seed 001's actuator (:mod:`fsarm_sim.studies.rtca_bench`) and its calibrated P loop."""
    from fsarm_sim.studies import rtca_bench as rb

    def build() -> tuple[Any, Any]:
        act = rb.Rtca001()
        return act, rb.Pid(rb.calibrate_kp(act), 0.0, 0.0)

    return ctx.once("001/bench", build)


def _bench_tracking(ctx: Context) -> Any:
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = _bench(ctx)
    return ctx.once("001/bench/track6", lambda: rb.tracking(act, pid, periods=5))


BENCH_NOTE = (
    "seed 001's bench (studies.rtca_bench): EC-4pole 30 + 86:1, 192 rpm / 12 N·m limits, 500 CPT "
    "motor and 2000 CPT shaft encoders, 1 kHz velocity PI and torque loop, output blocked; the "
    "P gain is calibrated to the paper's 25 ms offset (I, D = 0)"
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
            "kp_rad_s_per_nm": pid.kp,
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
        "poles + 1 zero, -3 dB of the fit; the same gain at every R",
    )


def bench_bandwidth_straight(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 0)


def bench_bandwidth_r450(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 1)


def bench_bandwidth_r300(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 2)


def bench_bandwidth_r150(ctx: Context) -> Measured:
    return _bench_bandwidth(ctx, 3)


def bench_impedance(ctx: Context) -> Measured:
    from fsarm_sim.studies import rtca_bench as rb

    act, pid = _bench(ctx)
    zs = ctx.once(
        "001/bench/Z",
        lambda: [rb.output_impedance(act, pid, radius_m=r) for r in R_IMPEDANCE_M],
    )
    level = [z.level for z in zs]
    slow = ctx.once(
        "001/bench/felt-slow",
        lambda: [rb.interaction(act, pid, radius_m=r) for r in R_IMPEDANCE_M],
    )
    return Measured(
        ours=level,
        text="|T̂/θ̇_s| level "
        + " → ".join(f"{v:.3g}" for v in level)
        + " N·m·s/rad; interaction RMS "
        + " → ".join(f"{z.interaction_rms_nm:.3g}" for z in zs)
        + " N·m; on a slow 20° sine (1.2 s) the load feels "
        + " → ".join(f"{x.felt_rms_nm:.3g}" for x in slow)
        + " N·m, T̂ reads "
        + " → ".join(f"{x.estimate_rms_nm:.3g}" for x in slow),
        details={
            "slow_felt_rms_nm": [x.felt_rms_nm for x in slow],
            "slow_estimate_rms_nm": [x.estimate_rms_nm for x in slow],
            "radius_mm": [1000 * r for r in R_IMPEDANCE_M],
            "level": level,
            "peak": [float(np.max(z.magnitude)) for z in zs],
            "peak_hz": [z.peak_hz for z in zs],
            "interaction_rms_nm": [z.interaction_rms_nm for z in zs],
            "freq_hz": [z.freq_hz for z in zs],
            "magnitude": [z.magnitude for z in zs],
        },
        note=BENCH_NOTE + "; the load moves the output through a 20° log chirp 0.1-10 Hz over "
        "60 s (also in --quick: shorter sweeps do not resolve 0.1-1 Hz; ideal position mode), "
        "torque set-point 0; Z = T̂_s/θ̇_s as the paper defines it (Sec. 4.2.1); "
        "level = geometric mean over the bands. With the loop velocity-sourced, T̂/θ̇_s = "
        "μK/(s + μK·Kp): a smaller μ lowers it at every frequency. The shaft's bend-dependent "
        "friction (the rtca transmission's slip element, 0.032 N·m · exp(1.16 |φ|), sized from "
        "Sec. 3.3's 0.32 → 2.3 % NRMSE) is felt by the load but not seen by T̂: T̂ reads the "
        "twist, which the motor's velocity loop sets, and the estimated 30 Hz EPOS3 loop rejects "
        "the friction. Tried on this bench, none makes the level rise: ×10 that friction, also "
        "with an 8 Hz velocity loop; a Coulomb drag on the rotor of 1 N·m straight growing as "
        "exp(1.16 φ); PI torque loops (Ki/Kp 1, 3, 4, 12 s⁻¹, Kp re-calibrated to 25 ms): with "
        "integral action |Z| rises with frequency to a peak that moves to lower frequency with "
        "bend (0.94 → 0.85 Hz at Ki/Kp 3), as Fig. 12 shows, but below the peak it rises ≤ 1 % "
        "and above it falls with μ (linear theory: |Z| = 1/|jω/(μK) + C(jω)e^(-jωτ)|, a peak "
        "of 1/Kp whatever μ). The classic Ziegler-Nichols PID (the paper's tuning method) with "
        "1, 5 or 10 ms bus delays moves the peak to lower frequency with bend too (5.37 → 5.14 "
        "Hz at 5 ms), but its level is not monotonic (0.049 → 0.056 → 0.053 at 10 ms) and its "
        "1 Hz run leads instead of lagging 25 ms. The paper's causes (friction, fixed PID gains) "
        "can raise T̂/θ̇_s by ≥ 10 % only through a motor that follows worse when bent, i.e. a "
        "friction far above what Sec. 3.3's NRMSE allows or drive gains the paper does not print. What the load "
        "feels does rise with bend on slow motion (rtca_bench.interaction: the load moves the "
        "output through a 20° sine at the 1.2 s stride of Sec. 4.2.2, a stand-in for its gait "
        "profiles, which are only in a figure): the friction is felt, T̂ does not see it. The bands start "
        "where the analysed sweep starts (0.29 Hz; 0.4.0 also averaged 0.15-0.24 Hz, which the "
        "sweep had passed during its cut fade-in: leakage, and a spurious rise of the peak)",
    )


MEASURES: dict[str, MeasureFn] = {
    "fit_range": fit_range,
    "rating_6nm": rating_6nm,
    "table1_transcribed": table1_transcribed,
    "through_origin": through_origin,
    "tol_stiffer": tol_stiffer,
    "bend_needs_more_twist": bend_needs_more_twist,
    "mu_tol_250": mu_tol_250,
    "mu_lol_250": mu_lol_250,
    "model_accuracy_vs_bend": model_accuracy_vs_bend,
    "deadzone": deadzone,
    "bandwidth_rtca": bandwidth_rtca,
    "bandwidth_flexible_shaft": bandwidth_flexible_shaft,
    "bench_tracking_rmse": bench_tracking_rmse,
    "bench_estimate_error": bench_estimate_error,
    "bench_symmetric": bench_symmetric,
    "bench_bandwidth_straight": bench_bandwidth_straight,
    "bench_bandwidth_r450": bench_bandwidth_r450,
    "bench_bandwidth_r300": bench_bandwidth_r300,
    "bench_bandwidth_r150": bench_bandwidth_r150,
    "bench_impedance": bench_impedance,
    "impedance_flexible_shaft": impedance_flexible_shaft,
    "transparent_low_f": transparent_low_f,
    "impedance_vs_frequency": impedance_vs_frequency,
    "bend_compensated_error": bend_compensated_error,
    "bend_neglected_error": bend_neglected_error,
    "bend_compensation_gain": bend_compensation_gain,
    "masterflex08_eq3_tol": masterflex08_eq3_tol,
    "masterflex08_eq3_lol": masterflex08_eq3_lol,
    "one_table1_curve": one_table1_curve,
}
