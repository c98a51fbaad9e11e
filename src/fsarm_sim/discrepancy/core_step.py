"""One step of the diagnosis core's forward selection: every candidate scored against the current
model by the rules of :mod:`.selection` (:func:`score`, on the effective sample counts the
step's candidates share: :func:`common_n_eff`), ranked by effect (:func:`rank`) and the step
recorded (:func:`step`). The selection itself is :func:`.core.diagnose`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from fsarm_sim.discrepancy import selection
from fsarm_sim.discrepancy.residuals import effective_n
from fsarm_sim.discrepancy.selection import Score, Step
from fsarm_sim.discrepancy.setup_protocol import F, Setup


def common_n_eff(setup: Setup[F], fits: Sequence[F]) -> tuple[float, float]:
    """Effective sample counts (teaching, held-out) shared by all candidates of a step: from
    the residual of the candidate that fits the held-out samples best - the closest to pure
    noise - so that every BIC of the step uses the same n (margins stay comparable)."""
    best = min(fits, key=lambda f: setup.cost(f)[1])
    r, teach, held = setup.residual(best)
    return effective_n(r, teach), effective_n(r, held)


def score(setup: Setup[F], cur: F, cand: F, n_t: float, n_h: float, nom: F | None = None) -> Score:
    """Scores of a candidate against the current model; ``nom`` (the refit nominal model) when
    the current model already holds named effects - then the stricter rule of an *extra* effect
    applies (:mod:`.selection`)."""
    t, h, _ = setup.cost(cand)
    j = selection.judge(
        setup.cost(cur),
        setup.cost(cand),
        n_t,
        n_h,
        setup.noise_var,
        setup.cost(nom)[1] if nom is not None and nom is not cur else None,
    )
    return j.score(
        label=cand.label,
        effect=cand.effect or "",
        variant=cand.variant or "",
        k=cand.k,
        mse_teach=t,
        mse_held=h,
        nrmse_held=setup.gap(cand),
        params=setup.effect_params(cand),
        note=cand.note,
    )


def why_not(top: Score, mse_name: str) -> str:
    """Why the best candidate of a step does not earn its place (the rules it fails)."""
    why = []
    if top.d_bic_teach >= -selection.BIC_THRESHOLD or top.d_bic_held >= -selection.BIC_THRESHOLD:
        why.append(
            f"BIC change {top.d_bic_teach:+.1f} (teaching) / {top.d_bic_held:+.1f} "
            f"(held-out) not below -{selection.BIC_THRESHOLD:g}"
        )
    if top.gain_held < selection.MIN_GAIN:
        why.append(
            f"held-out {mse_name} gain {100 * top.gain_held:.2f} % < {100 * selection.MIN_GAIN:g} %"
        )
    min_expl = selection.MIN_EXPLAINED_EXTRA if top.extra else selection.MIN_EXPLAINED
    if top.explained_over_noise < min_expl:
        why.append(
            f"explains {top.explained_over_noise:.3f} of the noise variance "
            f"(< {min_expl:g}{' for an extra effect' if top.extra else ''})"
        )
    if top.extra and not selection.extra_share_ok(top.share_of_explained, top.gain_held):
        why.append(
            f"explains {100 * top.share_of_explained:.2g} % of what the named effects "
            f"explain (< {100 * selection.MIN_SHARE_EXTRA:g} % for an extra effect) and removes "
            f"only {100 * top.gain_held:.1f} % of what is left "
            f"(< {100 * selection.MIN_GAIN_DOMINANT:g} %)"
        )
    return f"best candidate {top.label} does not earn its place: " + "; ".join(why)


def rank(
    setup: Setup[F], cur: F, named: Sequence[str], nom: F
) -> tuple[list[F], float, float, list[tuple[Score, F]], list[Score]]:
    """Fit and score every candidate on top of ``cur``: (fits, n_teach, n_held, the best variant
    of each effect ranked by held-out BIC change, every score ranked)."""
    fits = setup.candidates(cur, named)
    if not fits:
        return [], 0.0, 0.0, [], []
    n_t, n_h = common_n_eff(setup, fits)
    scored = sorted(
        ((score(setup, cur, f, n_t, n_h, nom), f) for f in fits), key=lambda sf: sf[0].d_bic_held
    )
    per_effect: dict[str, tuple[Score, F]] = {}
    for s, f in scored:  # the best variant of each effect (ties: the first fitted)
        per_effect.setdefault(s.effect, (s, f))
    return fits, n_t, n_h, list(per_effect.values()), [s for s, _ in scored]


def step_margin(top: Score, runner: Score | None) -> tuple[float | None, float | None]:
    """(held-out BIC margin, BIC's probability of the winner over the runner-up)."""
    if runner is None:
        return None, None
    margin = runner.d_bic_held - top.d_bic_held
    return margin, 1.0 / (1.0 + math.exp(-min(max(margin, -700.0), 700.0) / 2.0))


def step(
    setup: Setup[F], cur: F, named: Sequence[str], index: int, nom: F
) -> tuple[Step, F | None]:
    """One selection step: (the step, the accepted fit or None when nothing earns its place)."""
    st, accepted, _ = step_with_ranking(setup, cur, named, index, nom)
    return st, accepted


def step_with_ranking(
    setup: Setup[F], cur: F, named: Sequence[str], index: int, nom: F
) -> tuple[Step, F | None, list[tuple[Score, F]]]:
    fits, _, _, ranked, scores = rank(setup, cur, named, nom)
    if not fits:
        return (
            Step(index, [], None, None, None, None, False, "no candidate could be fitted"),
            None,
            [],
        )
    top_s, top_f = ranked[0]
    runner = ranked[1][0] if len(ranked) > 1 else None
    margin, prob = step_margin(top_s, runner)
    look = runner is not None and frozenset({top_s.effect, runner.effect}) in setup.look_alikes
    if not top_s.earns_place:
        reason = why_not(top_s, setup.mse_name)
        return Step(index, scores, None, top_s.effect, margin, prob, look, reason), None, ranked
    reason = (
        f"{top_s.label} lowers held-out BIC by {-top_s.d_bic_held:.1f} and held-out "
        f"{setup.mse_name} by {100 * top_s.gain_held:.1f} %"
    )
    runner_up = runner.effect if runner else None
    return Step(index, scores, top_s.effect, runner_up, margin, prob, look, reason), top_f, ranked
