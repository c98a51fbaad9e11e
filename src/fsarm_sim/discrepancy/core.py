"""One diagnosis core for every setup: forward selection of the missing effects behind a small
:class:`~.setup_protocol.Setup` protocol.

A setup (the series and parallel benches in :mod:`.bench_setup`, the arm in :mod:`.arm`) knows how
to replay its records and fit its models; the core knows how to choose. :func:`diagnose`:

1. the setup's nominal model, as stated and with its own parameters refit
   (:meth:`~.setup_protocol.Setup.nominal`),
2. each step: every candidate effect fitted on top of the current model
   (:meth:`~.setup_protocol.Setup.candidates`), scored by the rules of :mod:`.selection`
   (:func:`.selection.judge` on the setup's :meth:`~.setup_protocol.Setup.cost`; every BIC of a step
   uses the effective sample counts of the candidate that fits the held-out samples best), ranked by
   effect (best variant each); the best effect is added when it earns its place; else, when the
   held-out residual stays at least :data:`~.core_joint.JOINT_TRIGGER` x the noise floor, pairs and
   triples are fitted jointly (:func:`~.core_joint.joint_step`: effects that come together, neither
   earning its place alone) and named together when the combination and each member earn their
   places; else the selection stops,
3. with ``restart`` (the benches): when it stopped with the residual still above
   :data:`~.core_joint.RESTART_TRIGGER` x the noise floor, the joint search once more from the refit
   nominal model (:func:`~.core_joint.restart_step`: a look-alike of two true effects can win a
   greedy step), and backward elimination (:func:`~.core_joint.prune`: variants and look-alikes
   swapped, effects that no longer earn their place on top of the others dropped),
4. the final model (:meth:`~.setup_protocol.Setup.finish`) and the setup's verdict
   (:meth:`~.setup_protocol.Setup.conclude`).

The report (:mod:`.report`) is the core's too: the common keys of the result, the model file
the setup writes, the setup's plots and print-out. A new setup implements the protocol and gets
the selection, the judgement, the scores, the result file and the ``fsarm diagnose`` print-out.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, TypeVar, overload

from fsarm_sim.discrepancy.core_joint import (
    JOINT_TRIGGER,
    RESTART_TRIGGER,
    accept_joint,
    joint_step,
    prune,
    residual_over_noise,
    restart_step,
)
from fsarm_sim.discrepancy.core_step import common_n_eff, step_with_ranking
from fsarm_sim.discrepancy.selection import Score, Step
from fsarm_sim.discrepancy.setup_protocol import (
    BoolArray,
    Diagnosis,
    F,
    Fit,
    FloatArray,
    ReportParts,
    Setup,
    UnsupportedSetupError,
)

# the protocol, the step's scoring and the joint search live in their own modules; the names
# setups and tests read through this one
__all__ = [
    "JOINT_TRIGGER",
    "RESTART_TRIGGER",
    "BoolArray",
    "Diagnosis",
    "Fit",
    "FloatArray",
    "ReportParts",
    "Setup",
    "UnsupportedSetupError",
    "common_n_eff",
    "diagnose",
    "joint_step",
]

D = TypeVar("D", bound=Diagnosis[Any])


def _select(
    setup: Setup[Any], nom: Any, max_effects: int, *, joint: bool, restart: bool
) -> tuple[Any, list[str], list[Step], list[tuple[Any, list[tuple[Score, Any]]]]]:
    """(the model, the named effects, the steps, each step's starting model and ranking) of the
    forward selection from the nominal model ``nom`` (:func:`diagnose`), before pruning."""
    cur = nom
    named: list[str] = []
    steps: list[Step] = []
    trail: list[tuple[Any, list[tuple[Score, Any]]]] = []
    restarted = not (joint and restart)
    while True:
        st, accepted, ranked = (
            step_with_ranking(setup, cur, named, len(steps) + 1, nom)
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
        over = residual_over_noise(setup, cur)
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
    return cur, named, steps, trail


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
    cat, nom = setup.nominal()
    cur, named, steps, trail = _select(setup, nom, max_effects, joint=joint, restart=restart)
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
