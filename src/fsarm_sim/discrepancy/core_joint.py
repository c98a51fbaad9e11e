"""The diagnosis core's joint search, restart and backward elimination: pairs and triples of
effects fitted jointly when none earns its place alone (:func:`joint_step`), the joint search
once more from the refit nominal model (:func:`restart_step`) and effects swapped or dropped
that no longer earn their place on top of the others (:func:`prune`). The selection itself is
:func:`.core.diagnose`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic

from fsarm_sim.discrepancy import selection
from fsarm_sim.discrepancy.core_step import common_n_eff, score, step_margin, why_not
from fsarm_sim.discrepancy.selection import Score, Step
from fsarm_sim.discrepancy.setup_protocol import F, Setup

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
    j = selection.judge(
        setup.cost(sub), setup.cost(full), n_t, n_h, setup.noise_var, setup.cost(nom)[1]
    )
    return j.earns_place and j.explained_over_noise >= selection.MIN_EXPLAINED_EXTRA


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
    combos = _pair_combos(setup, cur, named, singles, both_orders)
    if room >= 3 and combos and both_orders and _a_pair_earns(setup, cur, nom, combos):
        room = 2  # triples only when no pair earns its place
    if room >= 3 and combos:
        _add_triples(setup, named, combos)
    if not combos:
        return Step(index, [], None, None, None, None, False, "no joint candidate", True), None
    return _judge(setup, cur, index, nom, ranked, combos)


def _pair_combos(
    setup: Setup[F], cur: F, named: Sequence[str], singles: dict[str, F], both_orders: bool
) -> list[_Combo[F]]:
    """The pairs of :func:`joint_step`: the setup's own (``joint_pairs``) or the best single
    fits extended by every other candidate."""
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
    return combos


def _a_pair_earns(setup: Setup[F], cur: F, nom: F, combos: list[_Combo[F]]) -> bool:
    """Whether a pair earns its place as a whole, each member on top of the other."""
    n_t2, n_h2 = common_n_eff(setup, [c.fit for c in combos])
    return any(
        score(setup, cur, c.fit, n_t2, n_h2, nom).earns_place
        and all(_member_needed(setup, sub, c.fit, n_t2, n_h2, nom) for sub in c.subs.values())
        and len(c.subs) == len(c.members)
        for c in combos
    )


def _add_triples(setup: Setup[F], named: Sequence[str], combos: list[_Combo[F]]) -> None:
    """The best pairs extended by a third effect, appended to ``combos`` (a triple whose
    members' need cannot be judged without another fit is left out)."""
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


def _scored(
    setup: Setup[F], cur: F, nom: F, combos: list[_Combo[F]]
) -> list[tuple[Score, _Combo[F]]]:
    """Every combination scored against ``cur`` on one effective sample count, best first; one
    whose member does not earn its place on top of the others does not earn its place."""
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
    return scored


def _judge(
    setup: Setup[F],
    cur: F,
    index: int,
    nom: F,
    ranked: list[tuple[Score, F]],
    combos: list[_Combo[F]],
) -> tuple[Step, F | None]:
    """The joint step's verdict: the best combination that earns its place, or why none does."""
    scored = _scored(setup, cur, nom, combos)
    per_set: dict[frozenset[str], tuple[Score, _Combo[F]]] = {}
    for sc, c in scored:
        per_set.setdefault(c.effects, (sc, c))
    best = list(per_set.values())
    scores = [sc for sc, _ in scored]
    winners = [(sc, c) for sc, c in best if sc.earns_place]
    if not winners:
        top = best[0][0]
        reason = "joint search: " + why_not(top, setup.mse_name)
        if top.d_bic_held < -selection.BIC_THRESHOLD and top.gain_held >= selection.MIN_GAIN:
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
    margin, prob = step_margin(top_s, runner)
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


def residual_over_noise(setup: Setup[F], fit: F) -> float:
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
        j = selection.judge(
            setup.cost(cur), setup.cost(jfit), n_t, n_h, setup.noise_var, setup.cost(nom)[1]
        )
        better = j.earns_place and j.explained_over_noise >= selection.MIN_EXPLAINED_EXTRA
        why = (
            f"held-out BIC {j.d_bic_held:+.1f} and held-out {setup.mse_name} "
            f"{-100 * j.gain_held:+.1f} % against {' + '.join(named)}"
        )
    jst.reason = (
        f"restart from the nominal model ({' + '.join(named)} left "
        f"{residual_over_noise(setup, cur):.2g} x the noise floor): {jst.added} - {why}; "
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
    _drop_absent(cur, named, steps, holds)
    if swap is not None:
        cur = _swap_lookalikes(cur, named, steps, swap)
        _drop_absent(cur, named, steps, holds)
    changed = True
    while changed and len(named) >= 2:
        changed = False
        for e in reversed(named):
            sub = drop(cur, e)
            if sub is None:
                continue
            n_t, n_h = common_n_eff(setup, [sub, cur])
            if selection.judge(
                setup.cost(sub), setup.cost(cur), n_t, n_h, setup.noise_var
            ).earns_place:
                continue  # it still earns its place by the rule of a first effect: kept
            steps.append(_drop_step(setup, sub, cur, e, n_t, n_h, len(steps) + 1))
            label = cur.label
            named.remove(e)
            cur = sub
            cur.label = label
            _drop_absent(cur, named, steps, holds)
            changed = True
            break
    return cur, named


def _drop_absent(
    cur: F, named: list[str], steps: list[Step], holds: Callable[[F, str], bool] | None
) -> None:
    """Named effects the model ``cur`` no longer holds leave ``named`` (a step each)."""
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


def _swap_lookalikes(
    cur: F, named: list[str], steps: list[Step], swap: Callable[[F], tuple[F, dict[str, str]]]
) -> F:
    """The setup's look-alike swaps applied to ``cur`` and ``named`` (a step each)."""
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
    return cur


def _drop_step(setup: Setup[F], sub: F, cur: F, e: str, n_t: float, n_h: float, index: int) -> Step:
    """The step that drops ``e``: it no longer earns its place on top of the others."""
    sc = score(setup, sub, cur, n_t, n_h)
    sc.label, sc.effect = f"{e} on top of the others", e
    return Step(
        index,
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
