"""Does a named effect hold, or does it only help? The checks that separate a real effect from a
stand-in (issue 28).

A library effect that lowers the held-out cost and the BIC may still be a *stand-in*: a cause
outside the library (a ripple, a drift, a resonance) leaves a residual that some mix of library
effects shrinks without being what it is. An effect earns its name only when, besides the
selection's rules (:mod:`.selection`):

* **its parameters agree across independent parts of the record.** The record's usable samples
  are cut into :data:`N_SEGMENTS` contiguous segments (different excitation: a sweep's
  frequencies, a random input's stretches). In each, the effect's contribution ``c`` (the final
  model's output minus that of the final model without the effect, the others refit) is scaled
  by least squares onto what the model without it leaves, ``r``: ``beta = <c, r> / <c, c>``.
  Every parameter that enters linearly scales ``c`` (a friction torque, a damping coefficient,
  an offset, element stiffnesses), and a delay or a play scales it to first order, so ``beta``
  is the segment's own parameter over the whole record's. Real: ``beta`` = 1 in every segment
  where the effect acts (its contribution at least :data:`ACTIVE` x the noise floor RMS),
  within ``max(`` :data:`Z_AGREE` x its standard error, :data:`REL_TOL` ``)``; the standard error
  from the segment's residual inflated by its autocorrelation time. And jointly: the segments'
  ``beta`` must not disagree among themselves both significantly (chi-square about their
  weighted mean beyond the :data:`JOINT_P` quantile) and by more than :data:`SPREAD_TOL` (a law
  that is a model, not the truth, lets a real effect's size scatter by ~0.2 between parts; a
  stand-in for a cause that changes over the record drifts by more).
* **the residual it removes has the shape its physics predicts, everywhere.** In each segment
  where it acts the effect must lower the residual's mean square (by at least
  :data:`MIN_SEGMENT_GAIN` x the noise variance): a stand-in that helps on average and hurts in
  parts does not.
* **its parameters sit inside their physical ranges and off the fit's bounds** (the registry's
  ranges, :mod:`fsarm_sim.plant.effects.registry`; within :data:`BOUND_FRACTION` of a bound's
  span counts as at it). A parameter *at* a bound (not beyond it, not at zero) only counts while
  the model leaves something unexplained - a true parameter may lie at its range's end, and with
  nothing left over there is nothing for the effect to stand in for (:func:`bound_waived`).

The checks read arrays only; the setup supplies the fits (:mod:`.bench_setup`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy import stats

from fsarm_sim.discrepancy.residuals import tau_int
from fsarm_sim.plant.effects import registry

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

N_SEGMENTS = 4
ACTIVE = 0.5  # contribution RMS / noise floor from which the effect acts in a segment
Z_AGREE = 4.0  # standard errors within which a segment's scale must agree with 1
REL_TOL = 0.35  # ... or this relative tolerance (the effect's law is a model, not the truth)
JOINT_P = 1e-4  # chance of the segments' sizes disagreeing this much by noise alone
SPREAD_TOL = 0.3  # ... and by more than this (largest minus smallest beta)
MIN_SEGMENT_GAIN = 0.0  # noise variances the effect must remove in every segment where it acts
BOUND_FRACTION = 1e-6  # of the range: a fit pinned at a bound sits on it (clipped)
ZERO_FRACTION = 1e-9  # a magnitude with a zero lower bound this close to it is at zero


@dataclass
class EffectCheck:
    """The realness checks of one named effect."""

    effect: str
    variant: str
    passed: bool
    reasons: list[str] = field(default_factory=list)
    segments: list[dict[str, float]] = field(default_factory=list)
    at_bound: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return {
            "effect": self.effect,
            "variant": self.variant,
            "passed": self.passed,
            "reasons": list(self.reasons),
            "segments": [dict(s) for s in self.segments],
            "at_bound": list(self.at_bound),
        }


def segments(use: BoolArray, n: int = N_SEGMENTS) -> list[npt.NDArray[np.int64]]:
    """Indices of ``n`` contiguous segments of the samples in ``use``."""
    idx = np.flatnonzero(use)
    return [np.asarray(s, dtype=np.int64) for s in np.array_split(idx, n) if s.size > 10]


def segment_agreement(
    y: FloatArray,
    y_full: FloatArray,
    y_without: FloatArray,
    t: FloatArray,
    use: BoolArray,
    sigma: float,
) -> tuple[list[dict[str, float]], list[str]]:
    """Per segment: the effect's scale ``beta`` with its standard error and the noise variances
    it removes; and the reasons it fails (empty: it holds)."""
    c_all = y_full - y_without
    r_all = y - y_without
    out: list[dict[str, float]] = []
    reasons: list[str] = []
    s2n = max(sigma * sigma, 1e-300)
    for seg in segments(use):
        c, r = c_all[seg], r_all[seg]
        cc = float(np.dot(c, c))
        rms_c = math.sqrt(cc / c.size)
        active = rms_c >= ACTIVE * sigma
        if cc <= 0.0:
            out.append({"t_start_s": float(t[seg[0]]), "t_end_s": float(t[seg[-1]]), "active": 0.0})
            continue
        beta = float(np.dot(c, r) / cc)
        e = r - beta * c
        se = math.sqrt(float(np.mean(e * e)) * tau_int(e) / cc)
        gain = (float(np.mean(r * r)) - float(np.mean((r - c) ** 2))) / s2n
        row = {
            "t_start_s": float(t[seg[0]]),
            "t_end_s": float(t[seg[-1]]),
            "active": float(active),
            "contribution_over_noise": rms_c / sigma if sigma > 0 else math.inf,
            "scale": beta,
            "scale_se": se,
            "gain_over_noise_var": gain,
        }
        out.append(row)
        if not active:
            continue
        where = f"{row['t_start_s']:.3g}-{row['t_end_s']:.3g} s"
        if abs(beta - 1.0) > max(Z_AGREE * se, REL_TOL):
            reasons.append(
                f"its size in {where} is {beta:.2f} +/- {se:.2f} x the whole record's "
                f"(allowed 1 +/- max({Z_AGREE:g} se, {REL_TOL:g}))"
            )
        if gain < MIN_SEGMENT_GAIN:
            reasons.append(
                f"it makes the residual worse in {where} (by {-gain:.2g} noise variances)"
            )
    act = [s for s in out if s.get("active") and s.get("scale_se", 0.0) > 0.0]
    if len(act) < 2 and not reasons:
        return out, []  # acts in one part only: no second part to agree with (not judged)
    if len(act) >= 3:
        w = np.array([1.0 / s["scale_se"] ** 2 for s in act])
        b = np.array([s["scale"] for s in act])
        chi2 = float(np.sum(w * (b - float(np.sum(w * b) / np.sum(w))) ** 2))
        p = float(stats.chi2.sf(chi2, b.size - 1))
        spread = float(np.ptp(b))
        if p < JOINT_P and spread > SPREAD_TOL:
            sizes = ", ".join(f"{x:.2f}" for x in b)
            reasons.append(
                f"its size differs between the record's parts ({sizes} x the whole record's: "
                f"chi-square {chi2:.3g} on {b.size - 1} dof, p = {p:.1e}; spread {spread:.2f} "
                f"> {SPREAD_TOL:g})"
            )
    return out, reasons


def params_at_bounds(effect: str, variant: str, params: dict[str, Any]) -> list[str]:
    """The parameters of an effect that lie outside or at their registry range's bounds (a
    magnitude at a zero lower bound counts: the effect is absent)."""
    try:
        var = registry.get(effect).variant(variant)
    except Exception:  # an effect the registry does not list (not a bench effect): no ranges
        return []
    out: list[str] = []
    for p in var.params:
        if p.name not in params:
            continue
        vals = params[p.name]
        seq = vals if isinstance(vals, list | tuple) else [vals]
        span = p.upper - p.lower
        zeros = 0
        for i, v in enumerate(seq):
            if not isinstance(v, int | float) or not math.isfinite(float(v)):
                out.append(f"{p.name} is not a finite number")
                continue
            v = float(v)
            tag = f"{p.name}[{i}]" if len(seq) > 1 else p.name
            if v < p.lower - BOUND_FRACTION * span or v > p.upper + BOUND_FRACTION * span:
                out.append(f"{tag} = {v:.4g} outside [{p.lower:g}, {p.upper:g}] {p.unit}")
            elif p.lower == 0.0 and abs(v) <= ZERO_FRACTION * span:
                zeros += 1  # a magnitude at zero: absent (an element among others may be)
            elif abs(v - p.upper) <= BOUND_FRACTION * span or (
                p.lower != 0.0 and abs(v - p.lower) <= BOUND_FRACTION * span
            ):
                out.append(f"{tag} = {v:.4g} at a bound of [{p.lower:g}, {p.upper:g}] {p.unit}")
        if seq and zeros == len(seq):
            out.append(f"{p.name} = 0 {p.unit}: at zero, the effect is absent")
    return out


def check(
    effect: str,
    variant: str,
    params: dict[str, Any],
    y: FloatArray,
    y_full: FloatArray,
    y_without: FloatArray,
    t: FloatArray,
    use: BoolArray,
    sigma: float,
) -> EffectCheck:
    """All checks of one named effect (module docstring)."""
    segs, reasons = segment_agreement(y, y_full, y_without, t, use, sigma)
    bounds = params_at_bounds(effect, variant, params)
    reasons = reasons + [f"parameter {b}" for b in bounds]
    return EffectCheck(effect, variant, not reasons, reasons, segs, bounds)


def bound_waived(c: EffectCheck) -> EffectCheck:
    """``c`` without its at-a-bound reasons (the caller's model leaves nothing unexplained)."""
    keep = [r for r in c.reasons if " at a bound of " not in r]
    if keep == c.reasons:
        return c
    return EffectCheck(c.effect, c.variant, not keep, keep, c.segments, c.at_bound)
