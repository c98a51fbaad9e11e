"""The discrepancy battery: synthetic datasets with every library effect hidden one at a time (two
magnitudes, two noise levels), null datasets and two-effect datasets; run ``diagnose`` on each and
tabulate what was named against the truth.

Generality on purpose: the battery's input trajectories are *not* the synth default (chirp); the
true stiffness differs from the catalogue (+-10 %) and an inertia load's true inertia from the
stated one (+20 %), so the nominal refit has work to do; the noise floor is estimated from the
data by the workflow. Magnitudes are calibrated per case: an effect's size is the RMS of what the
refit nominal model cannot reproduce of the clean output, as a fraction of its range (small
:data:`SMALL`, large :data:`LARGE`). ``scripts/discrepancy_battery.py`` runs the full battery;
``tests/test_discrepancy.py`` a reduced one.

Gap targets are reported twice: the held-out NRMSE halved, and the gap *above the estimated noise
floor* (``sqrt(max(gap^2 - floor^2, 0))``) halved - at high noise and a small effect the first
cannot be met even by the true model, the second can. Single-effect cases where more effects were
named after the right one are counted (``single_extra_effect_named``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import candidate_structure, candidates, replay_inputs, synth, variants
from fsarm_sim.discrepancy.bench_setup import BenchDiagnosis, diagnose
from fsarm_sim.discrepancy.benchmodel import BenchModel, EffectInstance, stated_model
from fsarm_sim.discrepancy.residuals import gap_excess
from fsarm_sim.discrepancy.selection import Step
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import registry
from fsarm_sim.records.measured import Dataset, load_dataset, stated_shaft, validate_columns

FloatArray = npt.NDArray[np.float64]

T = TypeVar("T")
R_ = TypeVar("R_")


def run_all(
    fn: Callable[[T], R_], cases: Sequence[T], jobs: int, line: Callable[[R_], str]
) -> list[R_]:
    """The battery scripts' loop: ``fn`` on every case, in ``jobs`` worker processes (1: here),
    printing ``line(result)`` as each comes; the results in the cases' order."""
    out: list[R_] = []
    if jobs > 1:
        with ProcessPoolExecutor(jobs) as ex:
            for r in ex.map(fn, cases):
                out.append(r)
                print(line(r), flush=True)
    else:
        for c in cases:
            r = fn(c)
            out.append(r)
            print(line(r), flush=True)
    return out


SMALL = 0.03  # effect size: RMS of the unexplained clean output / its range
LARGE = 0.08
NOISES = (0.003, 0.01)  # torque noise std / range
TRAJ_STATIC = ("multisine", "triangle", "random", "steps", "biased_sine")
TRAJ_INERTIA = ("multisine", "random", "steps")
STATED_J = synth.DEFAULT_LOAD_INERTIA_KGM2  # what the sidecar states for an inertia load
TRUE_J = 0.012


@dataclass
class Case:
    name: str
    setup: str
    inertia: bool
    effects: list[tuple[str, str]]  # hidden (effect, variant); empty: null
    size: float | None  # target effect size (fraction of range); None: as given / null
    noise: float
    trajectory: str
    seed: int
    stiffness_scale: float = 1.1
    duration_s: float = 30.0
    sign: float = 1.0
    rate_hz: float = 1000.0
    # out-of-library residual: (kind, size) with kind in OUT_OF_LIBRARY, size the RMS of what it
    # adds to the clean output / its range
    extra: tuple[str, float] | None = None


@dataclass
class Outcome:
    case: Case
    truth: BenchModel
    named: list[str]
    gap_before: float
    gap_after: float
    runtime_s: float
    first_margin: float | None
    first_runner_up: str | None
    recovery: dict[str, float] = field(default_factory=dict)
    achieved_size: float = math.nan
    noise_floor: float = math.nan  # estimated noise floor, held-out NRMSE units
    noise_floor_inputs: float = math.nan  # ... of the recorded inputs' own errors, propagated
    steps: list[dict[str, Any]] = field(default_factory=list)  # why each step added / stopped

    @property
    def gap_excess_before(self) -> float:
        return gap_excess(self.gap_before, self.noise_floor)

    @property
    def gap_excess_after(self) -> float:
        return gap_excess(self.gap_after, self.noise_floor)

    @property
    def truth_names(self) -> list[str]:
        return [e for e, _ in self.case.effects]


# ------------------------------------------------------------------------------ truth models


def _base_params(effect: str, variant: str, setup: str, amp: float, sign: float) -> dict[str, Any]:
    """Effect parameters at knob = 1 (scaled by the calibration)."""
    if effect == variants.COULOMB:
        return {"f_c_nm": 0.1}
    if effect == variants.VISCOUS:
        return {"b_nms": 0.01}
    if effect == variants.BACKLASH:
        return {"width_rad": 0.05 * amp, "center_rad": 0.1 * 0.05 * amp * sign}
    if effect == variants.DELAY:
        return {"delay_s": 0.005 * sign}
    if effect == variants.OFFSET:
        return (
            {"offset_nm": 0.1 * sign} if variant == "output" else {"offset_rad": 0.02 * amp * sign}
        )
    # catalogue's elements, deflections
    if effect == variants.HYSTERESIS and variant == "maxwell_slip":
        # scaled to the amplitude (shaft.toml: 0.1/12, 0.15/6, 0.25/3 rad at ~0.4 rad), and at
        # least twice the Coulomb boundary (an element that slips within it *is* Coulomb friction)
        b = candidate_structure.coulomb_delta_max(amp)
        return {
            "k_nm_per_rad": [12.0, 6.0, 3.0],
            "delta_rad": [max(0.02 * amp, 2 * b), max(0.06 * amp, 5 * b), max(0.2 * amp, 12 * b)],
        }
    # catalogue conduit branches (fractions 0.35, 0.25; 0.15 s, 1.5 s)
    if effect == variants.HYSTERESIS:
        return {"k_nm_per_rad": [0.35, 0.25], "tau_s": [0.15, 1.5]}
    if effect == variants.NONLINEAR and variant == "masterflex08":
        return {"twist_scale": 865.0 / 450.0}
    if effect == variants.NONLINEAR:  # stiffening: cubic (sign > 0) or quadratic (sign < 0)
        # (measured shafts stiffen: seed 001 Table 1, seed 000 Fig. 9; a softening polynomial
        # large enough to matter reaches negative stiffness - the masterflex08 case softens
        # beyond 60 deg the way a real curve does)
        return {
            "c2_nm": 0.5 if sign < 0 else 0.0,
            "c3_nm": 0.5 if sign > 0 else 0.0,
            "x_ref_rad": amp,
        }
    raise KeyError(effect)


def _scale(effect: str, variant: str, p: dict[str, Any], m: float) -> dict[str, Any]:
    q = dict(p)
    keys = {
        variants.COULOMB: ["f_c_nm"],
        variants.VISCOUS: ["b_nms"],
        variants.BACKLASH: ["width_rad", "center_rad"],
        variants.DELAY: ["delay_s"],
        variants.OFFSET: ["offset_nm", "offset_rad"],
        variants.HYSTERESIS: ["k_nm_per_rad"],
        variants.NONLINEAR: ["c2_nm", "c3_nm"],
    }[effect]
    for k in keys:
        if k in q:
            q[k] = [m * v for v in q[k]] if isinstance(q[k], list) else m * q[k]
    return q


def _clip_to_bounds(effect: str, variant: str, p: dict[str, Any]) -> dict[str, Any]:
    var = registry.get(effect).variant(variant)
    q = dict(p)
    for par in var.params:
        v = q[par.name]
        q[par.name] = (
            [float(np.clip(a, par.lower, par.upper)) for a in v]
            if isinstance(v, list)
            else float(np.clip(v, par.lower, par.upper))
        )
    return q


OUT_OF_LIBRARY = ("line", "drift", "signal")
LINE_HZ = 50.0  # mains pickup on the torque amplifier (50 Hz grid)
RIPPLE_PERIOD = 0.25  # signal: a ripple of the twist, period / the twist's reference amplitude


def out_of_library(
    kind: str, size: float, y: FloatArray, t: FloatArray, twist: FloatArray, seed: int
) -> tuple[FloatArray, dict[str, float]]:
    """(what an out-of-library disturbance adds to the clean output, its truth): ``line`` a
    50 Hz line, ``drift`` the output's gain (the stiffness) rising linearly over the record,
    ``signal`` a ripple periodic in the twist (no library effect models it) - each scaled to an
    RMS of ``size`` x the clean output's range."""
    span = float(np.ptp(y))
    rng = np.random.default_rng(seed + 31)
    if kind == "line":
        amp = math.sqrt(2.0) * size * span
        add = amp * np.sin(2 * np.pi * LINE_HZ * t + rng.uniform(0, 2 * np.pi))
        return add, {"frequency_hz": LINE_HZ, "amplitude": amp}
    if kind == "drift":
        tau = (t - 0.5 * (t[0] + t[-1])) / float(t[-1] - t[0])
        base = (y - y.mean()) * tau
        g = size * span / float(np.sqrt(np.mean(base * base)))
        return g * base, {"relative_change_over_record": g}
    if kind == "signal":
        x_ref = float(np.quantile(np.abs(twist), 0.995)) or 1.0
        ripple = np.sin(2 * np.pi * twist / (RIPPLE_PERIOD * x_ref))
        amp = size * span / float(np.sqrt(np.mean(ripple * ripple)))
        return amp * ripple, {"amplitude": amp, "period_rad": RIPPLE_PERIOD * x_ref}
    raise KeyError(kind)


def dataset(truth: BenchModel, case: Case, noise: float) -> Dataset:
    """The synthetic record of a case (its out-of-library disturbance added, then the noise)."""
    rec = synth.Recording(
        duration_s=case.duration_s,
        noise=0.0 if case.extra else noise,
        trajectory=case.trajectory,
        seed=case.seed,
        rate_hz=case.rate_hz,
    )
    cols, side = synth.synthesize(truth, rec)
    if case.extra:
        out = "tau_s" if truth.setup == "series_bench" else "m_b"
        twist = cols["theta_m"] - cols["theta_s"] if out == "tau_s" else cols["phi_b"]
        y = cols[out]
        add, _ = out_of_library(case.extra[0], case.extra[1], y, cols["t"], twist, case.seed)
        rng = np.random.default_rng(case.seed + 7919)
        cols[out] = y + add + noise * float(np.ptp(y)) * rng.standard_normal(y.size)
    validate_columns(truth.setup, cols, synth.Path(case.name))
    sh = stated_shaft()
    return Dataset(
        path=synth.Path(case.name),
        setup=truth.setup,
        columns=cols,
        sidecar=side,
        shaft=sh,
        load_inertia_kgm2=truth.load_inertia_kgm2,
    )


_dataset = dataset  # the name the battery's older callers use


def effect_size(truth: BenchModel, case: Case) -> float:
    """RMS of what the refit nominal model cannot reproduce of the clean output / its range
    (without the case's out-of-library disturbance)."""
    ds = _dataset(truth, replace(case, extra=None), 0.0)
    inp = replay_inputs.prepare_inputs(ds)
    ctx = candidate_structure.make_context(inp, stated_model(ds))
    fit = candidates.nominal(ctx)
    r = inp.y - fit.yhat
    return float(np.sqrt(np.mean(r[ctx.teach | ctx.held] ** 2)) / np.ptp(inp.y))


def _nominal_truth(case: Case) -> BenchModel:
    return synth.truth_model(
        case.setup,
        load_inertia_kgm2=STATED_J if case.inertia else None,
        stiffness_scale=case.stiffness_scale,
        true_inertia_kgm2=TRUE_J if case.inertia else None,
    )


def deflection_amplitude(truth: BenchModel, case: Case) -> float:
    """99.5th percentile of |input - output angle| of the clean nominal record: the deflection
    the shaft actually sees (an inertia load follows the input, leaving a small twist)."""
    ds = _dataset(truth, replace(case, extra=None), 0.0)
    c = ds.columns
    x = c["theta_m"] - c["theta_s"] if truth.setup == "series_bench" else c["phi_b"]
    return float(np.quantile(np.abs(x), 0.995))


def build_truth(case: Case) -> tuple[BenchModel, float]:
    """Truth model of a case, each hidden effect calibrated to the case's size."""
    truth = _nominal_truth(case)
    nominal = truth.copy()
    amp = deflection_amplitude(truth, case)
    achieved = math.nan
    for effect, variant in case.effects:
        base = _base_params(effect, variant, case.setup, amp, case.sign)
        if case.size is None:
            truth.effects.append(EffectInstance(effect, variant, base))
            continue
        m = 1.0
        m_ok = 0.0  # the last knob whose truth replayed without diverging
        for _ in range(6):
            trial = nominal.copy()  # each hidden effect calibrated on its own
            trial.effects.append(
                EffectInstance(
                    effect,
                    variant,
                    _clip_to_bounds(effect, variant, _scale(effect, variant, base, m)),
                )
            )
            try:
                achieved = effect_size(trial, case)
            except InvalidParameterError:  # the truth diverged: too strong for the load
                m *= 0.5
                continue
            m_ok = m
            if achieved <= 0 or abs(achieved / case.size - 1.0) < 0.1:
                break
            m *= min(case.size / achieved, 10.0)
        m = m_ok if m_ok > 0 else m
        truth.effects.append(
            EffectInstance(
                effect, variant, _clip_to_bounds(effect, variant, _scale(effect, variant, base, m))
            )
        )
    if len(case.effects) != 1 or case.size is None:
        achieved = effect_size(truth, case) if case.effects else 0.0
    return truth, achieved


# ------------------------------------------------------------------------------ recovery


def _scalar(effect: str, e: EffectInstance) -> float | None:
    p = e.params
    if effect == variants.COULOMB:
        return float(p["f_c_nm"])
    if effect == variants.VISCOUS:
        return float(p["b_nms"])
    if effect == variants.BACKLASH:
        return float(p["width_rad"])
    if effect == variants.DELAY:
        return float(p["delay_s"])
    if effect == variants.OFFSET:
        return float(p.get("offset_nm", p.get("offset_rad", 0.0)))
    if effect == variants.HYSTERESIS and e.variant == "maxwell_slip":  # total slip torque
        return float(sum(k * d for k, d in zip(p["k_nm_per_rad"], p["delta_rad"], strict=True)))
    # sum of branch stiffnesses (the fast-rate stiffness increase)
    if effect == variants.HYSTERESIS:
        return float(sum(p["k_nm_per_rad"]))
    return None


def recovery(truth: BenchModel, fitted: BenchModel) -> dict[str, float]:
    """Relative error of each hidden effect's main parameter (same effect and variant fitted)."""
    out: dict[str, float] = {}
    for te in truth.effects:
        fe = fitted.effect(te.name, te.variant)
        if fe is None:
            continue
        if te.name == variants.NONLINEAR:
            if te.variant == "masterflex08" or "x_ref_rad" not in fe.params:
                continue
            xr = fe.params["x_ref_rad"]

            def nl(e: EffectInstance, x: float) -> float:
                p = e.params
                r = x / p["x_ref_rad"]
                sfx = "" if e.variant == "poly" else ("_pos" if x >= 0 else "_neg")
                return p[f"c2{sfx}_nm"] * r * abs(r) + p[f"c3{sfx}_nm"] * r**3

            tv = nl(te, xr) - nl(te, -xr)
            fv = nl(fe, xr) - nl(fe, -xr)
            out[te.label] = abs(fv - tv) / max(abs(tv), 1e-12)
            continue
        tv2 = _scalar(te.name, te)
        fv2 = _scalar(te.name, fe)
        if tv2 is not None and fv2 is not None and tv2 != 0:
            out[te.label] = abs(fv2 - tv2) / abs(tv2)
    return out


# ------------------------------------------------------------------------------ cases


def single_effects(setup: str, inertia: bool) -> list[tuple[str, str]]:
    pairs = registry.applicable(setup, inertia)
    # one variant per effect is enough for hiding, except where the variant changes the physics
    keep = []
    for e, v in pairs:
        if e == variants.NONLINEAR and v == "poly_per_sign":
            continue
        keep.append((e, v))
    if setup == "series_bench" and not inertia:
        keep.append((variants.NONLINEAR, "masterflex08"))
    return keep


def cases(full: bool = True, duration_s: float = 30.0) -> list[Case]:
    out: list[Case] = []
    seed = 100
    setups = [("series_bench", False), ("series_bench", True), ("parallel_bench", False)]
    for setup, inertia in setups:
        trajs = TRAJ_INERTIA if inertia else TRAJ_STATIC
        tag = (
            "series_inertia"
            if inertia
            else ("series_blocked" if setup == "series_bench" else "parallel")
        )
        for e, v in single_effects(setup, inertia):
            sizes: tuple[float | None, ...] = (None,) if v == "masterflex08" else (SMALL, LARGE)
            for size in sizes:
                for noise in NOISES:
                    seed += 1
                    out.append(
                        Case(
                            name=f"{tag}/{e}[{v}]/size{size}/noise{noise}",
                            setup=setup,
                            inertia=inertia,
                            effects=[(e, v)],
                            size=size,
                            noise=noise,
                            trajectory=trajs[seed % len(trajs)],
                            seed=seed,
                            sign=1.0 if seed % 2 else -1.0,
                            stiffness_scale=1.1 if seed % 2 else 0.9,
                            duration_s=duration_s,
                        )
                    )
        for noise in NOISES:
            for k in range(3):
                seed += 1
                out.append(
                    Case(
                        name=f"{tag}/null/{trajs[k % len(trajs)]}/noise{noise}",
                        setup=setup,
                        inertia=inertia,
                        effects=[],
                        size=None,
                        noise=noise,
                        trajectory=trajs[k % len(trajs)],
                        seed=seed,
                        stiffness_scale=1.1 if seed % 2 else 0.9,
                        duration_s=duration_s,
                    )
                )
    two = [
        ("series_bench", False, [(variants.COULOMB, "shaft"), (variants.NONLINEAR, "poly")]),
        ("series_bench", False, [(variants.BACKLASH, "coupling"), (variants.VISCOUS, "shaft")]),
        ("series_bench", True, [(variants.COULOMB, "load"), (variants.DELAY, "input")]),
        (
            "parallel_bench",
            False,
            [(variants.HYSTERESIS, "viscoelastic"), (variants.NONLINEAR, "poly")],
        ),
    ]
    for setup, inertia, effs in two:
        seed += 1
        trajs = TRAJ_INERTIA if inertia else TRAJ_STATIC
        tag = (
            "series_inertia"
            if inertia
            else ("series_blocked" if setup == "series_bench" else "parallel")
        )
        out.append(
            Case(
                name=f"{tag}/two:{'+'.join(e for e, _ in effs)}",
                setup=setup,
                inertia=inertia,
                effects=effs,
                size=LARGE,
                noise=NOISES[0],
                trajectory=trajs[seed % len(trajs)],
                seed=seed,
                duration_s=duration_s,
            )
        )
    if not full:
        out = reduced(out)
    return out


def reduced(all_cases: list[Case]) -> list[Case]:
    """A small, fast subset (CI): blocked series and parallel bench, large effects, low noise."""
    pick = []
    seen: set[tuple[str, str]] = set()
    for c in all_cases:
        if c.inertia:
            continue
        key = (c.setup, c.effects[0][0] if c.effects else "null")
        if c.effects and (c.size != LARGE or c.noise != NOISES[0]):
            continue
        if key in seen or len(c.effects) > 1:
            continue
        seen.add(key)
        pick.append(c)
    return pick


def run_case(case: Case) -> Outcome:
    truth, achieved = build_truth(case)
    t0 = time.perf_counter()
    try:
        ds = _dataset(truth, case, case.noise)
        t0 = time.perf_counter()
        diag: BenchDiagnosis = diagnose(ds)
    except Exception as exc:  # a battery reports failures, it does not stop at them
        return Outcome(
            case,
            truth,
            [f"ERROR: {type(exc).__name__}: {exc}"[:120]],
            math.nan,
            math.nan,
            time.perf_counter() - t0,
            None,
            None,
            {},
            achieved,
        )
    dt = time.perf_counter() - t0
    first = next((s for s in diag.steps if s.added is not None), None)
    return Outcome(
        case=case,
        truth=truth,
        named=list(diag.named),
        gap_before=diag.gap_before,
        gap_after=diag.gap_after,
        runtime_s=dt,
        first_margin=first.bic_margin if first else None,
        first_runner_up=first.runner_up if first else None,
        recovery=recovery(truth, diag.final.model),
        achieved_size=achieved,
        noise_floor=diag.noise_floor_nrmse,
        noise_floor_inputs=diag.noise_floor_inputs_nrmse,
        steps=[_step_summary(st) for st in diag.steps],
    )


def _step_summary(st: Step) -> dict[str, Any]:
    """The deciding numbers of one selection step (its best candidate)."""
    top = st.scores[0] if st.scores else None
    return {
        "added": st.added,
        "best": top.label if top else None,
        "d_bic_held": top.d_bic_held if top else None,
        "gain_held": top.gain_held if top else None,
        "explained_over_noise": top.explained_over_noise if top else None,
        "share_of_explained": top.share_of_explained if top else None,
        "reason": st.reason,
    }


# ------------------------------------------------------------------------------ tables


def summary(outcomes: list[Outcome]) -> dict[str, Any]:
    singles = [o for o in outcomes if len(o.case.effects) == 1]
    nulls = [o for o in outcomes if not o.case.effects]
    hidden = [o for o in outcomes if o.case.effects]
    right_first = [o for o in singles if o.named[:1] == o.truth_names]
    null_ok = [o for o in nulls if not o.named]
    halved = [o for o in hidden if o.gap_after <= 0.5 * o.gap_before]
    # the same target on the gap above the noise floor (a gap cannot shrink below the floor)
    excess_halved = [o for o in hidden if o.gap_excess_after <= 0.5 * o.gap_excess_before]
    extra = [o for o in singles if o.named[:1] == o.truth_names and len(o.named) > 1]
    two = [o for o in outcomes if len(o.case.effects) > 1]
    two_ok = [o for o in two if set(o.named) >= set(o.truth_names)]
    rec = [v for o in singles if o.named[:1] == o.truth_names for v in o.recovery.values()]
    return {
        "cases": len(outcomes),
        "single_right_first": (len(right_first), len(singles)),
        "null_nothing_named": (len(null_ok), len(nulls)),
        "gap_halved": (len(halved), len(hidden)),
        "excess_gap_halved": (len(excess_halved), len(hidden)),
        "single_extra_effect_named": (len(extra), len(singles)),
        "two_effect_both_named": (len(two_ok), len(two)),
        "recovery_median_rel_error": float(np.median(rec)) if rec else math.nan,
        "recovery_p90_rel_error": float(np.quantile(rec, 0.9)) if rec else math.nan,
        "runtime_median_s": float(np.median([o.runtime_s for o in outcomes])) if outcomes else 0.0,
        "runtime_max_s": float(max((o.runtime_s for o in outcomes), default=0.0)),
    }


def confusion(outcomes: list[Outcome]) -> tuple[list[str], list[str], dict[tuple[str, str], int]]:
    """Truth (rows: hidden effect or 'none') vs first named effect (columns, or 'none')."""
    table: dict[tuple[str, str], int] = {}
    rows: list[str] = []
    cols: list[str] = []
    for o in outcomes:
        if len(o.case.effects) > 1:
            continue
        t = o.truth_names[0] if o.truth_names else "none"
        n = o.named[0] if o.named else "none"
        table[(t, n)] = table.get((t, n), 0) + 1
        if t not in rows:
            rows.append(t)
        if n not in cols:
            cols.append(n)
    order = [*registry.names(), "none"]
    rows.sort(key=lambda r: order.index(r) if r in order else 99)
    cols.sort(key=lambda c: order.index(c) if c in order else 99)
    return rows, cols, table


LOOK_ALIKE_TRUTHS = (
    variants.DELAY,
    variants.VISCOUS,
    variants.BACKLASH,
    variants.NONLINEAR,
    variants.COULOMB,
    variants.HYSTERESIS,
)


def look_alike_lines(outcomes: list[Outcome]) -> list[str]:
    """Per look-alike-prone truth: how often right, which runner-up, BIC margins."""
    lines = ["look-alikes: first named vs runner-up, held-out BIC margin (single-effect cases)"]
    for truth_name in LOOK_ALIKE_TRUTHS:
        sel = [o for o in outcomes if o.truth_names == [truth_name]]
        if not sel:
            continue
        right = [o for o in sel if o.named[:1] == [truth_name]]
        margins = [o.first_margin for o in right if o.first_margin is not None]
        runners: dict[str, int] = {}
        for o in right:
            key = o.first_runner_up or "-"
            runners[key] = runners.get(key, 0) + 1
        stat = (
            f"margin min {min(margins):.0f}, median {float(np.median(margins)):.0f}"
            if margins
            else "margin -"
        )
        lines.append(
            f"  {truth_name:<20} right {len(right)}/{len(sel)}; {stat}; runner-up {runners}"
        )
    return lines


def format_tables(outcomes: list[Outcome]) -> str:
    rows, cols, table = confusion(outcomes)
    short = {n: n.replace("_", " ")[:11] for n in cols}
    w = 20
    lines = ["confusion (single-effect and null cases): truth (rows) vs first named (columns)"]
    lines.append(" " * w + "".join(f"{short[c]:>12}" for c in cols))
    for r in rows:
        lines.append(f"{r:<{w}}" + "".join(f"{table.get((r, c), 0):>12}" for c in cols))
    s = summary(outcomes)
    lines.append("")
    for k, v in s.items():
        if isinstance(v, tuple):
            lines.append(f"{k:<32} {v[0]}/{v[1]} ({100 * v[0] / max(v[1], 1):.0f} %)")
        else:
            lines.append(f"{k:<32} {v:.3g}")
    lines.append("")
    lines.extend(look_alike_lines(outcomes))
    lines.append("")
    lines.append(
        "per case: named | gap before -> after (held-out NRMSE %) | noise floor | gap above the "
        "floor before -> after | size | margin (runner-up) | recovery | runtime"
    )
    for o in outcomes:
        rec = ", ".join(f"{k} {100 * v:.0f}%" for k, v in o.recovery.items())
        if len(o.case.effects) > 1:
            good = set(o.named) >= set(o.truth_names)
        elif o.case.effects:
            good = o.named[:1] == o.truth_names
        else:
            good = not o.named
        mark = "ok " if good else "BAD"
        marg = f"{o.first_margin:.0f} ({o.first_runner_up})" if o.first_margin is not None else "-"
        lines.append(
            f"{mark} {o.case.name:<58} [{o.case.trajectory:<11}] {','.join(o.named) or 'none':<34} "
            f"{100 * o.gap_before:6.2f} -> {100 * o.gap_after:5.2f}  floor {100 * o.noise_floor:5.2f}"
            f" (inputs {100 * o.noise_floor_inputs:4.2f})  "
            f"excess {100 * o.gap_excess_before:6.2f} -> {100 * o.gap_excess_after:5.2f}  "
            f"size {100 * o.achieved_size:5.1f}%  "
            f"{marg:<28} {rec:<30} {o.runtime_s:5.1f}s"
        )
    return "\n".join(lines)


def load_truth(path: str) -> BenchModel:
    """Helper for scripts: the truth model embedded in a synthetic dataset's sidecar."""
    from fsarm_sim.discrepancy.benchmodel import model_from_dict

    ds = load_dataset(path)
    return model_from_dict(ds.sidecar["synthetic"]["truth"])
