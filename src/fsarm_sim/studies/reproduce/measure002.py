"""Seed 002: how ours is measured, on the qa-joint transmission's law.

* Stiffness ranges: the design law (eq. 13, a_S = b_S = 40 N·m) over the preset range of the
  transmission's block, K = d tau_J / d phi at the deflection where tau_J has the given value.
* Adjustment time: the stiffness drive's own rate law integrated from one end of the preset range
  to the other.
* Identification (Sec. V): the paper's clamped-link test on our law - the motor drives cyclic
  motions of constant speed (30, 60, 90 deg/s, "cyclic rectangular motions") within the elastic
  range at presets 3, 9, 15 deg, the Dahl friction state integrated at 1 ms, torque-sensor and
  encoder noise added - then eq. 17-19 by :func:`fsarm_sim.studies.identification.qa_joint_ls.identify`.
* Sec. VI throws (Fig. 10-12): :mod:`fsarm_sim.studies.qa_joint_experiments`, the two-mass bench
  of eq. 14-15 with Table V and the Table IV row of each preset; the best one-switch strike-out
  throw at each motor speed (the paper's premise: maximum deflection with one switching cycle).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from fsarm_sim.studies.reproduce.claims import Context, Measured, MeasureFn
from fsarm_sim.studies.reproduce.measure002_design import (
    DEG,
    DT,
    ENCODER_NOISE_RAD,
    PRESETS_DEG,
    PRESETS_QUICK_DEG,
    REVERSAL_BAND_RAD,
    SPEEDS_DEG_S,
    TORQUE_NOISE_NM,
    adjust_time,
    deflection_range,
    design_block,
    design_constants,
    nominal_stiffness_range,
    qa_law,
    stiffness_high,
    stiffness_low,
    torque_capacity,
)

# ------------------------------------------------------------------------- identification


def clamped_link_test(
    sigma_deg: float,
    speeds_deg_s: tuple[float, ...] = SPEEDS_DEG_S,
    seed: int = 0,
    *,
    amp_fraction: float = 0.9,
    cycles: int = 2,
    presliding_rad: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Sec. V on our law: the link clamped, the motor driving ``cycles`` rectangular velocity
    cycles of ``amp_fraction`` sigma at each speed (the Table IV row at ``sigma_deg``, the Dahl
    state integrated with explicit 1 ms steps; noise on the torque sensor and the encoders).
    Returns time, deflection, torque, speed label per sample, true block."""
    tr, qa = qa_law()
    overrides = qa.table_iv_overrides(sigma_deg)
    if presliding_rad is not None:
        overrides["presliding_rad"] = presliding_rad
    block = tr.block(overrides)
    sigma = sigma_deg * DEG
    amp = amp_fraction * sigma
    act = np.array([sigma, 0.0, 0.0])
    t, x = 0.0, 0.0
    ts, xs, taus, labels = [], [], [], []
    for speed in speeds_deg_s:
        for _ in range(cycles):
            for target in (amp, -amp):
                d = 1.0 if target > x else -1.0
                while (target - x) * d > 0.0:
                    xdot = d * speed * DEG
                    ts.append(t)
                    xs.append(x)
                    labels.append(speed)
                    taus.append(qa.torque_nm(block, x, xdot, 0.0, act, 0))
                    act[1] = min(
                        1.0, max(-1.0, act[1] + DT * qa.state_rate(block, x, xdot, 0.0, act, 0, 1))
                    )
                    x += xdot * DT
                    t += DT
    rng = np.random.default_rng(seed)
    n = len(ts)
    phi = np.array(xs) + ENCODER_NOISE_RAD * rng.standard_normal(n)
    tau = np.array(taus) + TORQUE_NOISE_NM * rng.standard_normal(n)
    return np.array(ts), phi, tau, np.array(labels), block


def _identify(t: np.ndarray, phi: np.ndarray, tau: np.ndarray, sigma_deg: float) -> Any:
    from fsarm_sim.studies.identification import qa_joint_ls as ls

    return ls.identify(
        t,
        tau,
        sigma_deg * DEG,
        deflection_rad=phi,
        min_speed_rad_s=0.05,
        reversal_band_rad=REVERSAL_BAND_RAD,
    )


def _identification(ctx: Context) -> list[dict[str, Any]]:
    def run() -> list[dict[str, Any]]:
        _, qa = qa_law()
        rows = []
        for s in PRESETS_QUICK_DEG if ctx.quick else PRESETS_DEG:
            t, phi, tau, labels, _ = clamped_link_test(s)
            fit = _identify(t, phi, tau, s)
            rows.append(
                {
                    "sigma_deg": s,
                    "true": qa.TABLE_IV[s],
                    "fit": (fit.a_s_nm, fit.b_s_nm, fit.a_f_nm, fit.b_f_nm),
                    "data": (t, phi, tau, labels),
                }
            )
        return rows

    return ctx.once("002/identification", run)


def _identified(ctx: Context, idx: tuple[int, int], names: str, note: str = "") -> Measured:
    """The largest relative error of the fitted coefficients ``idx`` over the presets."""
    worst = 0.0
    rows = []
    for r in _identification(ctx):
        for i in idx:
            e = abs(r["fit"][i] / r["true"][i] - 1.0)
            worst = max(worst, e)
        rows.append({"sigma_deg": r["sigma_deg"], "table_iv": r["true"], "fitted": r["fit"]})
    return Measured(
        ours=worst,
        text=f"largest |fit/Table IV − 1| of {names}: {100 * worst:.2f} %",
        details={"rows": rows},
        note=note,
    )


def identify_stiffness(ctx: Context) -> Measured:
    note = "clamped-link test on our law with torque (0.02 N·m) and encoder noise"
    return _identified(ctx, (0, 1), "a_S, b_S", note)


def identify_friction(ctx: Context) -> Measured:
    return _identified(ctx, (2, 3), "a_F, b_F")


def friction_velocity(ctx: Context) -> Measured:
    r = _identification(ctx)[0]
    t, phi, tau, labels = r["data"]
    fits = {}
    for speed in (30.0, 90.0):
        sel = labels == speed
        fits[speed] = _identify(t[sel], phi[sel], tau[sel], r["sigma_deg"])
    a = (fits[30.0].a_f_nm, fits[30.0].b_f_nm)
    b = (fits[90.0].a_f_nm, fits[90.0].b_f_nm)
    worst = max(abs(y / x - 1.0) for x, y in zip(a, b, strict=True))
    return Measured(
        ours=worst,
        text=f"a_F, b_F at 30 °/s {a[0]:.3g}, {a[1]:.3g}; at 90 °/s {b[0]:.3g}, {b[1]:.3g} N·m",
        details={"sigma_deg": r["sigma_deg"]},
    )


def spring_energy(ctx: Context) -> Measured:
    tr, qa, block = design_block()
    names = tr.param_names()
    sigma = float(block[names.index("sigma_max")])
    e = float(qa.elastic_potential_j(block, sigma, sigma))
    return Measured(
        ours=e,
        text=f"{e:.3g} J (eq. 13 integrated to φ = σ = {math.degrees(sigma):g}°)",
        note="eq. 13's two springs: the energy of the loaded one at the end stop",
    )


# ---------------------------------------------------------------------- Sec. VI throws

EFF_SPEEDS_DEG_S = (60.0, 75.0, 90.0, 100.0, 120.0)  # estimate: Fig. 10's axis, values not printed
EFF_SPEEDS_QUICK_DEG_S = (60.0, 90.0, 120.0)
EFF_PRESETS_DEG = (15.0, 11.0, 7.0)  # soft -> stiff (Table IV rows; 3 deg is infeasible at 75)
ADJUST_SPEED_SEARCH = (70.0, 110.0)


def _qx() -> Any:
    from fsarm_sim.studies import qa_joint_experiments

    return qa_joint_experiments


def _throw(ctx: Context, sigma_deg: float, v_deg_s: float, adjust: str = "none") -> Any:
    qx = _qx()
    return ctx.once(
        f"002/throw/{sigma_deg}/{v_deg_s}/{adjust}",
        lambda: qx.best_throw(qx.bench(sigma_deg), v_deg_s, adjust=adjust),
    )


def efficiency_trend(ctx: Context) -> Measured:
    speeds = EFF_SPEEDS_QUICK_DEG_S if ctx.quick else EFF_SPEEDS_DEG_S
    series: dict[str, list[float]] = {}
    for s in EFF_PRESETS_DEG:
        eps = [_throw(ctx, s, v).epsilon for v in speeds]
        series[f"σ = {s:g}°, over θ'_d {'/'.join(f'{v:g}' for v in speeds)} °/s"] = eps
    for v in (speeds[0], speeds[-1]):
        eps = [_throw(ctx, s, v).epsilon for s in EFF_PRESETS_DEG]
        series[f"θ'_d = {v:g} °/s, over σ 15/11/7° (stiffer)"] = eps
    bad = [k for k, e in series.items() if not all(math.isfinite(x) for x in e)]
    if bad:
        raise RuntimeError(f"infeasible throws in {bad}: no switch time meets the constraints")
    return Measured(
        ours=series,
        text="; ".join(f"{k}: " + ", ".join(f"{x:.2f}" for x in e) for k, e in series.items()),
        note="best one-switch throw per point on the eq. 14-15 bench (Table V, Table IV rows); "
        "the optimal control of [16] is not printed, its premise is: max deflection, one switch",
    )


def efficiency_27(ctx: Context) -> Measured:
    t = _throw(ctx, 7.0, 75.0)
    extra: dict[str, Any] = {"throw": t.__dict__}
    note = "ε at the claim's operating point (75 °/s, σ = 7°)"
    if not ctx.quick:
        grid = {
            (s, v): _throw(ctx, s, v).epsilon for s in EFF_PRESETS_DEG for v in EFF_SPEEDS_DEG_S
        }
        (s_b, v_b), e_b = max(
            ((k, e) for k, e in grid.items() if math.isfinite(e)), key=lambda kv: kv[1]
        )
        extra["grid_best"] = {"sigma_deg": s_b, "v_deg_s": v_b, "epsilon": e_b}
        note += f"; the largest on our grid is {e_b:.2f} at {v_b:g} °/s, σ = {s_b:g}°"
    return Measured(
        ours=t.epsilon,
        text=f"ε = {t.epsilon:.3g} (link {t.link_velocity_deg_s:.4g} °/s, switch at "
        f"{t.t_switch_s:.3g} s, φ_max {t.phi_max_deg:.3g}°, |τ_J| ≤ {t.tau_j_max_nm:.3g} N·m)",
        details=extra,
        note=note,
    )


def efficiency_largest_where(ctx: Context) -> Measured:
    """Where on the σ x θ'_d grid of efficiency_trend the largest ε lies."""
    grid = {(s, v): _throw(ctx, s, v).epsilon for s in EFF_PRESETS_DEG for v in EFF_SPEEDS_DEG_S}
    finite = [(k, e) for k, e in grid.items() if math.isfinite(e)]
    if not finite:
        raise RuntimeError("no feasible throw on the grid")
    (s_b, v_b), e_b = max(finite, key=lambda kv: kv[1])
    return Measured(
        ours=[s_b == 7.0, v_b == 75.0],
        text=f"largest ε {e_b:.3g} at σ = {s_b:g}°, θ'_d = {v_b:g} °/s (ε(7°, 75 °/s) = "
        f"{grid[(7.0, 75.0)]:.3g})",
        details={"grid": {f"{s:g}/{v:g}": e for (s, v), e in grid.items()}},
        note="grid σ "
        + "/".join(f"{s:g}" for s in EFF_PRESETS_DEG)
        + "°, θ'_d "
        + "/".join(f"{v:g}" for v in EFF_SPEEDS_DEG_S)
        + " °/s (Fig. 10's axis; 3° is infeasible at 75 °/s); where ε peaks is set by the "
        "throw, our one-switch reconstruction of the unprinted optimal control [16]",
    )


WINDOW_PRESETS_DEG = (3.0, 7.0, 11.0, 15.0)  # Table IV's rows
WINDOW_SPEEDS_DEG_S = (10.0, 30.0, 60.0, 90.0, 130.0, 200.0, 400.0)  # estimate: wide, log-spaced


def speed_window(ctx: Context) -> Measured:
    """Per preset, which motor speeds admit a one-switch throw that reaches the maximum
    deflection within the constraints (Sec. VI's premise)."""
    rows = {
        s: [bool(_throw(ctx, s, v).feasible) for v in WINDOW_SPEEDS_DEG_S]
        for s in WINDOW_PRESETS_DEG
    }

    def bounded(flags: list[bool]) -> tuple[bool, bool]:
        if not any(flags):
            return False, False
        first, last = flags.index(True), len(flags) - 1 - flags[::-1].index(True)
        return first > 0, last < len(flags) - 1

    lows, highs = zip(*(bounded(f) for f in rows.values()), strict=True)
    return Measured(
        ours=[all(lows), all(highs)],
        text="; ".join(
            f"σ = {s:g}°: "
            + (
                "/".join(f"{v:g}" for v, ok in zip(WINDOW_SPEEDS_DEG_S, f, strict=True) if ok)
                or "none"
            )
            + " °/s feasible"
            for s, f in rows.items()
        ),
        details={f"{s:g}": f for s, f in rows.items()},
        note="speeds tried: " + "/".join(f"{v:g}" for v in WINDOW_SPEEDS_DEG_S) + " °/s",
    )


def link_velocity_twice(ctx: Context) -> Measured:
    pts = ((3.0, 60.0), (11.0, 100.0))  # Fig. 11's two cases
    eps = {f"σ = {s:g}°, {v:g} °/s": _throw(ctx, s, v).epsilon for s, v in pts}
    worst = max(eps.values(), key=lambda e: abs(e - 2.0))
    return Measured(
        ours=worst,
        text="final q'/θ'_d " + ", ".join(f"{k}: {e:.3g}" for k, e in eps.items()),
        details=eps,
        note="the case farther from 2 is judged",
    )


def _adjust_speed(ctx: Context) -> float:
    """Fig. 12's motor speed at sigma = 9 deg: the text's own numbers fix it - without adjustment
    the link reaches 266 / 1.2 ~ 222 deg/s - so it is the speed whose best constant-preset throw
    gives 222 deg/s (bisection)."""

    def run() -> float:
        qx = _qx()
        b = qx.bench(9.0)
        target = 266.0 / 1.2
        lo, hi = ADJUST_SPEED_SEARCH
        for _ in range(4 if ctx.quick else 7):
            mid = 0.5 * (lo + hi)
            if qx.best_throw(b, mid).link_velocity_deg_s < target:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    return ctx.once("002/adjust/v", run)


def stiffness_adjustment_266(ctx: Context) -> Measured:
    """Fig. 12 at sigma = 9 deg at the speed of :func:`_adjust_speed`; ours is the best eq. 20
    throw there."""
    qx = _qx()
    b = qx.bench(9.0)
    v = _adjust_speed(ctx)
    const = qx.best_throw(b, v)
    drive = qx.best_throw(b, v, adjust="drive")
    ideal = qx.best_throw(b, v, adjust="ideal")
    gain = drive.link_velocity_deg_s / const.link_velocity_deg_s - 1.0
    return Measured(
        ours=drive.link_velocity_deg_s,
        text=f"{drive.link_velocity_deg_s:.4g} °/s with eq. 20 ({100 * gain:+.1f} % vs "
        f"{const.link_velocity_deg_s:.4g} °/s constant) at θ'_d = {v:.3g} °/s; ideal adjuster "
        f"{ideal.link_velocity_deg_s:.4g} °/s",
        details={
            "v_deg_s": v,
            "constant": const.__dict__,
            "drive": drive.__dict__,
            "ideal": ideal.__dict__,
        },
        note="our stiffness drive (Table III: full range in 0.12 s) follows σ_d = φ in the "
        "relaxation phase; the speed is set so that the constant-σ throw gives 266/1.2 °/s",
    )


LOWEST_SPEED_STEPS = 5  # bisection steps below the window's grid (30 deg/s gaps -> ~1 deg/s)


def low_stiffness_needs_faster(ctx: Context) -> Measured:
    """The lowest feasible motor speed per preset: the window's grid (:func:`speed_window`)
    brackets it, a bisection between the last infeasible and the first feasible grid speed
    finds it (the grid alone ties every preset at one grid step)."""
    lowest: dict[float, float] = {}
    for s in WINDOW_PRESETS_DEG:
        ok = [v for v in WINDOW_SPEEDS_DEG_S if _throw(ctx, s, v).feasible]
        if not ok or ok[0] == WINDOW_SPEEDS_DEG_S[0]:
            lowest[s] = min(ok) if ok else math.inf  # no bracket below: the grid's value
            continue
        hi = ok[0]
        lo_v = WINDOW_SPEEDS_DEG_S[WINDOW_SPEEDS_DEG_S.index(hi) - 1]
        for _ in range(LOWEST_SPEED_STEPS):
            mid = 0.5 * (lo_v + hi)
            if _throw(ctx, s, mid).feasible:
                hi = mid
            else:
                lo_v = mid
        lowest[s] = hi
    lo = [lowest[s] for s in WINDOW_PRESETS_DEG]
    found = all(math.isfinite(x) for x in lo)  # a preset with no feasible speed shows nothing
    rises = found and lo[-1] > lo[0]
    never_falls = found and all(b >= a for a, b in itertools.pairwise(lo))
    return Measured(
        ours=[rises, never_falls],
        text="lowest feasible speed: "
        + ", ".join(f"σ = {s:g}°: {lowest[s]:g} °/s" for s in WINDOW_PRESETS_DEG),
        details={f"{s:g}": lowest[s] for s in WINDOW_PRESETS_DEG},
        note="the lowest speed found to "
        f"{30.0 / 2**LOWEST_SPEED_STEPS:.2g} °/s by bisection inside the window's grid ("
        + "/".join(f"{v:g}" for v in WINDOW_SPEEDS_DEG_S)
        + " °/s)",
    )


def adjustment_raises_joint_torque(ctx: Context) -> Measured:
    """Fig. 12 at sigma = 9 deg: the constant-preset best throw and the eq. 20 throw (the
    module's stiffness drive) at the same speed and switch time; mean tau_J from the moment the
    adjuster leaves the preset to the first end of the two throws."""
    qx = _qx()
    b = qx.bench(9.0)
    v = _adjust_speed(ctx)
    const = qx.best_throw(b, v)
    ts = np.array([const.t_switch_s])
    tc = qx.simulate_throws(b, v * DEG, ts, keep_trace=True)
    td = qx.simulate_throws(b, v * DEG, ts, adjust="drive", keep_trace=True)
    t = np.asarray(td.traces["t"])[:, 0]
    sig = np.asarray(td.traces["sigma"])[:, 0]
    moved = np.flatnonzero(np.abs(sig - sig[0]) > 1e-9)
    if moved.size == 0:
        return Measured(ours=[False], text="the adjuster never left the preset")
    ends = [x for x in (tc.t_final[0], td.t_final[0]) if np.isfinite(x)]
    end = float(min(ends)) if ends else float(t[-1])
    w = (t >= t[moved[0]]) & (t <= end)
    mc = float(np.mean(np.asarray(tc.traces["tau_j"])[w, 0]))
    md = float(np.mean(np.asarray(td.traces["tau_j"])[w, 0]))
    return Measured(
        ours=[md > mc],
        text=f"mean τ_J {md:.3g} N·m with eq. 20 vs {mc:.3g} N·m constant over "
        f"{t[moved[0]]:.3g}-{end:.3g} s (θ'_d = {v:.3g} °/s, switch {const.t_switch_s:.3g} s)",
        details={"mean_tau_j_drive_nm": md, "mean_tau_j_const_nm": mc, "v_deg_s": v},
        note="the stiffness drive (Table III: full range in 0.12 s) follows σ_d = φ in the "
        "relaxation phase; same speed as 002-stiffness-adjustment-266",
    )


# Sec. VII gives no lever arm r of the impact point: the claims are judged at every r of this
# range (estimate: a forearm-length link, 0.3-0.6 m, for the link's 0.524 kg m^2 of Table V;
# fixed before any impact was run for the report); ours is the worst case over r
IMPACT_LEVERS_M = (0.3, 0.45, 0.6)
IMPACT_STIFFEST_DEG, IMPACT_SOFTEST_DEG = 3.0, 15.0  # "covering the entire range" (Table IV)
IMPACT_NOTE = (
    "4.2 kg at 1.07 m/s on the link at lever arm r (not printed: judged at every r of "
    "{levers} m, the worst case), the joint in position control (Table V's PD), a stiff "
    "linear contact (qa_joint_experiments.impact, estimates)"
)


def _impacts(ctx: Context) -> dict[tuple[float, float], float]:
    """Peak |tau_J| per (preset, lever arm)."""
    qx = _qx()
    return ctx.once(
        "002/impacts",
        lambda: {
            (s, r): qx.impact(s, r).peak_joint_torque_nm
            for s in (IMPACT_STIFFEST_DEG, IMPACT_SOFTEST_DEG)
            for r in IMPACT_LEVERS_M
        },
    )


def _impact_text(peaks: dict[tuple[float, float], float]) -> str:
    return "; ".join(
        f"r = {r:g} m: σ {IMPACT_STIFFEST_DEG:g}° {peaks[(IMPACT_STIFFEST_DEG, r)]:.3g} N·m, "
        f"σ {IMPACT_SOFTEST_DEG:g}° {peaks[(IMPACT_SOFTEST_DEG, r)]:.3g} N·m"
        for r in IMPACT_LEVERS_M
    )


def impact_below_capacity(ctx: Context) -> Measured:
    peaks = _impacts(ctx)
    worst = max(peaks[(IMPACT_STIFFEST_DEG, r)] for r in IMPACT_LEVERS_M)
    return Measured(
        ours=worst,
        text=f"largest peak |τ_J| at σ = {IMPACT_STIFFEST_DEG:g}°: {worst:.3g} N·m; "
        + _impact_text(peaks),
        details={f"{s:g}/{r:g}": v for (s, r), v in peaks.items()},
        note=IMPACT_NOTE.format(levers="/".join(f"{r:g}" for r in IMPACT_LEVERS_M))
        + ". Where ours departs: the lever arm does not set the verdict (above 40 N·m at every "
        "r), the contact does: ours is nearly elastic (damping ratio 0.05, an estimate for "
        "metal on metal; the paper prints no restitution), so the link takes almost twice the "
        "impactor's momentum share; a more dissipative contact (damping ratio 0.3, checked once "
        "at r = 0.45 m) gives 34.9 N·m, below 40. Not tuned to this claim",
    )


def impact_halved(ctx: Context) -> Measured:
    peaks = _impacts(ctx)
    ratios = [
        peaks[(IMPACT_SOFTEST_DEG, r)] / peaks[(IMPACT_STIFFEST_DEG, r)] for r in IMPACT_LEVERS_M
    ]
    worst = max(ratios, key=lambda q: abs(q / 0.5 - 1.0))
    return Measured(
        ours=worst,
        text="peak |τ_J| σ 15° / σ 3°: "
        + ", ".join(f"{q:.3g} (r = {r:g} m)" for q, r in zip(ratios, IMPACT_LEVERS_M, strict=True))
        + f"; judged: {worst:.3g}",
        details={"ratios": ratios, "levers_m": list(IMPACT_LEVERS_M)},
        note=IMPACT_NOTE.format(levers="/".join(f"{r:g}" for r in IMPACT_LEVERS_M))
        + "; the ratio farthest from the paper's 0.5 is judged",
    )


ADJUSTER_LAG_MIN_DEG = 0.1  # the claim's bounds (002-adjuster-slightly-slow), estimates
ADJUSTER_LAG_SLIGHT = 0.3


def adjuster_slightly_slow(ctx: Context) -> Measured:
    """Fig. 12 at sigma = 9 deg: the best eq. 20 throw through the stiffness drive (Table III
    rate) at the speed of :func:`_adjust_speed`, traced; from the moment the adjuster leaves the
    preset to the end of the throw, sigma against eq. 20's sigma_d = phi (clamped to the preset
    range, as the drive is commanded)."""
    from fsarm_sim.plant.transmissions import qa_joint as qa

    qx = _qx()
    b = qx.bench(9.0)
    v = _adjust_speed(ctx)
    drive = qx.best_throw(b, v, adjust="drive")
    if not drive.feasible:
        return Measured(ours=[False, False], text="no feasible eq. 20 throw at this speed")
    td = qx.simulate_throws(
        b, v * DEG, np.array([drive.t_switch_s]), adjust="drive", keep_trace=True
    )
    t = np.asarray(td.traces["t"])[:, 0]
    sig = np.asarray(td.traces["sigma"])[:, 0]
    phi = np.asarray(td.traces["phi"])[:, 0]
    moved = np.flatnonzero(np.abs(sig - sig[0]) > 1e-9)
    if moved.size == 0:
        return Measured(ours=[False, False], text="the adjuster never left the preset")
    end = float(td.t_final[0]) if np.isfinite(td.t_final[0]) else float(t[-1])
    w = (t >= t[moved[0]]) & (t <= end)
    lo, hi = float(b.block[qa.I_SIGMA_MIN]), float(b.block[qa.I_SIGMA_MAX])
    sig_d = np.clip(phi[w], lo, hi)
    lag = float(np.max(np.abs(sig[w] - sig_d))) / DEG
    travel = (float(sig[0]) - float(np.min(sig_d))) / DEG
    share = lag / travel if travel > 0.0 else math.inf
    return Measured(
        ours=[lag >= ADJUSTER_LAG_MIN_DEG, share <= ADJUSTER_LAG_SLIGHT],
        text=f"largest |σ − σ_d| {lag:.3g}° = {100 * share:.3g} % of the {travel:.3g}° the "
        f"preset travels ({t[moved[0]]:.3g}-{end:.3g} s, θ'_d = {v:.3g} °/s, switch "
        f"{drive.t_switch_s:.3g} s)",
        details={"lag_deg": lag, "travel_deg": travel, "v_deg_s": v},
        note="the stiffness drive (Table III: full range in 0.12 s, 002-adjust-time) commanded "
        "with σ_d = φ clamped to the preset range in the relaxation phase; same speed as "
        "002-stiffness-adjustment-266. The 30 % bound of 'slightly' is the claim's estimate; "
        "the drive's rate and its first-order lag are the module's (qa_joint: sigma_rate, "
        "sigma_tau)",
    )


MEASURES: dict[str, MeasureFn] = {
    "impact_below_capacity": impact_below_capacity,
    "impact_halved": impact_halved,
    "adjuster_slightly_slow": adjuster_slightly_slow,
    "low_stiffness_needs_faster": low_stiffness_needs_faster,
    "adjustment_raises_joint_torque": adjustment_raises_joint_torque,
    "speed_window": speed_window,
    "efficiency_largest_where": efficiency_largest_where,
    "efficiency_trend": efficiency_trend,
    "efficiency_27": efficiency_27,
    "link_velocity_twice": link_velocity_twice,
    "stiffness_adjustment_266": stiffness_adjustment_266,
    "spring_energy": spring_energy,
    "design_constants": design_constants,
    "nominal_stiffness_range": nominal_stiffness_range,
    "stiffness_low": stiffness_low,
    "stiffness_high": stiffness_high,
    "deflection_range": deflection_range,
    "adjust_time": adjust_time,
    "torque_capacity": torque_capacity,
    "identify_stiffness": identify_stiffness,
    "identify_friction": identify_friction,
    "friction_velocity": friction_velocity,
}
