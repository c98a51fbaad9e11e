"""Seed 003: how ours is measured.

The model-selection workflow of Sec. 6 (experiments A, B and C) on a simulated ATTRACTOR bench
around our magnetic-spring law: :mod:`fsarm_sim.studies.magnetic_spring_selection` (the bench and
its estimates: inertia, flywheel unbalance, bearing damping, sampling period, encoder resolution)
and :mod:`fsarm_sim.studies.identification.magnetic_spring_models` (eq. 1 and eq. 3 fits, models
A-F of Table 3, Table 4's criteria). Eq. 1 and J are the ones identified in experiments A and B,
as in the paper; the trials of experiment C are split into two equinumerous halves, teaching and
verifying (Sec. 6.1).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fsarm_sim.studies.reproduce.claims import Context, Measured, MeasureFn

DEG = math.pi / 180.0
DISTANCES_M = (0.0, 0.004, 0.008)
MODELS = ("A", "B", "C", "D", "E", "F")


def _ms() -> tuple[Any, Any]:
    from fsarm_sim.plant import transmissions
    from fsarm_sim.plant.transmissions import magnetic_spring

    return transmissions.get("magnetic-spring"), magnetic_spring


def _study(ctx: Context) -> Any:
    def run() -> Any:
        from fsarm_sim.studies import magnetic_spring_selection as sel

        cfg = sel.BenchConfig(trial_s=3.0) if ctx.quick else sel.BenchConfig()
        return sel.run_study(cfg, free_run=not ctx.quick)

    return ctx.once("003/study", run)


def experiment_c(ctx: Context) -> dict[str, dict[str, Any]]:
    """Per model: Table 4's criteria on both halves and the fitted parameters."""
    st = _study(ctx)
    out: dict[str, dict[str, Any]] = {}
    for m in MODELS:  # Table 3's A-F (the study also fits A_L, F_L: in its table)
        r = st.rows[m]
        out[m] = {
            "mse_teach": r.teaching.mse,
            "mse_verify": r.verifying.mse,
            "one_minus_r2adj_teach": r.teaching.one_minus_r2_adj,
            "one_minus_r2adj_verify": r.verifying.one_minus_r2_adj,
            "se_teach": r.teaching.se,
            "se_verify": r.verifying.se,
            "bic_teach": r.teaching.bic,
            "bic_verify": r.verifying.bic,
            "v": r.fit.v,
            "params": list(r.fit.params),
        }
    return out


def _mse(ctx: Context) -> dict[str, float]:
    return {m: r["mse_verify"] for m, r in experiment_c(ctx).items()}


def model_ranking(ctx: Context) -> Measured:
    res = experiment_c(ctx)
    mse = _mse(ctx)
    st = _study(ctx)
    return Measured(
        ours=mse,
        text="MSE " + ", ".join(f"{m} {mse[m]:.4g}" for m in MODELS) + " (rad/s²)²",
        details={
            "table4": st.table(),
            **{m: {k: v for k, v in r.items() if k != "params"} for m, r in res.items()},
        },
        note="simulated bench (magnetic_spring_selection): eq. 1 and J identified in "
        f"experiments A/B (J = {st.inertia_kgm2:.4g} kg·m²); bench estimates: J 0.01 kg·m², "
        "flywheel unbalance 9.8 mN·m, bearing damping 2e-4 N·m·s/rad, 16-bit encoders, T = 5 ms",
    )


def _reduction(ctx: Context, a: str, b: str) -> Measured:
    mse = _mse(ctx)
    red = 1.0 - mse[b] / mse[a]
    return Measured(ours=red, text=f"MSE {a} {mse[a]:.4g} → {b} {mse[b]:.4g} ({-100 * red:+.1f} %)")


def friction_term(ctx: Context) -> Measured:
    return _reduction(ctx, "A", "B")


def unbalance_term(ctx: Context) -> Measured:
    """Table 4's C -> D gain on the simulated bench, whose flywheel unbalance is the bench's
    estimate (BenchConfig: 1 kg at 1 mm, w = 9.8 mN*m, x = 0.4 rad), not the authors' flywheel."""
    m = _reduction(ctx, "C", "D")
    m.note = (
        "the bench's flywheel unbalance is an estimate (1 kg at 1 mm eccentricity, w = 9.8 "
        "mN·m, 1/5 of the bearing friction; the text gives neither w, x nor the flywheel's "
        "mass and eccentricity) and the C → D gain follows its size; the paper's MSEs are "
        "~300× ours, its unbalance and measurement noise are not printed"
    )
    return m


def output_damping_term(ctx: Context) -> Measured:
    m = _reduction(ctx, "D", "E")
    m.ours = abs(m.ours)
    return m


def relative_damping_term(ctx: Context) -> Measured:
    return _reduction(ctx, "D", "F")


def stable_range(ctx: Context) -> Measured:
    _, ms = _ms()
    v = math.degrees(ms.stable_range_rad(0.0))
    return Measured(
        ours=v, text=f"{v:.3g}°", note="shape coefficients were solved from 31.5°/19.7°"
    )


def linear_range(ctx: Context) -> Measured:
    _, ms = _ms()
    v = math.degrees(ms.linear_range_rad(0.0))
    return Measured(
        ours=v, text=f"{v:.3g}°", note="shape coefficients were solved from 31.5°/19.7°"
    )


def kinetic_friction(ctx: Context) -> Measured:
    """Experiment B as the paper identifies it: eq. 3 fitted to the drops (Sec. 6.2)."""
    tr, _ = _ms()
    st = _study(ctx)
    v = float(st.friction_b_nm)
    truth = float(tr.block()[tr.param_names().index("tau_fr")])
    return Measured(
        ours=v,
        text=f"{v:.3g} N·m (eq. 3 fitted to the simulated drops of experiment B)",
        details={"model_parameter_nm": truth, "inertia_kgm2": st.inertia_kgm2},
        note=f"the bench's bearing friction parameter is {truth:g} N·m (seed 003 Sec. 7.1); the "
        "eq. 3 fit sees its tanh form and the flywheel unbalance as part of it",
    )


def stiffness_vs_distance(ctx: Context) -> Measured:
    _, ms = _ms()
    ds = (0.0, 0.004, 0.008, 0.012)
    k = [float(ms.stiffness_at_equilibrium(d)) for d in ds]
    return Measured(
        ours=k,
        text="k_sp " + " → ".join(f"{v:.3g}" for v in k) + " N·m/rad (d = 0, 4, 8, 12 mm)",
    )


def negative_stiffness(ctx: Context) -> Measured:
    tr, _ = _ms()
    block = tr.block()
    ks = [tr.module.stiffness_nm_per_rad(block, a * DEG, 0.0) for a in (35.0, 45.0, 55.0)]
    return Measured(
        ours=[all(k < 0.0 for k in ks)], text="K at 35/45/55°: " + ", ".join(f"{k:.3g}" for k in ks)
    )


def three_equilibria(ctx: Context) -> Measured:
    tr, _ = _ms()
    block = tr.block()
    xs = np.radians(np.linspace(-60.0, 60.0, 241))
    worst = max(
        abs(
            tr.sensor_torque(block, float(x) + 2.0 * math.pi / 3.0, 0.0)
            - tr.sensor_torque(block, float(x), 0.0)
        )
        for x in xs
    )
    return Measured(ours=[worst < 1e-9], text=f"max |τ(φ+120°) − τ(φ)| = {worst:.2g} N·m")


def _linearised(ctx: Context) -> dict[str, dict[str, float]]:
    st = _study(ctx)
    out: dict[str, dict[str, float]] = {}
    for lin, full in (("AL", "A"), ("FL", "F")):
        rl, rf = st.rows[lin], st.rows[full]
        out[lin] = {
            "teach": rl.teaching.mse / rf.teaching.mse,
            "verify": rl.verifying.mse / rf.verifying.mse,
        }
    return out


def _within(x: float, paper: float, factor: float) -> bool:
    return x > 1.0 and paper / factor <= x <= paper * factor


def _linearised_factors(ctx: Context, half: str, paper: dict[str, float], f: float) -> Measured:
    r = _linearised(ctx)
    return Measured(
        ours=[_within(r[m][half], paper[m], f) for m in ("AL", "FL")],
        text=f"A_L/A ×{r['AL'][half]:.3g}, F_L/F ×{r['FL'][half]:.3g} ({half} MSE)",
        details=r,
        note="the trials' share beyond the critical angle (where the linearised spring is "
        "wrong) sets these ratios; the paper does not give its share",
    )


def linearised_teaching(ctx: Context) -> Measured:
    return _linearised_factors(ctx, "teach", {"AL": 1.23, "FL": 1.55}, 2.0)


def linearised_verifying(ctx: Context) -> Measured:
    return _linearised_factors(ctx, "verify", {"AL": 35.6, "FL": 76.6}, 3.0)


def model_ranking_teaching(ctx: Context) -> Measured:
    mse = {m: r["mse_teach"] for m, r in experiment_c(ctx).items()}
    return Measured(ours=mse, text="MSE " + ", ".join(f"{m} {mse[m]:.4g}" for m in MODELS))


def bic_ranking(ctx: Context) -> Measured:
    bic = {m: float(r["bic_verify"]) for m, r in experiment_c(ctx).items()}
    return Measured(
        ours=bic,
        text="BIC " + ", ".join(f"{m} {bic[m]:.6g}" for m in MODELS),
        note="BIC = n ln(SSE/n) + k ln(n) on the verifying half",
    )


def eq2_from_eq1(ctx: Context) -> Measured:
    tr, ms = _ms()
    worst = 0.0
    for d in DISTANCES_M:
        block = tr.block({"d": d})
        h = 1e-6
        slope = (tr.sensor_torque(block, h, 0.0) - tr.sensor_torque(block, -h, 0.0)) / (2 * h)
        k = float(ms.stiffness_at_equilibrium(d))
        worst = max(worst, abs(slope / k - 1.0))
    return Measured(ours=worst, text=f"largest relative difference {worst:.2g}")


def fms_vs_ams_safe_range(ctx: Context) -> Measured:
    from fsarm_sim.studies import magnetic_spring_arc as arc

    fms, ams = arc.compare()
    flags = [fms.safe_deg[f] > ams.safe_deg[f] for f in arc.SAFE_MARGINS]
    return Measured(
        ours=flags,
        text="safe range FMS / AMS: "
        + ", ".join(
            f"{100 * f:g} %: {fms.safe_deg[f]:.3g}° / {ams.safe_deg[f]:.3g}°"
            for f in arc.SAFE_MARGINS
        ),
        details={"fms": fms.__dict__, "ams": ams.__dict__},
        note="both shapes are eq. 1's three harmonics solved from their published stable/linear "
        "ranges (FMS 31.5°/19.7°, AMS 26°/11°), compared at equal maximal torque (the AMS's "
        "torque is not given); Sec. 3 leaves the safe margin to the user",
    )


def _free_run(ctx: Context) -> tuple[dict[str, float], dict[str, float], str]:
    """Sec. 6.2 / Figs. 13-15: eq. 7 fed with its own output over the verifying trials, the
    median RMS error of φ_out (deg) per model, within and beyond the critical angle."""
    fr = _study(ctx).free_run_deg
    within = next((v for k, v in fr.items() if k.startswith("within")), None)
    beyond = next((v for k, v in fr.items() if k.startswith("beyond")), None)
    if within is None or beyond is None:
        raise ValueError(f"the verifying half lacks a class of movement: {sorted(fr)}")
    text = "; ".join(
        f"{k}: " + ", ".join(f"{m} {e:.3g}°" for m, e in v.items()) for k, v in fr.items()
    )
    return within, beyond, text


FREE_RUN_NOTE = (
    "median RMS error of φ_out over the verifying trials of each class (our bench's trials; "
    "the paper shows its worst cases in Figs. 13-15 and gives no number)"
)


def free_run_beyond(ctx: Context) -> Measured:
    _, b, text = _free_run(ctx)
    return Measured(
        ours=[
            b["F"] < b["FL"],
            b["A"] < b["AL"],
            b["F"] == min(b[m] for m in ("A", "F", "AL", "FL")),
        ],
        text=text,
        note=FREE_RUN_NOTE,
    )


def free_run_within_fl(ctx: Context) -> Measured:
    w, _, text = _free_run(ctx)
    return Measured(
        ours=w["FL"] / w["F"],
        text=f"F_L/F ×{w['FL'] / w['F']:.3g} within; " + text,
        note=FREE_RUN_NOTE + "; F_L's spring is linear (k_sp(d)·φ_r), exact only inside the "
        "±19.7° linear range, and the stable class spans up to 31.5°: our verifying trials of "
        "that class that twist past the linear range (the paper does not give its trials' "
        "amplitudes) set the ratio",
    )


NOT_BETTER_THAN_F = 0.95  # 003-free-run-no-model-beats-f: under 5 % is not "better" (estimate)


def free_run_no_model_beats_f(ctx: Context) -> Measured:
    """Sec. 6.2: B, C, D, E against F in both classes (the claim's order of conditions)."""
    w, b, text = _free_run(ctx)
    flags = [cls[m] >= NOT_BETTER_THAN_F * cls["F"] for cls in (w, b) for m in ("B", "C", "D", "E")]
    return Measured(
        ours=flags,
        text=text,
        note=FREE_RUN_NOTE + ". Where ours departs: our bench's output shaft has bearing drag "
        "(y, magnetic_spring_selection.BenchConfig.output_damping_nms, an estimate) as well as "
        "the spring's relative damping z; E models y and F models z, so beyond the critical "
        "angle, where the output spins fast, E can follow our bench better than F",
    )


def free_run_critical(ctx: Context) -> Measured:
    w, b, text = _free_run(ctx)
    return Measured(ours=[w["F"] < b["F"]], text=text, note=FREE_RUN_NOTE)


MEASURES: dict[str, MeasureFn] = {
    "free_run_beyond": free_run_beyond,
    "free_run_within_fl": free_run_within_fl,
    "free_run_critical": free_run_critical,
    "free_run_no_model_beats_f": free_run_no_model_beats_f,
    "linearised_teaching": linearised_teaching,
    "linearised_verifying": linearised_verifying,
    "fms_vs_ams_safe_range": fms_vs_ams_safe_range,
    "model_ranking_teaching": model_ranking_teaching,
    "bic_ranking": bic_ranking,
    "eq2_from_eq1": eq2_from_eq1,
    "model_ranking": model_ranking,
    "friction_term": friction_term,
    "unbalance_term": unbalance_term,
    "output_damping_term": output_damping_term,
    "relative_damping_term": relative_damping_term,
    "stable_range": stable_range,
    "linear_range": linear_range,
    "kinetic_friction": kinetic_friction,
    "stiffness_vs_distance": stiffness_vs_distance,
    "negative_stiffness": negative_stiffness,
    "three_equilibria": three_equilibria,
}
