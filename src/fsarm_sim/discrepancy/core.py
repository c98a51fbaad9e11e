"""One diagnosis core for every setup: forward selection of the missing effects behind a small
:class:`Setup` protocol.

A setup (the series and parallel benches in :mod:`.bench_setup`, the arm in :mod:`.arm`) knows how
to replay its records and fit its models; the core knows how to choose. :func:`diagnose`:

1. the setup's nominal model, as stated and with its own parameters refit (:meth:`Setup.nominal`),
2. each step: every candidate effect fitted on top of the current model
   (:meth:`Setup.candidates`), scored by the rules of :mod:`.selection` (:func:`.selection.judge`
   on the setup's :meth:`~Setup.cost`; every BIC of a step uses the effective sample counts of
   the candidate that fits the held-out samples best), ranked by effect (best variant each);
   the best effect is added when it earns its place, else the selection stops,
3. the final model (:meth:`Setup.finish`) and the setup's verdict (:meth:`Setup.conclude`).

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


def step(
    setup: Setup[F], cur: F, named: Sequence[str], index: int, nom: F
) -> tuple[Step, F | None]:
    """One selection step: (the step, the accepted fit or None when nothing earns its place)."""
    fits = setup.candidates(cur, named)
    if not fits:
        return Step(index, [], None, None, None, None, False, "no candidate could be fitted"), None
    n_t, n_h = common_n_eff(setup, fits)
    scored = sorted(
        ((score(setup, cur, f, n_t, n_h, nom), f) for f in fits), key=lambda sf: sf[0].d_bic_held
    )
    per_effect: dict[str, tuple[Score, F]] = {}
    for s, f in scored:  # the best variant of each effect (ties: the first fitted)
        per_effect.setdefault(s.effect, (s, f))
    ranked = list(per_effect.values())
    top_s, top_f = ranked[0]
    runner = ranked[1][0] if len(ranked) > 1 else None
    margin = (runner.d_bic_held - top_s.d_bic_held) if runner is not None else None
    prob = 1.0 / (1.0 + math.exp(-min(margin, 700.0) / 2.0)) if margin is not None else None
    look = runner is not None and frozenset({top_s.effect, runner.effect}) in setup.look_alikes
    scores = [s for s, _ in scored]
    if not top_s.earns_place:
        reason = why_not(top_s, setup.mse_name)
        return Step(index, scores, None, top_s.effect, margin, prob, look, reason), None
    reason = (
        f"{top_s.label} lowers held-out BIC by {-top_s.d_bic_held:.1f} and held-out "
        f"{setup.mse_name} by {100 * top_s.gain_held:.1f} %"
    )
    runner_up = runner.effect if runner else None
    return Step(index, scores, top_s.effect, runner_up, margin, prob, look, reason), top_f


@overload
def diagnose(
    setup: Setup[F], max_effects: int, *, started: float | None = None
) -> Diagnosis[F]: ...


@overload
def diagnose(
    setup: Setup[F], max_effects: int, *, kind: Callable[..., D], started: float | None = None
) -> D: ...


def diagnose(
    setup: Setup[Any],
    max_effects: int,
    *,
    kind: Callable[..., Any] = Diagnosis,
    started: float | None = None,
) -> Any:
    """Forward selection on a setup: name and fit the effects missing from its nominal model,
    one at a time while each earns its place (at most ``max_effects``). ``kind``: the
    diagnosis class to return; ``started``: ``time.perf_counter()`` at the start of the work
    (the record's preparation included), for ``runtime_s``."""
    t0 = time.perf_counter() if started is None else started
    cat, cur = setup.nominal()
    nom = cur
    named: list[str] = []
    steps: list[Step] = []
    while len(named) < max_effects:
        st, accepted = step(setup, cur, named, len(steps) + 1, nom)
        steps.append(st)
        if accepted is None or st.added is None:
            break
        named.append(st.added)
        cur = setup.accept(accepted)
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
    )
