"""Forward selection of missing effects: add one at a time while each still earns its place.

This module holds the rules and their numbers; the loop that applies them to every setup (the
benches and the arm) is :func:`.core.diagnose`.

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
from dataclasses import dataclass, field
from typing import Any

from fsarm_sim.discrepancy import variants
from fsarm_sim.discrepancy.benchmodel import stated_model
from fsarm_sim.discrepancy.input_errors import input_error_floor, quantisation_step, remeasure
from fsarm_sim.discrepancy.residuals import bic

__all__ = [
    "BIC_THRESHOLD",
    "LOOK_ALIKES",
    "MAX_EFFECTS",
    "MIN_EXPLAINED",
    "MIN_EXPLAINED_EXTRA",
    "MIN_GAIN",
    "MIN_GAIN_DOMINANT",
    "MIN_SHARE_EXTRA",
    "Judgement",
    "Score",
    "Step",
    "extra_share_ok",
    "input_error_floor",  # the bench's, in .input_errors (kept here for old imports)
    "judge",
    "quantisation_step",  # ditto
    "remeasure",  # ditto
    "stated_model",  # the bench's, in .benchmodel (kept here for old imports)
]

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
    frozenset({variants.DELAY, variants.VISCOUS}),
    frozenset({variants.BACKLASH, variants.NONLINEAR}),
    frozenset({variants.COULOMB, variants.VISCOUS}),
    frozenset({variants.COULOMB, variants.HYSTERESIS}),
    frozenset({variants.VISCOUS, variants.HYSTERESIS}),
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
    joint: bool = False  # a joint step: ``added`` names two or three effects ("a+b")
    added_effects: list[str] = field(default_factory=list)  # the effects this step names

    def __post_init__(self) -> None:
        if self.added is not None and not self.added_effects:
            self.added_effects = [self.added]

    def as_dict(self) -> dict[str, Any]:
        d = dict(self.__dict__)
        d["scores"] = [s.as_dict() for s in self.scores]
        return d


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
