"""Forward selection of missing effects: add one at a time while each still earns its place.

Step 0 refits the nominal model's own parameters (stiffness per twist sign, bending stiffness,
a loosely stated load inertia): an effect is missing only when no such refit removes the
disagreement. Each following step fits every applicable candidate (:mod:`.candidates`) on top of
the current model and ranks the *effects* (best variant each) by the change of BIC on the
held-out samples. The best one is added when it earns its place:

* BIC falls by more than :data:`BIC_THRESHOLD` on the teaching samples *and* on the held-out
  samples (10 = "very strong" evidence on the Kass-Raftery scale; BIC in seed 003 Table 4's form
  ``n ln(MSE) + k ln(n)``, with n the *effective* number of samples of the candidate's residual),
* the held-out MSE falls by at least :data:`MIN_GAIN` (relative), and
* the explained part is not lost in the noise: the held-out MSE falls by at least
  :data:`MIN_EXPLAINED` of the noise floor's variance (estimated from the data).

An *extra* effect (the current model already holds named effects) must earn its place more
clearly, because the residual of a fitted model is never pure noise: the fitted laws approximate
the true ones (a Prony grid for a relaxation spectrum, a polynomial for a measured curve), and the
recorded inputs carry their own errors (encoder quantisation, which the replay propagates through
the model's stiffness). That misfit is structured, and any flexible candidate (an offset, a
damper, a narrow backlash) soaks up part of it with a large BIC gain on tens of thousands of
samples. So an extra effect must in addition

* stand out of the noise: its held-out MSE reduction is at least :data:`MIN_EXPLAINED_EXTRA`
  times the noise variance (its contribution's RMS at least the noise floor) - misfit from the
  inputs' errors scales with the noise, not with the effects named, and
* not be a correction of what is named: the reduction is at least :data:`MIN_SHARE_EXTRA` of the
  held-out MSE reduction the named effects brought (its RMS at least ~14 % of theirs) - the
  approximation error of a fitted law scales with the law, whatever the noise. Measured on
  synthetic records with an out-of-library curve (seed 001's MasterFlex08 fitted by the
  polynomial) and quantised encoders, such spurious extras explained 0.04-1.5 % of the named
  effects' share; genuine second effects 1.9-76 % (the lowest, a 0.01 rad backlash on a
  stiffening shaft driven by a triangle wave, falls just short) - *unless* it removes at least
  :data:`MIN_GAIN_DOMINANT` of the residual that is left (a correction of a fitted law only nibbles
  at it: the spurious extras above removed about a quarter; a real second effect next to a much
  larger first one, e.g. a channel offset after a delay on the arm, removes almost all of it).
  A genuine second effect below these limits is not named: the verdict then says how much
  residual above the noise floor remains.

Noise floors. The thresholds use the white noise of the main output channel (``sigma_y``, from
the data alone). The recorded *inputs* carry errors too (encoder quantisation, sensor noise) that
the replay propagates through the model - through a stiff visco-elastic branch or a load
resonance they can reach the output noise's size. :func:`input_error_floor` estimates that part:
it re-measures a smoothed copy of each recorded angle the way the record was measured (on the
same encoder grid, or with the same white noise), replays the final model on both, and takes the
RMS difference on the held-out samples. It is reported (and named in the verdict), never used to
name an effect.

A hysteresis effect, once added, has its elements moved off the fixed grid of the candidate fit
(:func:`.candidates.refine_elements`); the ranking itself uses the grid fits.

Confidence of a step: the BIC margin between the added effect and the runner-up effect and the
probability ``1 / (1 + exp(-margin / 2))`` that BIC's evidence approximation gives the winner
over the runner-up. When the first step adds nothing and the residual is within noise, "nothing
is missing within noise"; when it adds nothing but the residual is not, the verdict says so.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import candidates as C
from fsarm_sim.discrepancy import replay as R
from fsarm_sim.discrepancy.benchmodel import BenchModel, nominal_from_shaft
from fsarm_sim.discrepancy.residuals import (
    bic,
    effective_n,
    gap_excess,
    noise_floor,
    nrmse,
    nrmse_floor,
    signature,
)
from fsarm_sim.effects import registry
from fsarm_sim.errors import FsarmError
from fsarm_sim.measured import Dataset

FloatArray = npt.NDArray[np.float64]


class UnsupportedSetupError(FsarmError, NotImplementedError):
    """The dataset's setup has no replay in the discrepancy workflow (yet)."""


BIC_THRESHOLD = 10.0
MIN_GAIN = 0.02
MIN_EXPLAINED = 0.25
MIN_EXPLAINED_EXTRA = 1.0
MIN_SHARE_EXTRA = 0.02
MIN_GAIN_DOMINANT = 0.5  # an extra effect below MIN_SHARE_EXTRA still earns it if it removes this
MAX_EFFECTS = 4


def extra_share_ok(share: float, gain_held: float) -> bool:
    """The share limit of an extra effect (module docstring): a large enough share of what the
    named effects explained, or most of the residual that is left."""
    return share >= MIN_SHARE_EXTRA or gain_held >= MIN_GAIN_DOMINANT


LOOK_ALIKES = (
    frozenset({"delay", "viscous_damping"}),
    frozenset({"backlash", "nonlinear_stiffness"}),
    frozenset({"coulomb_friction", "viscous_damping"}),
    frozenset({"coulomb_friction", "hysteresis"}),
    frozenset({"viscous_damping", "hysteresis"}),
)


@dataclass
class Score:
    label: str
    effect: str
    variant: str
    k: int
    mse_teach: float
    mse_held: float
    nrmse_held: float
    d_bic_teach: float
    d_bic_held: float
    gain_held: float
    explained_over_noise: float
    earns_place: bool
    params: dict[str, Any]
    note: str = ""
    share_of_explained: float = math.inf  # extra effect: its explained MSE / that of those named
    extra: bool = False  # scored as an extra effect (the current model already holds effects)

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


@dataclass
class Step:
    index: int
    scores: list[Score]
    added: str | None
    runner_up: str | None
    bic_margin: float | None
    probability: float | None
    look_alike: bool
    reason: str

    def as_dict(self) -> dict[str, Any]:
        d = dict(self.__dict__)
        d["scores"] = [s.as_dict() for s in self.scores]
        return d


@dataclass
class Diagnosis:
    dataset: Dataset
    ctx: C.Context
    catalogue: C.Fit
    nominal: C.Fit
    final: C.Fit
    steps: list[Step]
    named: list[str]
    runtime_s: float
    verdict: str
    extras: dict[str, Any] = field(default_factory=dict)
    sigma_inputs: float = 0.0  # output error caused by the recorded inputs' own errors

    @property
    def gap_before(self) -> float:
        return nrmse(self.ctx.inp.y, self.nominal.yhat, self.ctx.held)

    @property
    def gap_after(self) -> float:
        return nrmse(self.ctx.inp.y, self.final.yhat, self.ctx.held)

    @property
    def noise_floor_nrmse(self) -> float:
        """The estimated noise floor in held-out NRMSE units (a perfect model's gap)."""
        return nrmse_floor(self.ctx.inp.y, self.ctx.sigma_y, self.ctx.held)

    @property
    def noise_floor_inputs_nrmse(self) -> float:
        """The output error the recorded inputs' own errors cause, held-out NRMSE units."""
        return nrmse_floor(self.ctx.inp.y, self.sigma_inputs, self.ctx.held)

    @property
    def noise_floor_total_nrmse(self) -> float:
        """Output noise and propagated input errors together (they add in variance)."""
        return math.hypot(self.noise_floor_nrmse, self.noise_floor_inputs_nrmse)

    @property
    def gap_excess_before(self) -> float:
        """Held-out gap of the nominal model above the noise floor."""
        return gap_excess(self.gap_before, self.noise_floor_nrmse)

    @property
    def gap_excess_after(self) -> float:
        """Held-out gap of the final model above the noise floor."""
        return gap_excess(self.gap_after, self.noise_floor_nrmse)


def common_n_eff(ctx: C.Context, fits: list[C.Fit]) -> tuple[float, float]:
    """Effective sample counts (teaching, held-out) shared by all candidates of a step: from
    the residual of the candidate that fits the held-out samples best - the closest to pure
    noise - so that every BIC of the step uses the same n (margins stay comparable)."""
    best = min(fits, key=lambda f: f.mse_held)
    r = ctx.inp.y - best.yhat
    return effective_n(r, ctx.teach), effective_n(r, ctx.held)


@dataclass(frozen=True)
class Judgement:
    """The selection rule's numbers for one candidate against the current model."""

    d_bic_teach: float
    d_bic_held: float
    gain_held: float
    explained_over_noise: float
    share_of_explained: float
    extra: bool
    earns_place: bool

    def score(self, **fields: Any) -> Score:
        """The :class:`Score` of a candidate: ``fields`` (label, effect, variant, k, MSEs,
        nrmse_held, params, note) plus this judgement's numbers."""
        return Score(
            d_bic_teach=self.d_bic_teach,
            d_bic_held=self.d_bic_held,
            gain_held=self.gain_held,
            explained_over_noise=self.explained_over_noise,
            earns_place=self.earns_place,
            share_of_explained=self.share_of_explained,
            extra=self.extra,
            **fields,
        )


def judge(
    cur: tuple[float, float, int],
    cand: tuple[float, float, int],
    n_t: float,
    n_h: float,
    noise_var: float,
    nominal_mse_held: float | None = None,
) -> Judgement:
    """The rule of the module docstring, on (teaching MSE, held-out MSE, k) of the current model
    and of the candidate; ``nominal_mse_held`` (the refit nominal's held-out MSE) when the current
    model already holds named effects: the candidate is then an *extra* effect. Shared by the
    bench and the arm (whose MSE is the noise-weighted one, ``noise_var`` = 1)."""
    (t_cur, h_cur, k_cur), (t_cand, h_cand, k_cand) = cur, cand
    d_t = bic(t_cand, n_t, k_cand) - bic(t_cur, n_t, k_cur)
    d_h = bic(h_cand, n_h, k_cand) - bic(h_cur, n_h, k_cur)
    gain = 1.0 - h_cand / h_cur if h_cur > 0 else 0.0
    expl = (h_cur - h_cand) / noise_var if noise_var > 0 else math.inf
    extra = nominal_mse_held is not None
    share = math.inf
    if nominal_mse_held is not None:
        done = nominal_mse_held - h_cur  # what the effects named so far explained
        share = (h_cur - h_cand) / done if done > 0 else math.inf
    ok = (
        d_t < -BIC_THRESHOLD and d_h < -BIC_THRESHOLD and gain >= MIN_GAIN and expl >= MIN_EXPLAINED
    )
    if extra:
        ok = ok and expl >= MIN_EXPLAINED_EXTRA and extra_share_ok(share, gain)
    return Judgement(d_t, d_h, gain, expl, share, extra, ok)


def score(
    ctx: C.Context, cur: C.Fit, cand: C.Fit, n_t: float, n_h: float, nom: C.Fit | None = None
) -> Score:
    """Scores of a candidate against the current model; ``nom`` (the refit nominal model) when
    the current model already holds named effects - then the stricter rule of an *extra* effect
    applies (module docstring)."""
    j = judge(
        (cur.mse_teach, cur.mse_held, cur.k),
        (cand.mse_teach, cand.mse_held, cand.k),
        n_t,
        n_h,
        ctx.sigma_y**2,
        nom.mse_held if nom is not None and nom is not cur else None,
    )
    eff = cand.model.effect(cand.effect or "", cand.variant)
    return j.score(
        label=cand.label,
        effect=cand.effect or "",
        variant=cand.variant or "",
        k=cand.k,
        mse_teach=cand.mse_teach,
        mse_held=cand.mse_held,
        nrmse_held=nrmse(ctx.inp.y, cand.yhat, ctx.held),
        params=dict(eff.params) if eff is not None else {},
        note=cand.note,
    )


def stated_model(ds: Dataset) -> BenchModel:
    """The nominal model of a dataset's setup with the catalogue's / sidecar's parameters."""
    return nominal_from_shaft(ds.setup, ds.shaft, ds.load_inertia_kgm2, j_link=0.0)


def diagnose(ds: Dataset, *, max_effects: int = MAX_EFFECTS) -> Diagnosis:
    """Find, name and fit the effects missing from the nominal model of a bench dataset."""
    if ds.setup not in ("series_bench", "parallel_bench"):
        raise UnsupportedSetupError(
            f"this diagnose handles the bench setups (series_bench, parallel_bench); for "
            f"'{ds.setup}' use fsarm_sim.discrepancy.arm.diagnose_arm (`fsarm diagnose` picks "
            "the right one)"
        )
    t0 = time.perf_counter()
    inp = R.prepare_inputs(ds)
    ctx = C.make_context(inp, stated_model(ds))
    cat = C.stated(ctx)
    cur = C.nominal(ctx)
    nom = cur
    pairs = registry.applicable(ds.setup, inp.inertia_load)
    named: list[str] = []
    steps: list[Step] = []
    while len(named) < max_effects:
        if inp.inertia_load:  # screen with a short output-error refinement, redo the winner
            ctx.options["oe_nfev"] = C.OE_NFEV_SCREEN
        fits = [C.candidate(ctx, cur, e, v) for e, v in pairs if e not in named]
        ctx.options.pop("oe_nfev", None)
        good = [f for f in fits if f is not None and math.isfinite(f.mse_held)]
        if not good:
            break
        if inp.inertia_load:
            i_lead = min(range(len(good)), key=lambda i: good[i].mse_held)
            lead = good[i_lead]
            redo = C.solve(ctx, lead.structure)
            redo.label, redo.effect, redo.variant = lead.label, lead.effect, lead.variant
            if redo.mse_teach <= lead.mse_teach:
                good[i_lead] = redo
        n_t, n_h = common_n_eff(ctx, good)
        scores_fits = [(score(ctx, cur, f, n_t, n_h, nom), f) for f in good]
        best_per_effect: dict[str, tuple[Score, C.Fit]] = {}
        for s, f in scores_fits:
            if (
                s.effect not in best_per_effect
                or s.d_bic_held < best_per_effect[s.effect][0].d_bic_held
            ):
                best_per_effect[s.effect] = (s, f)
        ranked = sorted(best_per_effect.values(), key=lambda sf: sf[0].d_bic_held)
        top_s, top_f = ranked[0]
        runner = ranked[1][0] if len(ranked) > 1 else None
        margin = (runner.d_bic_held - top_s.d_bic_held) if runner is not None else None
        prob = 1.0 / (1.0 + math.exp(-min(margin, 700.0) / 2.0)) if margin is not None else None
        look = runner is not None and frozenset({top_s.effect, runner.effect}) in LOOK_ALIKES
        all_scores = sorted((s for s, _ in scores_fits), key=lambda s: s.d_bic_held)
        if top_s.earns_place:
            reason = (
                f"{top_s.label} lowers held-out BIC by {-top_s.d_bic_held:.1f} and held-out MSE by "
                f"{100 * top_s.gain_held:.1f} %"
            )
            steps.append(
                Step(
                    len(steps) + 1,
                    all_scores,
                    top_s.effect,
                    runner.effect if runner else None,
                    margin,
                    prob,
                    look,
                    reason,
                )
            )
            named.append(top_s.effect)
            # hysteresis elements were fitted on a fixed grid: move them off it before the next
            # step, so that the grid's approximation error is not left for another effect
            cur = C.refine_elements(ctx, top_f) if top_s.effect == "hysteresis" else top_f
        else:
            why = []
            if top_s.d_bic_teach >= -BIC_THRESHOLD or top_s.d_bic_held >= -BIC_THRESHOLD:
                why.append(
                    f"BIC change {top_s.d_bic_teach:+.1f} (teaching) / {top_s.d_bic_held:+.1f} "
                    f"(held-out) not below -{BIC_THRESHOLD:g}"
                )
            if top_s.gain_held < MIN_GAIN:
                why.append(
                    f"held-out MSE gain {100 * top_s.gain_held:.2f} % < {100 * MIN_GAIN:g} %"
                )
            min_expl = MIN_EXPLAINED_EXTRA if top_s.extra else MIN_EXPLAINED
            if top_s.explained_over_noise < min_expl:
                why.append(
                    f"explains {top_s.explained_over_noise:.3f} of the noise variance "
                    f"(< {min_expl:g}{' for an extra effect' if top_s.extra else ''})"
                )
            if top_s.extra and not extra_share_ok(top_s.share_of_explained, top_s.gain_held):
                why.append(
                    f"explains {100 * top_s.share_of_explained:.2g} % of what the named effects "
                    f"explain (< {100 * MIN_SHARE_EXTRA:g} % for an extra effect) and removes "
                    f"only {100 * top_s.gain_held:.1f} % of what is left "
                    f"(< {100 * MIN_GAIN_DOMINANT:g} %)"
                )
            reason = f"best candidate {top_s.label} does not earn its place: " + "; ".join(why)
            steps.append(
                Step(len(steps) + 1, all_scores, None, top_s.effect, margin, prob, look, reason)
            )
            break
    final = C.refine(ctx, cur) if named else cur
    if named:
        final.label = "nominal + " + " + ".join(named)
    sigma_in = input_error_floor(ds, ctx, final.model)
    verdict = _verdict(ctx, nom, final, named, sigma_in)
    return Diagnosis(
        dataset=ds,
        ctx=ctx,
        catalogue=cat,
        nominal=nom,
        final=final,
        steps=steps,
        named=named,
        runtime_s=time.perf_counter() - t0,
        verdict=verdict,
        sigma_inputs=sigma_in,
    )


def quantisation_step(x: FloatArray) -> float:
    """Step of a quantised channel (encoder counts), 0 when its values are not on a grid."""
    d = np.abs(np.diff(x))
    scale = float(np.max(np.abs(x))) if x.size else 0.0
    nz = d[d > 1e-12 * max(scale, 1e-300)]
    if nz.size < 10:
        return 0.0
    q = float(nz.min())
    frac = nz / q
    on_grid = np.abs(frac - np.round(frac)) < 0.01
    return q if float(np.mean(on_grid)) > 0.95 else 0.0


def remeasure(x: FloatArray, h: float, rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
    """(proxy, re-measured proxy) of a recorded angle: the proxy is the smoothed record; it is
    re-measured on the record's encoder grid (random grid phase) when the record is quantised and
    its noise is what quantisation alone leaves (d4 estimate <= the step), else with white noise
    of the record's noise floor."""
    proxy = R.smooth(x, h)
    q = quantisation_step(x)
    sig = noise_floor(x)
    if q > 0.0 and sig <= q:
        off = float(rng.uniform(0.0, q))
        return proxy, np.round((proxy + off) / q) * q - off
    return proxy, proxy + sig * rng.standard_normal(x.size)


def input_error_floor(ds: Dataset, ctx: C.Context, model: BenchModel) -> float:
    """RMS (held-out) of the output change a re-measurement of the recorded angles causes in the
    replay of ``model``: the part of the residual that the inputs' own errors explain."""
    names = ["theta_m", "theta_s"] if ds.setup == "series_bench" else ["phi_b"]
    cols_ref = dict(ds.columns)
    cols_new = dict(ds.columns)
    rng = np.random.default_rng(0)
    for nm in names:
        cols_ref[nm], cols_new[nm] = remeasure(np.asarray(ds.columns[nm], float), ds.dt, rng)
    try:
        y_ref = R.replay(model, R.prepare_inputs(replace(ds, columns=cols_ref)))["y"]
        y_new = R.replay(model, R.prepare_inputs(replace(ds, columns=cols_new)))["y"]
    except (ValueError, FloatingPointError):  # an estimate for the report: never fatal
        return 0.0
    d = (y_new - y_ref)[ctx.held]
    return float(np.sqrt(np.mean(d * d))) if np.all(np.isfinite(d)) else 0.0


WITHIN_NOISE = 1.15  # a held-out residual RMS up to this x the noise floor is "within noise"


def _verdict(
    ctx: C.Context, nom: C.Fit, final: C.Fit, named: list[str], sigma_in: float = 0.0
) -> str:
    """One honest sentence: what was named, the gap before / after, the noise floor and the
    gap above it (independent noise adds in variance)."""
    y, held = ctx.inp.y, ctx.held
    floor = nrmse_floor(y, ctx.sigma_y, held)
    gap_b, gap_a = nrmse(y, nom.yhat, held), nrmse(y, final.yhat, held)
    rms = math.sqrt(final.mse_held)
    ratio = rms / ctx.sigma_y if ctx.sigma_y > 0 else math.inf
    within = ratio <= WITHIN_NOISE
    floor_txt = (
        f"noise floor {100 * floor:.3g} %; gap above the floor "
        f"{100 * gap_excess(gap_b, floor):.3g} % -> {100 * gap_excess(gap_a, floor):.3g} %"
    )
    if not named:
        if within:
            return (
                "nothing is missing within noise: the refit nominal model leaves a held-out "
                f"residual of {rms:.4g} (noise floor {ctx.sigma_y:.4g}); no candidate earns its "
                "place"
            )
        return (
            f"no library effect earns its place, but the refit nominal model leaves "
            f"{ratio:.2g} x the noise floor (held-out NRMSE {100 * gap_a:.3g} %, {floor_txt}): "
            "something outside the library or the recorded inputs' own errors"
        )
    total = math.hypot(ctx.sigma_y, sigma_in)
    if within:
        rest = "the rest is within noise"
    elif total > 0 and rms <= WITHIN_NOISE * total:
        rest = (
            f"a residual of {ratio:.2g} x the output noise floor remains, within what the output "
            f"noise and the recorded inputs' own errors (quantisation / noise, propagated: "
            f"{100 * nrmse_floor(y, sigma_in, held):.3g} % NRMSE) explain together"
        )
    else:
        rest = f"a residual of {ratio:.2g} x the noise floor remains that no further effect claims"
    return (
        f"missing: {', '.join(named)}; held-out NRMSE {100 * gap_b:.3g} % -> {100 * gap_a:.3g} % "
        f"({floor_txt}); {rest}"
    )


def residual_signature(diag: Diagnosis, fit: C.Fit) -> dict[str, Any]:
    ctx = diag.ctx
    inp = ctx.inp
    s = inp.theta_s if inp.inertia_load and inp.theta_s is not None else inp.s
    x = inp.u - s
    xd = np.gradient(x, inp.h)
    return signature(inp.y, fit.yhat, x, xd, inp.phi, inp.t, ctx.sigma_y).as_dict()
