"""A general search of what a residual holds, each finding with its significance (issue 28).

Not a list of known causes: every search below looks for a *kind* of structure and says what it
found with numbers, and each is judged against what noise of the record's own colour would give
(the chance structure of coloured noise is the false alarm to beat). The searches:

* **spectral lines and resonances** - the residual's Welch spectrum (segments of
  :data:`WELCH_S` s, Hann, half overlap) against its own running median in log frequency
  (:data:`BASE_OCTAVES` octaves wide): a peak whose power over that baseline exceeds the
  chi-square quantile of the averaged segments at the false-alarm rate :data:`ALPHA` (Bonferroni
  over the bins) is a finding; its -3 dB width tells a line (a few bins) from a resonance
  (wider: ``Q`` = f / width). Peaks at the input's own frequencies (the band holding 99 % of the
  input's rate power, :func:`.unexplained.input_band`) are the misfit of a law driven by the input
  and are not lines.
* **periodicity in an angle** - the residual binned by each recorded or derived angle (theta_m,
  theta_s, twist, bend) on a uniform grid, the bin means' FFT (order analysis): a peak of at least
  :data:`MIN_CYCLES` periods over the angle's range whose sine fit explains significantly more
  than the bins' own noise (F test at :data:`ALPHA`, the bins' noise from their counts and the
  residual's autocorrelation time) names the angle and the period.
* **dependence on a signal** (torque level, speed, direction, acceleration, the angles) - the
  share of the residual variance its quantile-bin means explain, against circular-shift
  surrogates (the signal shifted in time: both series keep their colour, their relation is
  broken; :func:`signal_dependence`).
* **trends in time** - an offset and a gain (stiffness) drifting (:func:`.unexplained.trends`):
  ``|t|`` above the normal quantile at :data:`ALPHA`, standard errors inflated by the
  autocorrelation time of what the regression leaves.
* **slow variation in time** - the offset wandering (a zero following the room's temperature):
  Legendre polynomials in time up to about :data:`SLOW_HZ` (beside the model's output and the
  twist rate, so an input-driven misfit is not counted), their explained variance against what
  the same number of basis functions takes from noise of the record's own colour - the
  residual's Welch spectrum over :data:`SLOW_REF_HZ`, extrapolated down on its log-log slope
  (flat or rising: 1/f noise is not a drift), times :data:`SLOW_MARGIN`; chi-square at the
  search's share of :data:`ALPHA` (:func:`slow_offset`).
* **localisation in time** - windows of :data:`.unexplained.WINDOW_S` s whose energy stands out
  of the windows' robust spread by more than :data:`LOCAL_Z` (sparse events, stretches) and
  more than in any of :data:`LOCAL_SURROGATES` phase-randomised copies of the residual.
* **saturation** - the residual against the model's output beyond a level ``c``: a hinge
  ``sign(yhat) max(|yhat| - c, 0)`` with a negative slope (the measured output stops growing
  where the model's goes on), F test at :data:`ALPHA`.

Each finding carries ``explained_var`` (the residual variance it accounts for, output units
squared) and ``significant``; :func:`structured` says whether any significant finding explains
at least :data:`MIN_STRUCT` noise variances - with the residual above the noise floor, that is
the ``unexplained`` verdict. :data:`ALPHA` is the false-alarm rate the whole aims at, per record
(the searches share it, :data:`N_SEARCHES`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy import stats
from scipy.ndimage import median_filter
from scipy.signal import welch

from fsarm_sim.discrepancy.residuals import tau_int

FloatArray = npt.NDArray[np.float64]

ALPHA = 0.02  # the false-alarm rate aimed at, per record
N_SEARCHES = 7  # spectral, angle, dependence, trend, slow offset, localisation, saturation
WELCH_S = 2.0
BASE_OCTAVES = 1.0
MIN_LINE_HZ = 1.0  # below: trends, not lines
ANGLE_BINS = 1024
MIN_CYCLES = 2.0
MAX_CYCLES_PER_BIN = 0.25  # a period spans at least 4 bins
LOCAL_Z = 12.0
LOCAL_SURROGATES = 19  # a localisation beyond all of them: p < 1/20 against the record's colour
SLOW_HZ = 0.1  # the slow basis reaches about this frequency (Legendre degree 2 T SLOW_HZ)
SLOW_DEG = (2, 8)
SLOW_REF_HZ = (0.5, 5.0)  # the band whose noise level is extrapolated to the slow basis
SLOW_MARGIN = 6.0  # the extrapolation scatters: 1/f noise on 10 s records reaches ~5 x (dev nulls)
MIN_STRUCT = 0.5  # noise variances a significant finding must explain for "unexplained"
MIN_SHARE_STRUCT = 0.05  # ... and this share of the residual variance (the signature's headline)
GENERIC_WEIGHT = 0.5
GENERIC = ("signal", "localized")
N_SURROGATES = 30
SAT_QUANTILES = tuple(float(1.0 - q) for q in np.geomspace(0.5, 0.002, 30))


def _alpha_each() -> float:
    return ALPHA / N_SEARCHES


def _n_eff(e: FloatArray) -> float:
    return max(float(e.size) / tau_int(e), 2.0)


@dataclass
class Signals:
    """A channel's residual and what it may depend on (prepared by the setup)."""

    channel: str
    unit: str
    t: FloatArray
    residual: FloatArray
    output: FloatArray  # the final model's replay of the channel (for a gain drift)
    sigma: float  # the channel's noise floor
    inputs: list[FloatArray]  # the recorded inputs (their spectra flag lines as the input's)
    signals: dict[str, FloatArray] = field(default_factory=dict)  # name -> signal
    # recorded or derived angles (theta_m, theta_s, twist, bend) searched for periodicity;
    # name -> (angle, the other names of the same signal)
    angles: dict[str, tuple[FloatArray, list[str]]] = field(default_factory=dict)


# ---------------------------------------------------------------------------- spectrum


def spectral_peaks(s: Signals, input_top_hz: float) -> list[dict[str, Any]]:
    """Lines and resonances of the residual's Welch spectrum above its local baseline."""
    r = s.residual - float(np.mean(s.residual))
    h = float(s.t[1] - s.t[0])
    fs = 1.0 / h
    nper = min(r.size, int(WELCH_S * fs))
    if nper < 64:
        return []
    f, p = welch(r, fs=fs, nperseg=nper, noverlap=nper // 2, window="hann")
    n_seg = max(1, (r.size - nper) // (nper // 2) + 1)
    df = float(f[1] - f[0])
    # baseline: running median over BASE_OCTAVES in log frequency (resampled)
    sel = f >= max(MIN_LINE_HZ, input_top_hz * 1.05, 2 * df)
    if sel.sum() < 20:
        return []
    lf = np.log(f[sel])
    lp = np.log(np.maximum(p[sel], 1e-300))
    grid = np.linspace(lf[0], lf[-1], 2048)
    gp = np.interp(grid, lf, lp)
    w = max(3, int(BASE_OCTAVES * math.log(2) / (grid[1] - grid[0])) | 1)
    base = np.exp(np.interp(lf, grid, median_filter(gp, size=w, mode="nearest")))
    # the median of a chi2(2k)/2k variable is below its mean: scale the baseline to a mean
    dof = 2.0 * n_seg * 0.9  # Hann half-overlap: ~0.9 of the independent dof
    base = base / (stats.chi2.median(dof) / dof)
    ratio = p[sel] / base
    thr = stats.chi2.isf(_alpha_each() / sel.sum(), dof) / dof
    fsel = f[sel]
    psel = p[sel]
    out: list[dict[str, Any]] = []
    used = np.zeros(fsel.size, dtype=bool)
    for i in np.argsort(ratio)[::-1]:
        if ratio[i] <= thr or len(out) >= 4:
            break
        if used[max(0, i - 2) : i + 3].any():
            continue
        # -3 dB extent around the peak
        lo = i
        while lo > 0 and psel[lo - 1] > 0.5 * psel[i]:
            lo -= 1
        hi = i
        while hi + 1 < psel.size and psel[hi + 1] > 0.5 * psel[i]:
            hi += 1
        wide = hi - lo + 1  # the peak's skirts: no second peak inside them
        used[max(0, lo - wide - 2) : hi + wide + 3] = True
        width = float((hi - lo + 1) * df)
        band = slice(max(0, lo - 1), hi + 2)
        excess = float(np.sum(np.maximum(psel[band] - base[band], 0.0)) * df)
        fr = float(np.sum(fsel[band] * psel[band]) / np.sum(psel[band]))
        kind = "resonance" if hi - lo + 1 >= 4 else "spectral_line"
        amp = math.sqrt(2.0 * excess)
        out.append(
            {
                "kind": kind,
                "frequency_hz": fr,
                "width_hz": width,
                "q": fr / width if width > 0 else math.inf,
                "amplitude": amp,
                "power_over_baseline": float(ratio[i]),
                "threshold": float(thr),
                "explained_var": excess,
                "significant": True,
                "text": (
                    f"a {fr:.4g} Hz resonance (width {width:.2g} Hz, Q {fr / width:.3g}) of "
                    f"{amp:.3g} {s.unit} (amplitude) on {s.channel}"
                    if kind == "resonance"
                    else f"a {fr:.4g} Hz line of {amp:.3g} {s.unit} (amplitude) on {s.channel}"
                ),
            }
        )
    return out


# ---------------------------------------------------------------------------- angles


def angle_periodicity(s: Signals) -> list[dict[str, Any]]:
    """Per angle: the strongest periodic component of the residual in that angle (order
    analysis on bin means), with its F test."""
    out: list[dict[str, Any]] = []
    r = s.residual - float(np.mean(s.residual))
    tau = tau_int(r)
    var_r = float(np.var(r)) or 1.0
    for name, (a, aliases) in s.angles.items():
        if a.size != r.size or not np.all(np.isfinite(a)):
            continue
        span = float(np.ptp(a))
        if span <= 0:
            continue
        nb = int(min(ANGLE_BINS, max(64, r.size // 20)))
        g = np.minimum(((a - a.min()) / span * nb).astype(np.int64), nb - 1)
        cnt = np.bincount(g, minlength=nb).astype(np.float64)
        sums = np.bincount(g, weights=r, minlength=nb)
        ok = cnt > 0
        if ok.sum() < 32:
            continue
        means = np.zeros(nb)
        means[ok] = sums[ok] / cnt[ok]
        centres = (np.arange(nb) + 0.5) / nb * span + a.min()
        means_i = np.interp(centres, centres[ok], means[ok])
        # remove the smooth part (what a dependence on the angle explains): the search is for
        # periodic structure of at least MIN_CYCLES periods
        m = np.fft.rfft(means_i - means_i.mean())
        cycles = np.arange(m.size, dtype=np.float64)  # periods over the span
        band = (cycles >= max(MIN_CYCLES, 2.0)) & (cycles <= MAX_CYCLES_PER_BIN * nb)
        if not band.any():
            continue
        pw = np.abs(m) ** 2
        k = int(np.flatnonzero(band)[int(np.argmax(pw[band]))])
        # refine with a sine fit on the samples themselves, at periods around the peak
        best: tuple[float, float, float] = (0.0, 0.0, 0.0)  # (ss explained, period, amp)
        for kk in np.linspace(k - 0.5, k + 0.5, 11):
            if kk <= 0:
                continue
            per = span / kk
            ph = 2 * np.pi * a / per
            x = np.column_stack([np.sin(ph), np.cos(ph)])
            c, *_ = np.linalg.lstsq(x, r, rcond=None)
            fit = x @ c
            ss = float(np.dot(fit, fit))
            if ss > best[0]:
                best = (ss, per, float(math.hypot(c[0], c[1])))
        ss, per, amp = best
        e = r - _sine(a, per, r)
        n_eff = _n_eff(e)
        rss = float(np.dot(e, e))
        f_stat = (ss / 2.0) / (rss / max(n_eff - 2.0, 1.0))
        # periods searched: Bonferroni over the band's frequencies
        n_tests = int(band.sum()) * max(1, len(s.angles))
        p_val = float(stats.f.sf(f_stat, 2, max(n_eff - 2.0, 1.0))) * n_tests
        expl = ss / r.size
        sig = p_val < _alpha_each()
        out.append(
            {
                "kind": "angle_periodic",
                "signal": name,
                "aliases": list(aliases),
                "period_rad": per,
                "cycles_per_rev": 2 * math.pi / per,
                "amplitude": amp,
                "share_of_residual": expl / var_r,
                "explained_var": expl,
                "p_value": min(p_val, 1.0),
                "n_eff": n_eff,
                "tau_int": tau,
                "significant": bool(sig),
                "text": (
                    f"periodic in {name} with a period of {per:.4g} rad "
                    f"({2 * math.pi / per:.3g} per rev), amplitude {amp:.3g} {s.unit}"
                ),
            }
        )
    out.sort(key=lambda d: -float(d["explained_var"]))
    return out


def _sine(a: FloatArray, per: float, r: FloatArray) -> FloatArray:
    ph = 2 * np.pi * a / per
    x = np.column_stack([np.sin(ph), np.cos(ph)])
    c, *_ = np.linalg.lstsq(x, r, rcond=None)
    return np.asarray(x @ c, dtype=np.float64)


# ---------------------------------------------------------------------------- signals


def _groups(x: FloatArray, n_bins: int = 48) -> npt.NDArray[np.int64] | None:
    """Quantile-bin index of every sample (one bin per value for a signal of few values)."""
    vals = np.unique(x)
    if vals.size <= n_bins:
        return np.asarray(np.searchsorted(vals, x), dtype=np.int64) if vals.size >= 2 else None
    edges = np.unique(np.quantile(x, np.linspace(0, 1, n_bins + 1)))
    if edges.size < 3:
        return None
    g = np.clip(np.searchsorted(edges[1:-1], x, side="right"), 0, edges.size - 2)
    return np.asarray(g, dtype=np.int64)


def _share(r: FloatArray, g: npt.NDArray[np.int64], nb: int) -> float:
    cnt = np.bincount(g, minlength=nb)
    sums = np.bincount(g, weights=r, minlength=nb)
    means = np.divide(sums, cnt, out=np.zeros(nb), where=cnt > 0)
    var = float(np.var(r))
    return float(np.var(means[g]) / var) if var > 0 else 0.0


def signal_dependence(s: Signals, dep: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The binned dependences of :func:`.unexplained.dependence`, each tested against
    circular-shift surrogates: the residual paired with the signal shifted in time by
    :data:`N_SURROGATES` lags from 10 to 90 % of the record keeps both series' own colour and
    breaks only their relation - the share the bins explain must stand out of the surrogates'
    shares by the normal quantile at the false-alarm rate (Bonferroni over the signals) and be
    at least twice their mean."""
    r = s.residual - float(np.mean(s.residual))
    var_r = float(np.var(r)) or 1.0
    out: list[dict[str, Any]] = []
    n = r.size
    lags = np.linspace(0.1 * n, 0.9 * n, N_SURROGATES).astype(int)
    z_thr = float(stats.norm.isf(_alpha_each() / max(1, len(s.signals))))
    for d in dep:
        x = s.signals.get(d["signal"])
        if x is None:
            continue
        g = _groups(x)
        if g is None:
            continue
        nb = int(g.max()) + 1
        share = _share(r, g, nb)
        sur = np.array([_share(r, np.roll(g, int(k)), nb) for k in lags])
        mu, sd = float(sur.mean()), float(sur.std(ddof=1)) or 1e-12
        z = (share - mu) / sd
        out.append(
            {
                "kind": "signal",
                "signal": d["signal"],
                "share_of_residual": share,
                "explained_var": max(share - mu, 0.0) * var_r,
                "z_over_surrogates": z,
                "surrogate_share_mean": mu,
                "significant": bool(z > z_thr and share > 2.0 * mu),
                "text": f"the residual of {s.channel} follows the {d['signal']} "
                f"({100 * share:.0f} % of its variance)",
                "bin_centres": d["bin_centres"],
                "bin_means": d["bin_means"],
            }
        )
    return out


# ---------------------------------------------------------------------------- time


def trend_findings(s: Signals, tr: dict[str, Any]) -> list[dict[str, Any]]:
    """Offset and gain drifts (:func:`.unexplained.trends`) as findings."""
    var_r = float(np.var(s.residual)) or 1.0
    z = float(stats.norm.isf(_alpha_each() / 4))
    out = []
    o, g = tr["offset"], tr["gain"]
    out.append(
        {
            "kind": "drift",
            "trend": "offset",
            "rate_per_s": o["rate_per_s"],
            "change_over_record": o["change_over_record"],
            "t_value": o["t_value"],
            "explained_var": o["share_of_residual"] * var_r,
            "significant": bool(abs(o["t_value"]) > z),
            "text": f"the offset of {s.channel} drifts by {o['change_over_record']:+.3g} "
            f"{s.unit} over the record ({o['rate_per_s']:+.3g} {s.unit}/s)",
        }
    )
    ch = 100 * g["relative_change_over_record"]
    out.append(
        {
            "kind": "drift",
            "trend": "gain",
            "relative_change_over_record": g["relative_change_over_record"],
            "relative_rate_per_s": g["relative_rate_per_s"],
            "t_value": g["t_value"],
            "explained_var": g["share_of_residual"] * var_r,
            "significant": bool(abs(g["t_value"]) > z),
            "text": f"the gain of {s.channel} (the stiffness or the sensor's gain) "
            f"{'rises' if ch > 0 else 'falls'} by ~{abs(ch):.3g} % over the record "
            f"({100 * g['relative_rate_per_s']:+.3g} %/s)",
        }
    )
    return out


def slow_offset(s: Signals) -> dict[str, Any]:
    """The offset wandering slowly (module docstring), as a finding."""
    r, t = s.residual, s.t
    dur = float(t[-1] - t[0])
    out: dict[str, Any] = {"kind": "drift", "trend": "offset", "significant": False}
    fs = 1.0 / float(np.median(np.diff(t))) if t.size > 1 else 0.0
    if r.size < 200 or dur <= 0 or fs <= 2 * SLOW_REF_HZ[1]:
        return {**out, "explained_var": 0.0, "text": ""}
    deg = int(np.clip(round(2 * dur * SLOW_HZ), *SLOW_DEG))
    tau = 2.0 * (t - t[0]) / dur - 1.0
    leg = np.polynomial.legendre.legvander(tau, deg)
    nuis = [np.ones_like(r), s.output - float(np.mean(s.output))]
    if "twist rate" in s.signals and s.signals["twist rate"].shape == r.shape:
        nuis.append(s.signals["twist rate"])
    a0 = np.column_stack(nuis)
    a1 = np.column_stack([a0, leg[:, 1:]])
    e0 = r - a0 @ np.linalg.lstsq(a0, r, rcond=None)[0]
    e1 = r - a1 @ np.linalg.lstsq(a1, r, rcond=None)[0]
    explained = (float(e0 @ e0) - float(e1 @ e1)) / r.size
    f, p = welch(e1, fs=fs, nperseg=min(r.size, int(4.0 * fs)))
    band = (f >= SLOW_REF_HZ[0]) & (f <= SLOW_REF_HZ[1]) & (p > 0)
    if band.sum() < 4:
        return {**out, "explained_var": 0.0, "text": ""}
    slope, icpt = np.polyfit(np.log(f[band]), np.log(p[band]), 1)
    slope = min(float(slope), 0.0)
    fk = np.arange(1, deg + 1) / (2.0 * dur)
    expected = float(np.sum(np.exp(icpt + slope * np.log(fk)))) / (2.0 * dur)
    ratio = explained / expected if expected > 0 else math.inf
    thr = SLOW_MARGIN * float(stats.chi2.isf(_alpha_each(), deg)) / deg
    slow = e0 - e1
    swing = float(np.ptp(slow))
    return {
        **out,
        "shape": "slow",
        "degree": deg,
        "swing": swing,
        "over_coloured_noise": ratio,
        "threshold": thr,
        "explained_var": max(explained, 0.0),
        "significant": bool(ratio > thr),
        "text": f"the offset of {s.channel} wanders slowly over the record (swing "
        f"{swing:.3g} {s.unit}, {explained / max(s.sigma**2, 1e-300):.3g} noise variances)",
    }


def _window_z(r: FloatArray, w: int) -> tuple[FloatArray, FloatArray]:
    """Each window's mean square and its robust z against the windows' median and MAD."""
    nw = r.size // w
    e = np.mean((r[: nw * w] ** 2).reshape(nw, w), axis=1)
    med = float(np.median(e))
    mad = 1.4826 * float(np.median(np.abs(e - med))) or med or 1e-300
    return e, (e - med) / mad


def _surrogate_max_z(r: FloatArray, w: int, n: int = LOCAL_SURROGATES) -> float:
    """The largest window z of ``n`` phase-randomised copies of ``r`` (its spectrum, its colour
    kept; any localisation in time spread out), seeded by the record's length (reproducible)."""
    spec = np.fft.rfft(r)
    rng = np.random.default_rng(r.size)
    top = 0.0
    for _ in range(n):
        ph = np.exp(2j * np.pi * rng.random(spec.size))
        ph[0] = 1.0
        sur = np.fft.irfft(spec * ph, r.size)
        top = max(top, float(_window_z(sur, w)[1].max()))
    return top


def localisation(s: Signals, window_s: float) -> dict[str, Any]:
    """Windows whose energy stands out of the windows' robust spread (events, stretches) by
    more than :data:`LOCAL_Z` *and* by more than any of :data:`LOCAL_SURROGATES`
    phase-randomised copies of the residual (noise of the record's own colour: the window
    energies of slowly correlated noise scatter far more than white noise's)."""
    r = s.residual
    h = float(s.t[1] - s.t[0])
    w = max(1, int(window_s / h))
    nw = r.size // w
    if nw < 8:
        return {"kind": "localized", "significant": False, "explained_var": 0.0, "text": ""}
    e, z = _window_z(r, w)
    med = float(np.median(e))
    hot = z > LOCAL_Z
    excess = float(np.sum(e[hot] - med) * w / r.size)
    starts = np.flatnonzero(hot)
    t0 = float(s.t[0])
    events = [
        {"t_start_s": t0 + float(i * w * h), "t_end_s": t0 + float((i + 1) * w * h)}
        for i in starts[:10]
    ]
    sig = bool(hot.any() and hot.mean() < 0.3)
    z_sur = _surrogate_max_z(r, w) if sig else math.nan
    return {
        "kind": "localized",
        "windows": int(hot.sum()),
        "of_windows": int(nw),
        "max_z": float(z.max()),
        "max_z_surrogates": z_sur,
        "events": events,
        "explained_var": excess,
        "significant": sig and float(z.max()) > z_sur,
        "text": f"the residual of {s.channel} concentrates in {int(hot.sum())} of {nw} "
        f"{window_s:g} s windows"
        + (f" (first at {events[0]['t_start_s']:.3g} s)" if events else ""),
    }


def saturation(s: Signals) -> dict[str, Any]:
    """The measured output stops growing where the model's goes on: a hinge in the model output."""
    r = s.residual
    y = s.output - float(np.median(s.output))
    ay = np.abs(y)
    best: dict[str, Any] = {"kind": "saturation", "significant": False, "explained_var": 0.0}
    top: tuple[float, float, FloatArray, FloatArray] | None = None  # (ss, c, coef, e)
    for q in SAT_QUANTILES:
        c = float(np.quantile(ay, q))
        hinge = np.sign(y) * np.maximum(ay - c, 0.0)
        x = np.column_stack([np.ones_like(r), hinge])
        coef, *_ = np.linalg.lstsq(x, r, rcond=None)
        fit = x @ coef
        ss = float(np.var(fit))
        if coef[1] < -0.2 and (top is None or ss > top[0]):
            top = (ss, c, coef, r - fit)
    if top is None:
        return best
    ss, c, coef, e = top
    n_eff = _n_eff(e)  # the autocorrelation time of what the best hinge leaves (one FFT)
    f_stat = ss / max(float(np.var(e)), 1e-300) * (n_eff - 2)
    p_val = float(stats.f.sf(f_stat, 1, max(n_eff - 2, 1.0))) * len(SAT_QUANTILES)
    return {
        "kind": "saturation",
        "level": c,
        "level_abs": c + float(np.median(s.output)),
        "slope_beyond": float(1.0 + coef[1]),
        "explained_var": ss,
        "p_value": min(p_val, 1.0),
        "significant": bool(p_val < _alpha_each()),
        "text": f"{s.channel} saturates: beyond |{c:.3g}| {s.unit} from its middle it "
        f"grows at {100 * (1 + coef[1]):.0f} % of the model's rate",
    }


# ---------------------------------------------------------------------------- together


def findings(
    s: Signals, input_top_hz: float, dep: list[dict[str, Any]], tr: dict[str, Any], window_s: float
) -> list[dict[str, Any]]:
    """Every finding of every search, significant first, by the variance each explains; a
    signal dependence on an angle that a periodicity in it explains as well is dropped (the
    periodicity says more)."""
    allf: list[dict[str, Any]] = []
    allf += spectral_peaks(s, input_top_hz)
    per = angle_periodicity(s)
    allf += per
    sd = signal_dependence(s, dep)
    per_names = {
        n
        for p in per
        if p["significant"]
        for n in [p["signal"], *p["aliases"]]
        if p["explained_var"] > 0
    }
    for d in sd:
        if d["signal"] in per_names:
            pe = max(
                (p for p in per if d["signal"] in [p["signal"], *p["aliases"]]),
                key=lambda p: float(p["explained_var"]),
            )
            if pe["explained_var"] >= 0.5 * d["explained_var"]:
                continue
        allf.append(d)
    allf += trend_findings(s, tr)
    allf.append(slow_offset(s))
    allf.append(localisation(s, window_s))
    allf.append(saturation(s))
    allf = [f for f in allf if f.get("text")]
    # a dependence on a signal (bin means: many parameters) and a localisation (where, not
    # what) rank below a specific finding (a line, a period, a drift, a hinge: two or three
    # parameters) that explains at least half as much
    allf.sort(
        key=lambda f: (
            not f["significant"],
            -float(f["explained_var"]) * (GENERIC_WEIGHT if f["kind"] in GENERIC else 1.0),
        )
    )
    return allf


def structured(found: list[dict[str, Any]], sigma: float, var: float = 0.0) -> bool:
    """Does a significant finding explain at least MIN_STRUCT noise variances (and, given the
    residual's variance ``var``, at least :data:`MIN_SHARE_STRUCT` of it: a finding the
    signature would name, not a sliver of coloured noise above a white-noise floor)?"""
    return any(
        f["significant"]
        and f["explained_var"] >= MIN_STRUCT * sigma * sigma
        and f["explained_var"] >= MIN_SHARE_STRUCT * var
        for f in found
    )
