"""One diagnosis core for every setup: forward selection of the missing effects behind a small
:class:`Setup` protocol.

A setup (the series and parallel benches in :mod:`.bench_setup`, the arm in :mod:`.arm`) knows how
to replay its records and fit its models; the core knows how to choose. :func:`diagnose`:

1. the setup's nominal model, as stated and with its own parameters refit (:meth:`Setup.nominal`),
2. each step: every candidate effect fitted on top of the current model
   (:meth:`Setup.candidates`), scored by the rules of :mod:`.selection` (:func:`.selection.judge`
   on the setup's :meth:`~Setup.cost`; every BIC of a step uses the effective sample counts of
   the candidate that fits the held-out samples best), ranked by effect (best variant each);
   the best effect is added when it earns its place; else, when the held-out residual stays at
   least :data:`JOINT_TRIGGER` x the noise floor, pairs and triples are fitted jointly
   (:func:`joint_step`: effects that come together, neither earning its place alone) and named
   together when the combination and each member earn their places; else the selection stops,
3. with ``restart`` (the benches): when it stopped with the residual still above
   :data:`RESTART_TRIGGER` x the noise floor, the joint search once more from the refit nominal
   model (:func:`restart_step`: a look-alike of two true effects can win a greedy step), and
   backward elimination (:func:`prune`: variants and look-alikes swapped, effects that no
   longer earn their place on top of the others dropped),
4. the final model (:meth:`Setup.finish`) and the setup's verdict (:meth:`Setup.conclude`).

The report (:mod:`.report`) is the core's too: the common keys of the result, the model file
the setup writes, the setup's plots and print-out. A new setup implements the protocol and gets
the selection, the judgement, the scores, the result file and the ``fsarm diagnose`` print-out.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Generic, Protocol, TypeVar, overload

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import selection as S
from fsarm_sim.discrepancy.residuals import effective_n
from fsarm_sim.discrepancy.selection import Score, Step
from fsarm_sim.errors import FsarmError
from fsarm_sim.records.measured import Dataset

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


class UnsupportedSetupError(FsarmError, NotImplementedError):
    """The dataset's setup has no replay in the discrepancy workflow (yet)."""


class Fit(Protocol):
    """A fitted model of a setup: what the core reads and labels."""

    label: str
    effect: str | None  # the candidate's effect (None: no candidate, e.g. the nominal refit)
    variant: str | None
    note: str
    k: int  # fitted parameters (BIC's k)

    @property
    def model(self) -> Any: ...


F = TypeVar("F", bound=Fit)


@dataclass
class ReportParts:
    """The setup's own parts of the result (:func:`.report.result_dict` puts them in place)."""

    head: dict[str, Any]  # after "dataset": setup, samples, rate, main channel, ...
    gaps: dict[str, Any]  # after gap_before / gap_after: noise floors, gap over noise, ...
    nominal_refit: dict[str, Any]
    noise_floor: dict[str, Any]
    nrmse: dict[str, dict[str, float]]  # per channel: catalogue / nominal / final
    signatures: dict[str, Any]
    method: dict[str, Any]  # what the setup's replay, channels and BIC are
    tail: dict[str, Any] = field(default_factory=dict)  # after runtime_s


class Setup(Protocol[F]):
    """What the core needs from a setup. ``F`` is the setup's fit type.

    Costs are the setup's mean squares (one channel's MSE on a bench, the noise-weighted MSE of
    all channels on the arm); ``noise_var`` is the cost of pure noise in the same units.
    """

    @property
    def dataset(self) -> Dataset: ...

    @property
    def ctx(self) -> Any:
        """What the setup's fits share (the context of the record)."""
        ...

    @property
    def mse_name(self) -> str:
        """The cost's name in the reasons ("MSE", "weighted MSE")."""
        ...

    @property
    def noise_var(self) -> float:
        """The cost of pure noise."""
        ...

    @property
    def look_alikes(self) -> Collection[frozenset[str]]:
        """Effect pairs that mimic each other (flagged in the confidence)."""
        ...

    @property
    def score_cell(self) -> tuple[str, Callable[[Score], str]]:
        """The print-out's cost column: (header, cell of a score)."""
        ...

    @property
    def load_hint(self) -> str:
        """How to load the model file this setup writes (printed after writing it)."""
        ...

    def nominal(self) -> tuple[F, F]:
        """(the nominal model as stated, the nominal model with its own parameters refit)."""
        ...

    def candidates(self, cur: F, named: Sequence[str]) -> list[F]:
        """Every applicable candidate effect not in ``named``, fitted on top of ``cur`` (with
        ``effect``, ``variant`` and ``label`` set); [] when none could be fitted."""
        ...

    def cost(self, fit: F) -> tuple[float, float, int]:
        """(teaching cost, held-out cost, k) of a fit."""
        ...

    def residual(self, fit: F) -> tuple[FloatArray, BoolArray, BoolArray]:
        """(residual, teaching mask, held-out mask): the series whose autocorrelation gives the
        effective sample counts."""
        ...

    def gap(self, fit: F) -> float:
        """Held-out NRMSE of the main channel."""
        ...

    def effect_params(self, fit: F) -> dict[str, Any]:
        """The fitted parameters of a candidate's effect."""
        ...

    def accept(self, fit: F) -> F:
        """The model that carries on once ``fit``'s effect is named (e.g. refined)."""
        ...

    def finish(self, fit: F, named: Sequence[str]) -> F:
        """The final model from the last accepted one."""
        ...

    def conclude(self, nominal: F, final: F, named: Sequence[str]) -> tuple[str, dict[str, Any]]:
        """(verdict, extras) of the diagnosis."""
        ...

    def parameters(self, model: Any) -> dict[str, Any]:
        """A model's fitted parameters: ``{"nominal": {...}, "effects": [...]}``."""
        ...

    def save_model(self, model: Any, path: Path) -> Path:
        """Write the model file of ``model``."""
        ...

    def report(self, diag: Diagnosis[F]) -> ReportParts: ...

    def plots(self, diag: Diagnosis[F], folder: Path) -> list[Path]:
        """The setup's plots (time series, loops, NRMSE per channel) into ``folder``."""
        ...

    def summary_lines(self, diag: Diagnosis[F]) -> list[str]:
        """The print-out after the step tables."""
        ...


@dataclass
class Diagnosis(Generic[F]):
    """What a diagnosis found, with the setup that found it."""

    dataset: Dataset
    setup: Setup[F]
    catalogue: F  # the nominal model as stated
    nominal: F  # ... with its own parameters refit
    final: F
    steps: list[Step]
    named: list[str]
    runtime_s: float
    verdict: str
    extras: dict[str, Any] = field(default_factory=dict)
    # per step: (the model it started from, the best fit of each effect ranked) - for
    # :mod:`.design` (not in the result file)
    trail: list[tuple[F, list[tuple[Score, F]]]] = field(default_factory=list)

    @property
    def ctx(self) -> Any:
        return self.setup.ctx

    @property
    def gap_before(self) -> float:
        """Held-out NRMSE of the main channel, refit nominal model."""
        return self.setup.gap(self.nominal)

    @property
    def gap_after(self) -> float:
        """Held-out NRMSE of the main channel, final model."""
        return self.setup.gap(self.final)

    def gap_over_noise(self, fit: F) -> float:
        """Held-out residual RMS in noise-floor units (1 = noise)."""
        return math.sqrt(self.setup.cost(fit)[1] / self.setup.noise_var)


D = TypeVar("D", bound=Diagnosis[Any])


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
    j = S.judge(
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
    if top.d_bic_teach >= -S.BIC_THRESHOLD or top.d_bic_held >= -S.BIC_THRESHOLD:
        why.append(
            f"BIC change {top.d_bic_teach:+.1f} (teaching) / {top.d_bic_held:+.1f} "
            f"(held-out) not below -{S.BIC_THRESHOLD:g}"
        )
    if top.gain_held < S.MIN_GAIN:
        why.append(f"held-out {mse_name} gain {100 * top.gain_held:.2f} % < {100 * S.MIN_GAIN:g} %")
    min_expl = S.MIN_EXPLAINED_EXTRA if top.extra else S.MIN_EXPLAINED
    if top.explained_over_noise < min_expl:
        why.append(
            f"explains {top.explained_over_noise:.3f} of the noise variance "
            f"(< {min_expl:g}{' for an extra effect' if top.extra else ''})"
        )
    if top.extra and not S.extra_share_ok(top.share_of_explained, top.gain_held):
        why.append(
            f"explains {100 * top.share_of_explained:.2g} % of what the named effects "
            f"explain (< {100 * S.MIN_SHARE_EXTRA:g} % for an extra effect) and removes "
            f"only {100 * top.gain_held:.1f} % of what is left "
            f"(< {100 * S.MIN_GAIN_DOMINANT:g} %)"
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


def _margin(top: Score, runner: Score | None) -> tuple[float | None, float | None]:
    """(held-out BIC margin, BIC's probability of the winner over the runner-up)."""
    if runner is None:
        return None, None
    margin = runner.d_bic_held - top.d_bic_held
    return margin, 1.0 / (1.0 + math.exp(-min(max(margin, -700.0), 700.0) / 2.0))


def step(
    setup: Setup[F], cur: F, named: Sequence[str], index: int, nom: F
) -> tuple[Step, F | None]:
    """One selection step: (the step, the accepted fit or None when nothing earns its place)."""
    st, accepted, _ = _step(setup, cur, named, index, nom)
    return st, accepted


def _step(
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
    margin, prob = _margin(top_s, runner)
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


# ---------------------------------------------------------------------------- joint search

JOINT_TRIGGER = 2.0  # held-out residual RMS / noise floor from which the joint search runs
JOINT_FIRST = 4  # the best single effects whose fits are extended by a second effect
JOINT_TRIPLES_FROM = 2  # the best pairs extended by a third (when no pair earns its place)


@dataclass
class _Combo(Generic[F]):
    """A joint candidate: its members (effect, variant) in the order fitted, the fit, and the
    fits of its sub-models (each without one member)."""

    members: list[tuple[str, str]]
    fit: F
    subs: dict[str, F]  # member effect -> the fit without it

    @property
    def effects(self) -> frozenset[str]:
        return frozenset(e for e, _ in self.members)


def _label(members: Sequence[tuple[str, str]]) -> str:
    return " + ".join(f"{e}[{v}]" for e, v in members)


def _joint_params(setup: Setup[F], fit: F, members: Sequence[tuple[str, str]]) -> dict[str, Any]:
    """The fitted parameters of every member of a joint fit (the setup reads one effect)."""
    keep = fit.effect, fit.variant
    out: dict[str, Any] = {}
    try:
        for e, v in members:
            fit.effect, fit.variant = e, v
            out[f"{e}[{v}]"] = setup.effect_params(fit)
    finally:
        fit.effect, fit.variant = keep
    return out


def _extend(
    setup: Setup[F], base: F, base_members: list[tuple[str, str]], exclude: Sequence[str]
) -> list[tuple[list[tuple[str, str]], F]]:
    """Every candidate fitted on top of ``base`` (its effects not in ``exclude``)."""
    out = []
    for f in setup.candidates(base, list(exclude)):
        members = [*base_members, (f.effect or "", f.variant or "")]
        f.label = _label(members)
        out.append((members, f))
    return out


def _member_needed(setup: Setup[F], sub: F, full: F, n_t: float, n_h: float, nom: F) -> bool:
    """Does the member that ``full`` adds to ``sub`` earn its place there, by the rule of an
    extra effect (:mod:`.selection`)?"""
    j = S.judge(setup.cost(sub), setup.cost(full), n_t, n_h, setup.noise_var, setup.cost(nom)[1])
    return j.earns_place and j.explained_over_noise >= S.MIN_EXPLAINED_EXTRA


def joint_step(
    setup: Setup[F],
    cur: F,
    named: Sequence[str],
    index: int,
    nom: F,
    ranked: list[tuple[Score, F]],
    room: int,
    both_orders: bool = False,
) -> tuple[Step, F | None]:
    """Pairs (then triples) of effects fitted jointly on top of ``cur``, when no single effect
    earns its place (``ranked``: that step's best fit of each effect) but the residual stays
    well above the noise floor.

    Pairs: each of the :data:`JOINT_FIRST` best single fits (lowest held-out cost) extended by
    every other candidate (the candidates' own joint fit: linear parameters solved together,
    nonlinear ones searched on top of the first member's). Triples (``room`` >= 3, no pair
    earning): the :data:`JOINT_TRIPLES_FROM` best pairs extended by a third effect. Ranked by
    held-out BIC change against ``cur`` (one effective sample count for the whole step). A
    combination is named when it earns its place as a whole (the rule of a single effect, or
    of an extra effect when effects are named already) *and* each member earns its place on
    top of the others (the rule of an extra effect, against the combination without it), so
    that no passenger rides along with a real pair. ``both_orders``: a pair of two of the best
    single fits is fitted in both orders (the second member's nonlinear setting is searched
    with the first in place, so the order matters when the first alone settles off its true
    value, e.g. a delay that absorbs part of a damper's lead); the better of the two counts. A
    setup with the optional ``joint_pairs(cur, named)`` method fits its pairs itself (the arm,
    :mod:`.arm_joint`: every pair together from the start) - they replace the extended singles."""
    singles = {s.effect: f for s, f in ranked}
    firsts = sorted(singles.items(), key=lambda ef: setup.cost(ef[1])[1])[:JOINT_FIRST]
    combos: list[_Combo[F]] = []
    done: list[str] = []
    own: Callable[[F, Sequence[str]], list[tuple[list[tuple[str, str]], F]]] | None = getattr(
        setup, "joint_pairs", None
    )
    if own is not None:  # the setup fits its pairs itself (optional in the protocol: the arm)
        for members, f in own(cur, named):
            e_a, e_b = members[0][0], members[1][0]
            subs = {e: singles[o] for e, o in ((e_a, e_b), (e_b, e_a)) if o in singles}
            f.label = _label(members)
            combos.append(_Combo(members, f, subs))
        firsts = []
    for e_a, f_a in firsts:
        m_a = [(e_a, f_a.variant or "")]
        for members, f in _extend(setup, f_a, m_a, [*named, e_a, *done]):
            subs = {members[1][0]: f_a}
            if members[1][0] in singles:
                subs[e_a] = singles[members[1][0]]
            combos.append(_Combo(members, f, subs))
        if not both_orders:
            done.append(e_a)
    if room >= 3 and combos and both_orders:  # triples only when no pair earns its place
        n_t2, n_h2 = common_n_eff(setup, [c.fit for c in combos])
        if any(
            score(setup, cur, c.fit, n_t2, n_h2, nom).earns_place
            and all(_member_needed(setup, sub, c.fit, n_t2, n_h2, nom) for sub in c.subs.values())
            and len(c.subs) == len(c.members)
            for c in combos
        ):
            room = 2
    if room >= 3 and combos:
        pairs: dict[frozenset[str], _Combo[F]] = {}
        for c in sorted(combos, key=lambda c: setup.cost(c.fit)[1], reverse=True):
            pairs[c.effects] = c  # the better order of a pair last
        best_pairs = sorted(pairs.values(), key=lambda c: setup.cost(c.fit)[1])[:JOINT_TRIPLES_FROM]
        seen: set[frozenset[str]] = set()
        for pc in best_pairs:
            for members, f in _extend(setup, pc.fit, pc.members, [*named, *pc.effects]):
                effs = frozenset(e for e, _ in members)
                sub_pairs = {e: pairs.get(effs - {e}) for e in effs}
                if effs in seen or any(v is None for v in sub_pairs.values()):
                    continue  # a member's need could not be judged without another fit
                seen.add(effs)
                combos.append(_Combo(members, f, {e: c.fit for e, c in sub_pairs.items() if c}))
    if not combos:
        return Step(index, [], None, None, None, None, False, "no joint candidate", True), None
    n_t, n_h = common_n_eff(setup, [c.fit for c in combos])
    scored: list[tuple[Score, _Combo[F]]] = []
    for c in combos:
        sc = score(setup, cur, c.fit, n_t, n_h, nom)
        sc.label = _label(c.members)
        sc.effect = "+".join(e for e, _ in c.members)
        sc.variant = "+".join(v for _, v in c.members)
        sc.params = _joint_params(setup, c.fit, c.members)
        needed = len(c.subs) == len(c.members) and all(
            _member_needed(setup, sub, c.fit, n_t, n_h, nom) for sub in c.subs.values()
        )
        if sc.earns_place and not needed:
            sc.earns_place = False
            sc.note = (sc.note + "; " if sc.note else "") + "a member does not earn its place"
        scored.append((sc, c))
    scored.sort(key=lambda sc_c: sc_c[0].d_bic_held)
    per_set: dict[frozenset[str], tuple[Score, _Combo[F]]] = {}
    for sc, c in scored:
        per_set.setdefault(c.effects, (sc, c))
    best = list(per_set.values())
    scores = [sc for sc, _ in scored]
    winners = [(sc, c) for sc, c in best if sc.earns_place]
    if not winners:
        top = best[0][0]
        reason = "joint search: " + why_not(top, setup.mse_name)
        if top.d_bic_held < -S.BIC_THRESHOLD and top.gain_held >= S.MIN_GAIN:
            reason = f"joint search: best combination {top.label} has a member that does not earn its place"
        return Step(index, scores, None, None, None, None, False, reason, True), None
    top_s, top_c = winners[0]
    others = [sc for sc, c in best if c is not top_c]
    single_best = ranked[0][0] if ranked else None
    runner = min(
        [*others, *([single_best] if single_best else [])],
        key=lambda sc: sc.d_bic_held,
        default=None,
    )
    margin, prob = _margin(top_s, runner)
    names = [e for e, _ in top_c.members]
    reason = (
        f"joint search: {top_s.label} together lower held-out BIC by {-top_s.d_bic_held:.1f} "
        f"and held-out {setup.mse_name} by {100 * top_s.gain_held:.1f} %, each earning its "
        "place on top of the other(s); no one of them earns it alone"
    )
    st = Step(
        index,
        scores,
        "+".join(names),
        runner.label if runner else None,
        margin,
        prob,
        False,
        reason,
        True,
        names,
    )
    fit = top_c.fit
    fit.label = top_s.label
    fit.effect = "+".join(names)
    fit.variant = "+".join(v for _, v in top_c.members)
    return st, fit


def accept_joint(setup: Setup[F], fit: F, members: Sequence[tuple[str, str]]) -> F:
    """The model that carries on after a joint step: the setup's :meth:`Setup.accept` once per
    member (a setup reads the fit's ``effect`` to know what was named)."""
    label = fit.label
    for e, v in members:
        fit.effect, fit.variant = e, v
        fit = setup.accept(fit)
    fit.label = label
    return fit


RESTART_TRIGGER = math.sqrt(2.0)  # residual RMS / noise floor from which the restart runs


def _over(setup: Setup[F], fit: F) -> float:
    """Held-out residual RMS of ``fit`` in noise-floor units."""
    return math.sqrt(setup.cost(fit)[1] / setup.noise_var) if setup.noise_var > 0 else 0.0


def restart_step(
    setup: Setup[F],
    cur: F,
    named: Sequence[str],
    index: int,
    nom: F,
    ranked0: list[tuple[Score, F]],
    max_effects: int,
) -> tuple[Step, F | None]:
    """The joint search again, from the refit nominal model (``ranked0``: the first step's best
    fit of each effect), when the one-at-a-time selection stopped with the residual still above
    the noise floor. Greedy selection names first the effect that alone explains most, and a
    look-alike of two true effects can win that step (a backlash off its centre standing in for
    a backlash *and* an output offset) - what it then leaves is structured, so no later effect
    earns its place on top of it. The best combination (pairs in both orders, then triples; the
    rules of :func:`joint_step` against the nominal model) replaces what was named when it
    earns its place against the current model too: by the rule of an extra effect when it names
    a different set, or by a lower teaching *and* held-out cost when it names the same set."""
    jst, jfit = joint_step(setup, nom, [], index, nom, ranked0, max_effects, both_orders=True)
    if jfit is None:
        jst.reason = "restart from the nominal model: " + jst.reason
        return jst, None
    t_c, h_c, _ = setup.cost(cur)
    t_j, h_j, _ = setup.cost(jfit)
    same = set(jst.added_effects) == set(named)
    if same:
        better = t_j < t_c and h_j < h_c
        why = "same effects, a better fit" if better else "same effects, no better fit"
    else:
        n_t, n_h = common_n_eff(setup, [cur, jfit])
        j = S.judge(
            setup.cost(cur), setup.cost(jfit), n_t, n_h, setup.noise_var, setup.cost(nom)[1]
        )
        better = j.earns_place and j.explained_over_noise >= S.MIN_EXPLAINED_EXTRA
        why = (
            f"held-out BIC {j.d_bic_held:+.1f} and held-out {setup.mse_name} "
            f"{-100 * j.gain_held:+.1f} % against {' + '.join(named)}"
        )
    jst.reason = (
        f"restart from the nominal model ({' + '.join(named)} left "
        f"{_over(setup, cur):.2g} x the noise floor): {jst.added} - {why}; "
        + ("it replaces them" if better else "kept what was named")
    )
    if not better:
        jst.added, jst.added_effects = None, []
        return jst, None
    return jst, jfit


def prune(
    setup: Setup[F], cur: F, named: list[str], nom: F, steps: list[Step]
) -> tuple[F, list[str]]:
    """Backward elimination after the selection (setups with the optional ``holds``,
    ``swap_variants`` and ``without`` methods): a named effect the model no longer holds is not
    named; each named effect is refit as its other variants (kept when better on teaching and
    held-out samples) and as its look-alikes (kept when the BIC falls clearly: the setup's
    rule); then, latest named first, an effect that no longer earns its place on top of the
    others even by the rule of a *first* effect is dropped (an effect enters by the stricter
    rule of an extra effect and leaves only by the looser one, the usual asymmetry of stepwise
    selection that keeps it from cycling). A later effect or variant can make an earlier
    stand-in redundant - the effect named first too: a damper that stood in for a delay next to
    a backlash ends with a damping coefficient of zero within its interval once the delay is
    named. One effect is always kept; each drop is a step of its own. (``nom``: the refit
    nominal model, for the setups' protocol symmetry with :func:`joint_step`.)"""
    swap = getattr(setup, "swap_variants", None)
    drop = getattr(setup, "without", None)
    if drop is None:
        return cur, named
    named = list(named)
    holds: Callable[[F, str], bool] | None = getattr(setup, "holds", None)

    def drop_absent() -> None:
        for e in list(named):
            if holds is not None and len(named) >= 2 and not holds(cur, e):
                named.remove(e)
                steps.append(
                    Step(
                        len(steps) + 1,
                        [],
                        None,
                        None,
                        None,
                        None,
                        False,
                        f"pruning: {e} is no longer in the model (the fits of the other effects "
                        "dropped all its elements): not named",
                    )
                )

    drop_absent()
    if swap is not None:
        label = cur.label
        cur, replaced = swap(cur)
        cur.label = label
        for old, new in replaced.items():
            named[named.index(old)] = new
            steps.append(
                Step(
                    len(steps) + 1,
                    [],
                    new,
                    old,
                    None,
                    None,
                    True,
                    f"pruning: {new} replaces its look-alike {old} (held-out and teaching BIC "
                    "lower by more than 10 with the other effects refit around it)",
                )
            )
        drop_absent()
    changed = True
    while changed and len(named) >= 2:
        changed = False
        for e in reversed(named):
            sub = drop(cur, e)
            if sub is None:
                continue
            n_t, n_h = common_n_eff(setup, [sub, cur])
            if S.judge(setup.cost(sub), setup.cost(cur), n_t, n_h, setup.noise_var).earns_place:
                continue  # it still earns its place by the rule of a first effect: kept
            sc = score(setup, sub, cur, n_t, n_h)
            sc.label, sc.effect = f"{e} on top of the others", e
            steps.append(
                Step(
                    len(steps) + 1,
                    [sc],
                    None,
                    None,
                    None,
                    None,
                    False,
                    f"pruning: {e} no longer earns its place on top of the others (held-out BIC "
                    f"{sc.d_bic_held:+.1f}, held-out {setup.mse_name} gain "
                    f"{100 * sc.gain_held:.2f} %, explains {sc.explained_over_noise:.2f} of "
                    "the noise variance): dropped",
                )
            )
            label = cur.label
            named.remove(e)
            cur = sub
            cur.label = label
            drop_absent()
            changed = True
            break
    return cur, named


@overload
def diagnose(
    setup: Setup[F],
    max_effects: int,
    *,
    started: float | None = None,
    joint: bool = True,
    restart: bool = False,
) -> Diagnosis[F]: ...


@overload
def diagnose(
    setup: Setup[F],
    max_effects: int,
    *,
    kind: Callable[..., D],
    started: float | None = None,
    joint: bool = True,
    restart: bool = False,
) -> D: ...


def diagnose(
    setup: Setup[Any],
    max_effects: int,
    *,
    kind: Callable[..., Any] = Diagnosis,
    started: float | None = None,
    joint: bool = True,
    restart: bool = False,
) -> Any:
    """Forward selection on a setup: name and fit the effects missing from its nominal model,
    one at a time while each earns its place (at most ``max_effects``); when none does but the
    held-out residual stays at least :data:`JOINT_TRIGGER` x the noise floor, a joint search
    of pairs and triples (:func:`joint_step`, unless ``joint`` is False). ``restart`` (with
    ``joint``): pairs fitted in both orders, and once the selection stops with the held-out
    residual still :data:`RESTART_TRIGGER` x the noise floor, the joint search from the refit
    nominal model (:func:`restart_step`) may replace what was named. ``kind``: the
    diagnosis class to return; ``started``: ``time.perf_counter()`` at the start of the work
    (the record's preparation included), for ``runtime_s``."""
    t0 = time.perf_counter() if started is None else started
    cat, cur = setup.nominal()
    nom = cur
    named: list[str] = []
    steps: list[Step] = []
    trail: list[tuple[Any, list[tuple[Score, Any]]]] = []
    restarted = not (joint and restart)
    while True:
        st, accepted, ranked = (
            _step(setup, cur, named, len(steps) + 1, nom)
            if len(named) < max_effects
            else (None, None, [])
        )
        if st is not None:
            steps.append(st)
            trail.append((cur, ranked))
        if accepted is not None and st is not None and st.added is not None:
            named.append(st.added)
            cur = setup.accept(accepted)
            continue
        room = max_effects - len(named)
        over = _over(setup, cur)
        if joint and ranked and room >= 2 and over >= JOINT_TRIGGER:
            jst, jfit = joint_step(
                setup, cur, named, len(steps) + 1, nom, ranked, room, both_orders=restart
            )
            steps.append(jst)
            if jfit is not None:
                members = list(
                    zip(jst.added_effects, (jfit.variant or "").split("+"), strict=False)
                )
                named.extend(jst.added_effects)
                cur = accept_joint(setup, jfit, members)
                continue
        if restarted or not named or over < RESTART_TRIGGER or not trail:
            break
        restarted = True
        rst, rfit = restart_step(setup, cur, named, len(steps) + 1, nom, trail[0][1], max_effects)
        steps.append(rst)
        if rfit is None:
            break
        members = list(zip(rst.added_effects, (rfit.variant or "").split("+"), strict=False))
        named = list(rst.added_effects)
        cur = accept_joint(setup, rfit, members)
    if joint and restart and len(named) >= 2:
        cur, named = prune(setup, cur, named, nom, steps)
    final = setup.finish(cur, named)
    if named:
        final.label = "nominal + " + " + ".join(named)
    verdict, extras = setup.conclude(nom, final, named)
    return kind(
        dataset=setup.dataset,
        setup=setup,
        catalogue=cat,
        nominal=nom,
        final=final,
        steps=steps,
        named=named,
        runtime_s=time.perf_counter() - t0,
        verdict=verdict,
        extras=extras,
        trail=trail,
    )
