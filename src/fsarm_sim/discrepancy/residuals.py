"""Residuals of a replay: noise floor from the data, NRMSE, effective sample size, and the
signatures that point at a missing effect.

* Noise floor: robust scale of the 4th-order differences of the measured channel (a
  difference-based variance estimator in the manner of Rice 1984 / Gasser et al. 1986: smooth
  signal content cancels, white noise stays with variance 70 sigma^2; the median absolute
  deviation ignores kinks and impacts). It needs no model, so it is the same before and after.
  The 4th differences pass high frequencies most: a narrow line there (pickup, a vibration
  aliased by the sampling) would count as noise, so with ``lines=True`` lines are cut from the
  differences' spectrum first (bins over :data:`LINE_CUT` x their running median, which white or
  coloured noise exceeds with chance ~1e-9 per bin).
* NRMSE: RMSE over (max - min) of the measured channel on the same samples (seed 001 Sec. 3.3).
  The noise floor in the same units is ``sigma / (max - min)``: a perfect model's NRMSE. The gap
  *above* the noise floor is ``sqrt(max(gap^2 - floor^2, 0))`` (independent noise adds in
  variance), so a gap at the floor is 0 however noisy the record.
* Effective sample size: n / tau_int with tau_int the integrated autocorrelation time of the
  residual (Sokal's automatic window), so that coloured residuals do not fake evidence in BIC.
* Signatures: how much of the residual variance is explained by grouping it by velocity sign,
  velocity, deflection, bend angle, direction of traversal (deflection x velocity sign), the
  lag between measured and replayed output, and where in frequency / time the residual sits
  above the noise floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.ndimage import median_filter
from scipy.signal import welch

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

N_BLOCKS = 12  # teaching / verifying split: contiguous blocks, every third one held out
HELD_OUT_PHASE = 1
WARMUP_FRACTION = 0.01  # first samples belong to neither set (unknown initial internal states)


LINE_CUT = 30.0  # a periodogram bin over this x its running median is a line (not noise)
LINE_MEDIAN_BINS = 101
LINE_GUARD_BINS = 2  # bins either side of a line's cut with it (its leakage)


def cut_lines(d: FloatArray) -> FloatArray:
    """``d`` with the narrow spectral lines of its periodogram set to zero."""
    if d.size < 4 * LINE_MEDIAN_BINS:
        return d
    f = np.fft.rfft(d)
    p = np.abs(f) ** 2
    base = median_filter(p, size=LINE_MEDIAN_BINS, mode="nearest")
    line = p > LINE_CUT * np.maximum(base, 1e-300)
    if not np.any(line[1:]):
        return d
    for k in range(1, LINE_GUARD_BINS + 1):
        line[k:] |= line[:-k].copy()
        line[:-k] |= line[k:].copy()
    line[0] = False
    f[line] = 0.0
    return np.asarray(np.fft.irfft(f, d.size), dtype=np.float64)


def noise_floor(y: FloatArray, lines: bool = False) -> float:
    """Standard deviation of the measurement noise of ``y`` (white part), from the data alone;
    ``lines``: narrow spectral lines are not noise (module docstring)."""
    if y.size < 10:
        return 0.0
    d4 = y[:-4] - 4 * y[1:-3] + 6 * y[2:-2] - 4 * y[3:-1] + y[4:]
    if lines:
        d4 = cut_lines(d4)
    mad = float(np.median(np.abs(d4 - np.median(d4))))
    sigma = 1.4826 * mad / math.sqrt(70.0)
    if sigma == 0.0:  # quantised, nearly constant channel: fall back to the RMS of d4
        sigma = float(np.sqrt(np.mean(d4 * d4) / 70.0))
    return sigma


def split_masks(n: int, n_blocks: int = N_BLOCKS) -> tuple[BoolArray, BoolArray]:
    """(teaching, held-out) masks: contiguous blocks, every third held out (seed 003's
    teaching/verifying sets), the first WARMUP_FRACTION of samples in neither."""
    edges = np.linspace(0, n, n_blocks + 1).astype(int)
    held = np.zeros(n, dtype=bool)
    for b in range(n_blocks):
        if b % 3 == HELD_OUT_PHASE:
            held[edges[b] : edges[b + 1]] = True
    valid = np.ones(n, dtype=bool)
    valid[: math.ceil(WARMUP_FRACTION * n)] = False
    return valid & ~held, valid & held


def nrmse(y: FloatArray, yhat: FloatArray, mask: BoolArray) -> float:
    """RMSE / (max - min) of the measured channel over ``mask``."""
    ym = y[mask]
    if not np.all(np.isfinite(yhat[mask])):
        return math.inf
    span = float(ym.max() - ym.min()) if ym.size else 0.0
    if span <= 0.0:
        span = 1.0
    return float(np.sqrt(np.mean((ym - yhat[mask]) ** 2)) / span)


def nrmse_floor(y: FloatArray, sigma: float, mask: BoolArray) -> float:
    """The noise floor in NRMSE units: ``sigma / (max - min)`` of ``y`` over ``mask`` - the
    held-out NRMSE of a model that reproduces everything but the white measurement noise."""
    ym = y[mask]
    span = float(ym.max() - ym.min()) if ym.size else 0.0
    return sigma / span if span > 0.0 else sigma


def gap_excess(gap: float, floor: float) -> float:
    """The part of an NRMSE gap above the noise floor: ``sqrt(max(gap^2 - floor^2, 0))``."""
    if not (math.isfinite(gap) and math.isfinite(floor)):
        return gap
    return math.sqrt(max(gap * gap - floor * floor, 0.0))


def tau_int(r: FloatArray, max_lag: int = 2000) -> float:
    """Integrated autocorrelation time of ``r`` (>= 1), Sokal's window c = 5."""
    x = r - r.mean()
    n = x.size
    if n < 20 or float(np.dot(x, x)) == 0.0:
        return 1.0
    m = 1 << math.ceil(math.log2(2 * n))
    f = np.fft.rfft(x, m)
    acf = np.fft.irfft(f * np.conj(f), m)[: min(n, max_lag + 1)]
    acf = acf / acf[0]
    # t after each lag, summed in order (the running sum of 1 + 2 acf[1] + 2 acf[2] ...); the
    # window ends at the first lag k >= 5 t
    run = np.cumsum(np.concatenate(([1.0], 2.0 * acf[1:])))
    lags = np.arange(acf.size)
    stop = np.flatnonzero(lags[1:] >= 5.0 * run[1:])
    t = float(run[stop[0] + 1] if stop.size else run[-1])
    return float(min(max(t, 1.0), n / 20.0))


def effective_n(r: FloatArray, mask: BoolArray) -> float:
    """Samples in ``mask`` divided by the residual's autocorrelation time (over whole blocks)."""
    return float(mask.sum()) / tau_int(r[mask])


def bic(mse: float, n_eff: float, k: int) -> float:
    """BIC in the form of seed 003 Table 4: n ln(MSE) + k ln(n), with the effective n."""
    return n_eff * math.log(max(mse, 1e-300)) + k * math.log(max(n_eff, 2.0))


def _explained(r: FloatArray, groups: npt.NDArray[np.int64]) -> float:
    """Fraction of the variance of r explained by its group means."""
    var = float(np.var(r))
    if var <= 0.0 or r.size == 0:
        return 0.0
    g = groups - groups.min()
    cnt = np.bincount(g)
    sums = np.bincount(g, weights=r)
    means = np.divide(sums, cnt, out=np.zeros_like(sums), where=cnt > 0)
    return float(np.var(means[g]) / var)


def _bins(x: FloatArray, n_bins: int = 20) -> npt.NDArray[np.int64]:
    qs = np.quantile(x, np.linspace(0, 1, n_bins + 1)[1:-1])
    return np.searchsorted(qs, x).astype(np.int64)


def lag_of_best_match(y: FloatArray, yhat: FloatArray, h: float, max_lag_s: float = 0.1) -> float:
    """Time shift (s) of the replayed output that best matches the measured one (> 0: the
    measured output lags the replay), from the cross-correlation peak with parabolic refinement."""
    a = y - y.mean()
    b = yhat - yhat.mean()
    n = a.size
    m = 1 << math.ceil(math.log2(2 * n))
    cc = np.fft.irfft(np.fft.rfft(a, m) * np.conj(np.fft.rfft(b, m)), m)
    max_lag = max(1, min(int(max_lag_s / h), n // 4))
    lags = np.r_[np.arange(0, max_lag + 1), np.arange(-max_lag, 0)]
    vals = np.r_[cc[: max_lag + 1], cc[-max_lag:]]
    i = int(np.argmax(vals))
    k = int(lags[i])
    if -max_lag < k < max_lag:
        c0, cm, cp = cc[k % m], cc[(k - 1) % m], cc[(k + 1) % m]
        den = cm - 2 * c0 + cp
        off = 0.5 * (cm - cp) / den if den != 0 else 0.0
        return float((k + off) * h)
    return float(k * h)


def above_noise_intervals(
    r: FloatArray, t: FloatArray, sigma: float, window_s: float = 0.25, top: int = 5
) -> tuple[float, list[dict[str, float]]]:
    """Fraction of time the rolling residual RMS exceeds twice the noise floor, and the worst
    windows (start, end, rms / sigma)."""
    h = float(t[1] - t[0])
    w = max(1, int(window_s / h))
    if r.size < w or sigma <= 0:
        return 0.0, []
    c = np.cumsum(np.r_[0.0, r * r])
    rms = np.sqrt((c[w:] - c[:-w]) / w)
    frac = float(np.mean(rms > 2.0 * sigma))
    starts = np.arange(0, rms.size, w)
    vals = rms[starts]
    order = np.argsort(vals)[::-1][:top]
    out = [
        {
            "t_start_s": float(t[starts[i]]),
            "t_end_s": float(t[min(starts[i] + w, t.size - 1)]),
            "rms_over_noise": float(vals[i] / sigma),
        }
        for i in order
    ]
    return frac, out


def band_power(r: FloatArray, h: float, sigma: float) -> dict[str, Any]:
    """Residual power per frequency band, relative to the white noise floor in that band."""
    fs = 1.0 / h
    nper = min(r.size, int(4 * fs))
    f, p = welch(r, fs=fs, nperseg=max(16, nper))
    bands = [(0.0, 1.0), (1.0, 5.0), (5.0, 20.0), (20.0, fs / 2)]
    noise_psd = 2.0 * sigma * sigma / fs  # one-sided PSD of white noise of std sigma
    out: dict[str, Any] = {}
    for lo, hi in bands:
        sel = (f >= lo) & (f < hi)
        if sel.any() and noise_psd > 0:
            out[f"{lo:g}-{hi:g}Hz"] = float(np.mean(p[sel]) / noise_psd)
    out["dominant_hz"] = float(f[int(np.argmax(p[1:])) + 1]) if f.size > 1 else 0.0
    return out


@dataclass
class Signature:
    """What the residual looks like (fractions of its variance explained, 0..1)."""

    rms: float
    rms_over_noise: float
    velocity_sign: float
    velocity: float
    deflection: float
    bend: float
    direction_of_traversal: float
    lag_s: float
    time_above_noise: float
    worst_windows: list[dict[str, float]]
    bands_over_noise: dict[str, Any]

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def signature(
    y: FloatArray,
    yhat: FloatArray,
    x: FloatArray,
    xdot: FloatArray,
    phi: FloatArray,
    t: FloatArray,
    sigma: float,
) -> Signature:
    """Residual signatures of one replay against the measured main channel."""
    r = y - yhat
    h = float(t[1] - t[0])
    vthr = 0.05 * float(np.std(xdot)) if np.std(xdot) > 0 else 0.0
    moving = np.abs(xdot) > vthr
    sgn = (xdot > 0).astype(np.int64)
    rm = r[moving]
    vel_sign = _explained(rm, sgn[moving]) if rm.size > 10 else 0.0
    cv = np.corrcoef(rm, xdot[moving])[0, 1] if rm.size > 10 and np.std(rm) > 0 else 0.0
    xb = _bins(x)
    defl = _explained(r, xb)
    both = _explained(rm, xb[moving] * 2 + sgn[moving]) if rm.size > 10 else 0.0
    bend = _explained(r, _bins(phi, 10)) if np.ptp(phi) > 1e-3 else 0.0
    frac, worst = above_noise_intervals(r, t, sigma)
    rms = float(np.sqrt(np.mean(r * r)))
    return Signature(
        rms=rms,
        rms_over_noise=rms / sigma if sigma > 0 else math.inf,
        velocity_sign=vel_sign,
        velocity=float(cv * cv) if np.isfinite(cv) else 0.0,
        deflection=defl,
        bend=bend,
        direction_of_traversal=max(0.0, both - _explained(rm, xb[moving])) if rm.size > 10 else 0.0,
        lag_s=lag_of_best_match(y, yhat, h),
        time_above_noise=frac,
        worst_windows=worst,
        bands_over_noise=band_power(r, h, sigma),
    )
