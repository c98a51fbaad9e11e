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

Confidence of a step: the BIC margin between the added effect and the runner-up effect and the
probability ``1 / (1 + exp(-margin / 2))`` that BIC's evidence approximation gives the winner
over the runner-up. When the first step adds nothing, "nothing is missing within noise".
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import candidates as C
from fsarm_sim.discrepancy import replay as R
from fsarm_sim.discrepancy.benchmodel import BenchModel, nominal_from_shaft
from fsarm_sim.discrepancy.residuals import bic, effective_n, nrmse, signature
from fsarm_sim.effects import registry
from fsarm_sim.errors import FsarmError
from fsarm_sim.measured import Dataset


class UnsupportedSetupError(FsarmError, NotImplementedError):
    """The dataset's setup has no replay in the discrepancy workflow (yet)."""


BIC_THRESHOLD = 10.0
MIN_GAIN = 0.02
MIN_EXPLAINED = 0.25
MAX_EFFECTS = 4
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

    @property
    def gap_before(self) -> float:
        return nrmse(self.ctx.inp.y, self.nominal.yhat, self.ctx.held)

    @property
    def gap_after(self) -> float:
        return nrmse(self.ctx.inp.y, self.final.yhat, self.ctx.held)


def common_n_eff(ctx: C.Context, fits: list[C.Fit]) -> tuple[float, float]:
    """Effective sample counts (teaching, held-out) shared by all candidates of a step: from
    the residual of the candidate that fits the held-out samples best - the closest to pure
    noise - so that every BIC of the step uses the same n (margins stay comparable)."""
    best = min(fits, key=lambda f: f.mse_held)
    r = ctx.inp.y - best.yhat
    return effective_n(r, ctx.teach), effective_n(r, ctx.held)


def score(ctx: C.Context, cur: C.Fit, cand: C.Fit, n_t: float, n_h: float) -> Score:
    y = ctx.inp.y
    d_t = bic(cand.mse_teach, n_t, cand.k) - bic(cur.mse_teach, n_t, cur.k)
    d_h = bic(cand.mse_held, n_h, cand.k) - bic(cur.mse_held, n_h, cur.k)
    gain = 1.0 - cand.mse_held / cur.mse_held if cur.mse_held > 0 else 0.0
    s2 = ctx.sigma_y**2
    expl = (cur.mse_held - cand.mse_held) / s2 if s2 > 0 else math.inf
    ok = (
        d_t < -BIC_THRESHOLD and d_h < -BIC_THRESHOLD and gain >= MIN_GAIN and expl >= MIN_EXPLAINED
    )
    eff = cand.model.effect(cand.effect or "", cand.variant)
    return Score(
        label=cand.label,
        effect=cand.effect or "",
        variant=cand.variant or "",
        k=cand.k,
        mse_teach=cand.mse_teach,
        mse_held=cand.mse_held,
        nrmse_held=nrmse(y, cand.yhat, ctx.held),
        d_bic_teach=d_t,
        d_bic_held=d_h,
        gain_held=gain,
        explained_over_noise=expl,
        earns_place=ok,
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
            f"diagnose supports the bench setups (series_bench, parallel_bench); '{ds.setup}' "
            "is validated by fsarm_sim.measured but its replay (references + controller) is not "
            "implemented yet"
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
        scores_fits = [(score(ctx, cur, f, n_t, n_h), f) for f in good]
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
            cur = top_f
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
            if top_s.explained_over_noise < MIN_EXPLAINED:
                why.append(
                    f"explains {top_s.explained_over_noise:.3f} of the noise variance "
                    f"(< {MIN_EXPLAINED:g})"
                )
            reason = f"best candidate {top_s.label} does not earn its place: " + "; ".join(why)
            steps.append(
                Step(len(steps) + 1, all_scores, None, top_s.effect, margin, prob, look, reason)
            )
            break
    final = C.refine(ctx, cur) if named else cur
    if named:
        final.label = "nominal + " + " + ".join(named)
    gap_b = nrmse(inp.y, nom.yhat, ctx.held)
    gap_a = nrmse(inp.y, final.yhat, ctx.held)
    rms_final = math.sqrt(final.mse_held)
    within = ctx.sigma_y > 0 and rms_final <= 1.15 * ctx.sigma_y
    if not named:
        verdict = (
            "nothing is missing within noise: the refit nominal model leaves a held-out residual "
            f"of {rms_final:.4g} (noise floor {ctx.sigma_y:.4g}); no candidate earns its place"
        )
    else:
        verdict = (
            f"missing: {', '.join(named)}; held-out NRMSE {100 * gap_b:.3g} % -> {100 * gap_a:.3g} %"
            + (
                "; the rest is within noise"
                if within
                else f"; residual {rms_final / ctx.sigma_y:.2g} x the noise floor remains"
            )
        )
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
    )


def residual_signature(diag: Diagnosis, fit: C.Fit) -> dict[str, Any]:
    ctx = diag.ctx
    inp = ctx.inp
    s = inp.theta_s if inp.inertia_load and inp.theta_s is not None else inp.s
    x = inp.u - s
    xd = np.gradient(x, inp.h)
    return signature(inp.y, fit.yhat, x, xd, inp.phi, inp.t, ctx.sigma_y).as_dict()
