"""The bench diagnosis's re-test (issue 28): once the selection has ended and something is still
``unexplained``, every library effect not named is tested again on top of the effects named,
by the rule of a *first* effect and the realness checks instead of the extra effect's share
rule.

Why: an effect that enters after others must explain at least a noise variance and a share of
what those explained (:mod:`.selection`: the guard against corrections of a fitted law). When
the first effects are large, a real second or third effect a few noise variances in size
fails that share: the record ends ``unexplained`` with the library effect missing (a delay next
to a Coulomb friction ten times its size). The re-test runs only where the verdict already says
a structured residual remains above every floor - there, what a further effect takes up is not
noise - and asks of a candidate what a real effect shows:

* the rule of a first effect (:func:`.selection.judge` without the extra-effect terms: BIC
  lower by more than :data:`.selection.BIC_THRESHOLD` on teaching and held-out samples, held-out
  gain and explained variance above their minima),
* it is no look-alike of an effect named (:data:`.selection.LOOK_ALIKES`: those were weighed
  against each other by the selection and the pruning), and
* it passes the realness checks of :mod:`.realness` on its own contribution (the same size
  in every part of the record, parameters inside their ranges and off the fit's bounds), which
  a stand-in for a cause that varies along the record fails.

The best such candidate (by held-out BIC) is added, the others' settings refit around it
(:meth:`.bench_setup.BenchSetup.accept`), and the re-test repeats while the residual stays
``unexplained``. What it added is named only when the residual is then no longer
``unexplained``: a lost library effect accounts for what was left, while a library effect
that only nibbles at a cause outside the library (a delay taking up a little of a mount's
resonance) leaves it unexplained - then nothing is named and the step says what was tried. The
named set then goes through the realness checks of every effect
(:func:`.bench_setup.check_real`) like any other.
"""

from __future__ import annotations

from typing import Any

from fsarm_sim.discrepancy import realness, selection
from fsarm_sim.discrepancy.candidate_structure import BoolArray, Context, Fit
from fsarm_sim.discrepancy.core_step import rank
from fsarm_sim.discrepancy.selection import Score, Step
from fsarm_sim.discrepancy.setup_protocol import Diagnosis, Setup


def _first_passing(
    setup: Setup[Fit], ctx: Context, cur: Fit, named: list[str], nom: Fit, use: BoolArray
) -> tuple[Score, Fit] | None:
    """The best-ranked candidate on top of ``cur`` that is no look-alike of an effect ``named``,
    earns its place by the rule of a first effect and passes the realness checks; None if none."""
    _, n_t, n_h, ranked, _ = rank(setup, cur, named, nom)
    for s, f in ranked:
        if any(frozenset({s.effect, e}) in setup.look_alikes for e in named):
            continue
        j = selection.judge(setup.cost(cur), setup.cost(f), n_t, n_h, setup.noise_var)
        if not j.earns_place:
            continue
        eff = f.model.effect(s.effect, s.variant)
        params = dict(eff.params) if eff is not None else {}
        c = realness.check(
            s.effect,
            s.variant,
            params,
            ctx.inp.y,
            f.yhat,
            cur.yhat,
            ctx.inp.t,
            use,
            ctx.sigma_y,
        )
        if c.passed:
            return s, f
    return None


def retest(setup: Setup[Fit], ctx: Context, diag: Diagnosis[Fit], max_effects: int) -> bool:
    """Re-test the effects not named (module docstring) on a bench ``setup`` (its fitting
    context ``ctx``); True when one was named (``diag``'s final model, named effects, verdict
    and extras are then redone)."""
    if not diag.named or ctx.inp.inertia_load or not diag.extras.get("unexplained", False):
        return False
    cur, named, nom = diag.final, list(diag.named), diag.nominal
    use = ctx.teach | ctx.held
    tried: list[Score] = []
    resolved = False
    done: tuple[Fit, str, dict[str, Any]] | None = None  # the resolved model and its verdict
    while len(named) < max_effects:
        pick = _first_passing(setup, ctx, cur, named, nom, use)
        if pick is None:
            break
        s, f = pick
        tried.append(s)
        cur = setup.accept(f)
        named.append(s.effect)
        final = setup.finish(cur, named)
        final.label = "nominal + " + " + ".join(named)
        text, extras = setup.conclude(nom, final, named)
        if not extras["unexplained"]:
            resolved = True
            done = final, text, extras
            break
    if not tried:
        return False
    what = " + ".join(s.label for s in tried)
    if not resolved:
        diag.steps.append(
            Step(
                len(diag.steps) + 1,
                tried,
                None,
                None,
                None,
                None,
                False,
                f"re-test with a residual still unexplained: {what} would hold and take up part "
                "of it, but the residual stays unexplained with them - not a library effect "
                "that was lost: not named",
            )
        )
        return False
    diag.steps.append(
        Step(
            len(diag.steps) + 1,
            tried,
            "+".join(s.effect for s in tried),
            None,
            None,
            None,
            False,
            f"re-test with a residual still unexplained: {what} on top of "
            f"{' + '.join(diag.named)} (each by the rule of a first effect, holding across the "
            "record's parts) leave nothing unexplained: named",
            added_effects=[s.effect for s in tried],
        )
    )
    assert done is not None
    final, diag.verdict, extras = done  # the model and verdict that resolved it, not redone
    diag.final, diag.named = final, named
    diag.extras.update(extras)
    return True
