"""``fsarm design-experiment``: the bench input that best separates the diagnosis' near-ties.

When the two best effects of a selection step are near-ties (held-out BIC margin below
:data:`NEAR_TIE`; e.g. an input offset against backlash on a one-sided record: a dead zone that
the twist never crosses is an offset), the record cannot tell them apart; another record can.
:func:`design` proposes it:

1. the step with the smallest margin between its winner ``A`` and runner-up ``B`` (both fitted
   to the record, on top of the model the step started from);
2. every input of a small family (:func:`designs`: trajectory shape, amplitude, a bias that
   makes the twist one-sided or not, on the record's bench, load, bend and rate): ``A``'s model
   replayed on it (no noise) and ``B``'s structure fitted to that, and the other way round. The
   expected held-out BIC margin of the right effect over the wrong one, on a record of the
   design's length with the record's noise floor ``sigma``, is
   ``n_held ln(1 + MSE_wrong / sigma^2) - dk ln(n_held)`` (the right model leaves white noise;
   the wrong one the misfit on top) - the smaller of the two directions, since either may be
   true - and no larger than either effect's own expected margin over the model without it (a
   design too small to show the effects at all separates nothing), designs where an effect's
   contribution stays below :data:`MIN_VISIBLE` x the noise variance left out;
3. the design with the largest expected margin is written as a trajectory file
   (:func:`.synth.write_input_file`: ``t`` and the input angle, which the bench plays and
   ``fsarm synth --input-file`` reads), with its expected margin and that of the record's own
   input (same formula) beside it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import (
    candidate_inertia,
    candidate_structure,
    candidates,
    replay_inputs,
    synth,
)
from fsarm_sim.discrepancy.bench_setup import BenchDiagnosis, BenchSetup
from fsarm_sim.discrepancy.bench_setup import diagnose as bench_diagnose
from fsarm_sim.discrepancy.benchmodel import BenchModel, stated_model
from fsarm_sim.errors import FsarmError, InvalidParameterError
from fsarm_sim.records.measured import Dataset, stated_shaft

MIN_VISIBLE = 1.0  # the effect's contribution's variance / noise variance a design must reach
NESTED = 1e-2  # wrong-fit MSE / noise variance below which (on every design) a model nests
NEAR_TIE = 20.0  # held-out BIC margin below which two effects are near-ties (Kass-Raftery 10)
SHAPES = ("triangle", "multisine", "random")
BIASES = (-0.6, 0.0, 0.6)  # the input's mean, as a fraction of its amplitude
SPEEDS = (1.0, 4.0)
AMPLITUDES = (1.0, 0.3, 0.1)  # of the record's input amplitude (99.5th percentile of |input|)


class NothingToDesignError(FsarmError, ValueError):
    """The diagnosis has no two candidates to separate."""


@dataclass(frozen=True)
class Design:
    shape: str
    amplitude: float  # rad, peak of the input
    bias: float  # rad, the input's offset
    speed: float = 1.0  # the shape played this many times faster (frequency content)

    @property
    def label(self) -> str:
        return (
            f"{self.shape} x{self.speed:g} speed, amplitude {self.amplitude:.3g} rad, bias "
            f"{self.bias:+.3g} rad"
        )


def designs(amp: float) -> list[Design]:
    out = []
    for sp in SPEEDS:
        for a in AMPLITUDES:
            for b in BIASES:
                for sh in SHAPES:
                    if a < 1.0 and (sh != "triangle" or b != 0.0):
                        continue  # smaller amplitudes: the triangle's nested loops, centred
                    out.append(Design(sh, a * amp * (1 - abs(b)), b * a * amp, sp))
    return out


def input_of(d: Design, t: np.ndarray, setup: str, seed: int) -> np.ndarray:
    """The design's input angle on the time grid ``t`` (starts and ends at rest)."""
    limit = synth.SERIES_RATE_LIMIT if setup == "series_bench" else synth.PARALLEL_RATE_LIMIT
    # the shape on a time axis ``speed`` x faster, its rate kept below the bench's limit
    u = synth.trajectory(d.shape, t * d.speed, d.amplitude, limit / d.speed, seed)
    env = synth.envelope(t)  # the same ramp as the trajectories'
    return np.asarray(u + d.bias * env, dtype=np.float64)


def _record(model: BenchModel, ds: Dataset, t: np.ndarray, u: np.ndarray) -> Dataset:
    """A noise-free record of ``model`` driven by ``u`` (the record's rate, bend and load)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        f = synth.write_input_file(Path(tmp) / "u.csv", t, u, model.setup)
        phi = ds.columns.get("phi_b")
        bend = float(np.median(phi)) if model.setup == "series_bench" and phi is not None else 0.0
        rec = synth.Recording(
            duration_s=float(t[-1] - t[0]),
            rate_hz=1.0 / float(t[1] - t[0]),
            noise=0.0,
            bend_rad=bend,
            input_file=str(f),
        )
        cols, side = synth.synthesize(model, rec)
    return Dataset(
        path=Path("design"),
        setup=model.setup,
        columns=cols,
        sidecar=side,
        shaft=stated_shaft(),
        load_inertia_kgm2=model.load_inertia_kgm2,
    )


def wrong_fit_mse(
    truth: BenchModel,
    ds: Dataset,
    t: np.ndarray,
    u: np.ndarray,
    base: candidate_structure.Structure,
    wrong: candidate_structure.Fit,
) -> tuple[float, int, float, int]:
    """(held-out MSE, k) of the wrong effect's structure and (held-out MSE, k) of the step's base
    model (no effect) fitted to ``truth``'s noise-free record on the input ``u``."""
    rec = _record(truth, ds, t, u)
    ctx = candidate_structure.make_context(replay_inputs.prepare_inputs(rec), stated_model(rec))
    ctx.sigma_y = max(ctx.sigma_y, 1e-12)
    cur = candidate_inertia.solve(ctx, base.copy())
    fit = candidates.candidate(ctx, cur, wrong.effect or "", wrong.variant or "")
    if fit is None:
        return math.inf, 0, float(cur.mse_held), cur.k
    return float(fit.mse_held), fit.k, float(cur.mse_held), cur.k


def expected_margin(mse_wrong: float, sigma: float, n_held: float, dk: int) -> float:
    """Expected held-out BIC margin of the right model over the wrong one (module docstring)."""
    if not math.isfinite(mse_wrong):
        return math.inf
    return n_held * math.log1p(mse_wrong / sigma**2) - dk * math.log(max(n_held, 2.0))


def _tie(diag: BenchDiagnosis) -> tuple[int, Any, Any, Any, str, str]:
    """(step index, base fit, A fit, B fit) of the step that named an effect with the smallest
    margin (no step named one: the first step)."""
    best: tuple[float, int, Any, Any, Any] | None = None  # margin, step, base, (score, fit) x2
    added = [i for i, st in enumerate(diag.steps[: len(diag.trail)]) if st.added and not st.joint]
    for i, (base, ranked) in enumerate(diag.trail):
        if len(ranked) < 2 or (added and i not in added) or (not added and i > 0):
            continue
        margin = ranked[1][0].d_bic_held - ranked[0][0].d_bic_held
        if best is None or margin < best[0]:
            best = (margin, i, base, ranked[0], ranked[1])
    if best is None:
        raise NothingToDesignError("no selection step had two candidates to separate")
    return best[1], best[2], best[3][1], best[4][1], best[3][0].label, best[4][0].label


def _design_row(
    d: Design | None,
    u: np.ndarray,
    tie: tuple[Any, Any, Any],
    ds: Dataset,
    t: np.ndarray,
    sigma: float,
    n_held: float,
) -> dict[str, Any]:
    """Both directions' expected margins of one candidate input (``d`` None: the record's own),
    ``tie`` the near-tie's (base, A, B) fits."""
    base, fa, fb = tie
    m_b, k_b, m0_a, k0 = wrong_fit_mse(fa.model, ds, t, u, base.structure, fb)
    m_a, k_a, m0_b, _ = wrong_fit_mse(fb.model, ds, t, u, base.structure, fa)
    marg_a = expected_margin(m_b, sigma, n_held, k_a - k_b)  # A true, B fitted
    marg_b = expected_margin(m_a, sigma, n_held, k_b - k_a)  # B true, A fitted
    # either must still be found at all: its margin over the model without it, and its
    # contribution above the selection's floor (MIN_EXPLAINED_EXTRA of the noise variance)
    det = min(
        expected_margin(m0_a, sigma, n_held, k_a - k0),
        expected_margin(m0_b, sigma, n_held, k_b - k0),
    )
    seen = min(m0_a, m0_b) >= MIN_VISIBLE * sigma**2
    return {
        "design": d.label if d else "the record's own input",
        "shape": d.shape if d else None,
        "amplitude_rad": d.amplitude if d else None,
        "bias_rad": d.bias if d else None,
        "speed": d.speed if d else None,
        "expected_margin_if_A": marg_a,
        "expected_margin_if_B": marg_b,
        "expected_margin_over_base": det,
        "seen": seen,
        "wrong_mse_over_noise": (m_b / sigma**2, m_a / sigma**2),
        "u": u,
    }


def _score(rows: list[dict[str, Any]]) -> list[bool]:
    """Sets each row's ``expected_margin``; returns (A inside B, B inside A).

    A direction where the wrong model holds the right one (backlash of zero width *is* an input
    offset) leaves the wrong fit at the right one's noise on every input: no experiment moves
    its margin from -dk ln n, so it is left out of the design's score (and said)."""
    nested = [all(r["wrong_mse_over_noise"][j] < NESTED for r in rows) for j in (0, 1)]
    for r in rows:
        dirs = [r[f"expected_margin_if_{x}"] for x, n in zip("AB", nested, strict=True) if not n]
        r["expected_margin"] = (
            min([*dirs, r["expected_margin_over_base"]]) if r["seen"] else -math.inf
        )
    return nested


def design(
    ds: Dataset,
    diag: BenchDiagnosis | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> dict[str, Any]:
    """The separating experiment of a bench record (module docstring): a dict with the near-tie,
    every design's expected margins, and the best design's input (``t``, ``u``).
    ``progress(step, done, total)`` is called before the diagnosis and before each candidate
    input."""
    if ds.setup not in synth.INPUT_COLUMNS:
        raise InvalidParameterError(
            f"design-experiment designs bench inputs (series_bench, parallel_bench), not {ds.setup!r}"
        )
    if progress is not None:
        progress("diagnosing the record", 0, 1)
    diag = diag if diag is not None else bench_diagnose(ds)
    setup = diag.setup
    assert isinstance(setup, BenchSetup)
    ctx = setup.ctx
    i, base, fa, fb, label_a, label_b = _tie(diag)
    sigma = ctx.sigma_y
    t = ctx.inp.t - ctx.inp.t[0]
    amp = float(np.quantile(np.abs(ctx.inp.u), 0.995)) or ctx.x_ref
    n_held = float(ctx.held.sum())
    u_rec = ds.columns[synth.INPUT_COLUMNS[ds.setup]]
    rows: list[dict[str, Any]] = []
    cands: list[tuple[Design | None, np.ndarray]] = [(None, np.asarray(u_rec, dtype=np.float64))]
    cands += [(d, input_of(d, t, ds.setup, seed=k)) for k, d in enumerate(designs(amp))]
    for k, (d, u) in enumerate(cands):
        if progress is not None:
            progress("both fits on each candidate input", k + 1, len(cands) + 1)
        rows.append(_design_row(d, u, (base, fa, fb), ds, t, sigma, n_held))
    nested = _score(rows)
    own, others = rows[0], rows[1:]
    best = max(others, key=lambda r: float(r["expected_margin"]))
    st = diag.steps[i]
    return {
        "dataset": str(ds.path),
        "step": st.index,
        "A": label_a,
        "B": label_b,
        "record_margin": st.bic_margin,
        "near_tie": st.bic_margin is not None and st.bic_margin < NEAR_TIE,
        "nested": {
            "A_inside_B": nested[0],
            "B_inside_A": nested[1],
            "note": "where the wrong model holds the right one, its fit matches the right one's "
            "on every input: the margin stays at -dk ln n whatever the experiment; the design "
            "maximises the other direction",
        },
        "noise_floor": sigma,
        "own_input_expected_margin": own["expected_margin"],
        "best": {k: v for k, v in best.items() if k != "u"},
        "designs": [{k: v for k, v in r.items() if k != "u"} for r in others],
        "t": t,
        "u": best["u"],
        "input_column": synth.INPUT_COLUMNS[ds.setup],
        "method": "expected held-out BIC margin n_held ln(1 + MSE_wrong / sigma^2) - dk ln n_held, "
        "MSE_wrong the held-out MSE of the wrong effect fitted to the right one's noise-free "
        "replay on the design, the smaller of both directions",
    }
