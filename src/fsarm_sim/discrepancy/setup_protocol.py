"""What the diagnosis core (:mod:`.core`) asks of a setup: the :class:`Setup` protocol a setup
implements (the series and parallel benches in :mod:`.bench_setup`, the arm in :mod:`.arm`), the
:class:`Fit` it returns, the parts of its report (:class:`ReportParts`) and the
:class:`Diagnosis` the core hands back.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Generic, Protocol, TypeVar

import numpy as np
import numpy.typing as npt

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
