"""What a residual that no library effect explains looks like: ``residual_signature``.

When the final model leaves the held-out residual clearly above the noise floor, an expert says
*what* remains - "a 50 Hz line of 0.12 N*m on tau_s", "the stiffness rises ~12 % over the
record", "it follows the twist" - not only that something does. :func:`characterise` looks at the
final model's residual of one channel four ways:

* **Spectral lines**: the Hann-windowed periodogram of the whole residual against its running
  median (101 bins). A bin is a line when its power exceeds :data:`LINE_POWER` x the local
  median (white noise's periodogram is exponential: the chance of a bin passing is
  ``exp(-LINE_POWER ln 2)``, ~1e-9, so ~1e-5 false lines per 30 000-sample record). The
  frequency is refined by a parabola through the log power of the peak and its neighbours, the
  amplitude by least squares of a sine and cosine at that frequency on the whole record. A line
  at a frequency the recorded input carries (a line of the input's own periodogram, or inside
  the band holding 99 % of the input's power) is flagged ``in_input``: the misfit of a law driven
  by the input, not pickup.
* **Trends over time**: least squares of the residual on ``1, tau`` (an offset drifting at a
  fitted rate, output units per second) and on ``tau * yhat`` (the output's gain, i.e. the
  stiffness, drifting: relative change over the record), ``tau`` the time centred on the
  record's middle. Each with the share of the residual variance it explains and a t value whose
  standard error is inflated by the autocorrelation time of what the regression leaves.
* **Dependence on a signal**: the share of the residual variance explained by its mean in 20
  quantile bins of each recorded or derived signal (twist, twist rate, direction, input angle,
  bend, input acceleration, the model's output) - the signal that explains most is named, with
  its binned means (for the plot).
* **Where it concentrates**: the share of the residual energy in the worst 10 % of 0.25 s
  windows (0.1 when spread evenly) and the worst windows themselves; as a description
  (``localized``) only what time explains beyond a significant linear drift.

``kind`` names the description that explains the largest share: ``spectral_line`` (lines not
at the input's frequencies), ``drift``, ``signal`` or ``localized``; ``summary`` says it in one
sentence. All shares are of the residual's variance (noise included), so a pure-noise residual
gives small shares everywhere; the caller decides whether the residual is above the noise floor
at all (``unexplained``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.ndimage import median_filter

from fsarm_sim.discrepancy import residual_search
from fsarm_sim.discrepancy.residual_search import Signals
from fsarm_sim.discrepancy.residuals import above_noise_intervals, tau_int

FloatArray = npt.NDArray[np.float64]

LINE_POWER = 30.0  # periodogram power / running median for a line
LINE_MEDIAN_BINS = 101
MAX_LINES = 4
MIN_LINE_HZ_BINS = 3  # lines closer to 0 Hz than this many bins are trends, not lines
INPUT_BAND_POWER = 0.99  # the input's band: up to the frequency below which this share lies
N_BINS = 48  # fine enough for a ripple of a few periods over the signal's range
WINDOW_S = 0.25
MIN_SHARE = 0.05  # a description that explains less than this share of the variance is none


def _periodogram(x: FloatArray, h: float) -> tuple[FloatArray, FloatArray]:
    w = np.hanning(x.size)
    p = np.abs(np.fft.rfft((x - x.mean()) * w)) ** 2
    return np.asarray(np.fft.rfftfreq(x.size, h), dtype=np.float64), np.asarray(p, np.float64)


def _peaks(p: FloatArray) -> npt.NDArray[np.int64]:
    med = median_filter(p, size=LINE_MEDIAN_BINS, mode="nearest")
    med = np.maximum(med, 1e-300)
    ratio = p / med
    loc = (ratio[1:-1] > LINE_POWER) & (p[1:-1] >= p[:-2]) & (p[1:-1] >= p[2:])
    return np.flatnonzero(loc) + 1


def input_band(inputs: list[FloatArray], h: float) -> tuple[float, list[FloatArray]]:
    """(upper edge of the band holding INPUT_BAND_POWER of the inputs' rate power, their line
    masks per frequency bin) - the band of the input's *rate* spectrum, so that a slow offset
    does not hide the band's top."""
    top = 0.0
    masks = []
    for u in inputs:
        f, p = _periodogram(np.gradient(u, h), h)
        c = np.cumsum(p)
        if c[-1] > 0:
            top = max(top, float(f[int(np.searchsorted(c, INPUT_BAND_POWER * c[-1]))]))
        m = np.zeros(p.size, dtype=bool)
        m[_peaks(p)] = True
        masks.append(m)
    return top, masks


def spectral_lines(s: Signals) -> list[dict[str, Any]]:
    """The residual's spectral lines, strongest first (module docstring)."""
    r = s.residual
    h = float(s.t[1] - s.t[0])
    f, p = _periodogram(r, h)
    idx = _peaks(p)
    idx = idx[idx >= MIN_LINE_HZ_BINS]
    if idx.size == 0:
        return []
    idx = idx[np.argsort(p[idx])[::-1]][: 3 * MAX_LINES]
    band, masks = input_band(s.inputs, h)
    var = float(np.var(r)) or 1.0
    tt = s.t - s.t[0]
    out: list[dict[str, Any]] = []
    for i in idx:
        lp = np.log(np.maximum(p[i - 1 : i + 2], 1e-300))
        den = lp[0] - 2 * lp[1] + lp[2]
        off = 0.5 * (lp[0] - lp[2]) / den if den < 0 else 0.0
        fr = float(f[i] + off * (f[1] - f[0]))
        a = np.column_stack([np.sin(2 * np.pi * fr * tt), np.cos(2 * np.pi * fr * tt)])
        c = np.linalg.lstsq(a, r - r.mean(), rcond=None)[0]
        amp = float(math.hypot(c[0], c[1]))
        near = slice(max(i - 2, 0), i + 3)
        in_input = fr <= band or any(bool(m[near].any()) for m in masks)
        out.append(
            {
                "frequency_hz": fr,
                "amplitude": amp,
                "channel": s.channel,
                "unit": s.unit,
                "share_of_residual": min(0.5 * amp * amp / var, 1.0),
                "amplitude_over_noise": amp / s.sigma if s.sigma > 0 else math.inf,
                "in_input": in_input,
            }
        )
    out.sort(key=lambda d: -float(d["amplitude"]))
    return out[:MAX_LINES]


def _regress(a: FloatArray, r: FloatArray) -> tuple[FloatArray, FloatArray, float]:
    """(coefficients, standard errors, share of var(r) explained) of least squares of ``r`` on
    the columns of ``a``; the standard errors are the ordinary ones inflated by the integrated
    autocorrelation time of the regression's own residual (what the columns leave: a drift the
    columns describe must not count as correlated noise against itself)."""
    c, *_ = np.linalg.lstsq(a, r, rcond=None)
    fit = a @ c
    res = r - fit
    s2 = float(np.sum(res * res)) / max(r.size - a.shape[1], 1)
    cov = np.linalg.pinv(a.T @ a) * s2 * tau_int(res)
    var = float(np.var(r)) or 1.0
    se = np.asarray(np.sqrt(np.maximum(np.diag(cov), 0.0)), dtype=np.float64)
    return np.asarray(c, dtype=np.float64), se, float(np.var(fit - fit.mean()) / var)


def trends(s: Signals) -> dict[str, Any]:
    """An offset drifting and the output's gain (stiffness) drifting over the record."""
    r = s.residual
    t = s.t
    dur = float(t[-1] - t[0]) or 1.0
    tau = (t - 0.5 * (t[0] + t[-1])) / dur  # -0.5 .. 0.5
    one = np.ones_like(r)
    c, se, share = _regress(np.column_stack([one, tau]), r)
    yc = s.output - s.output.mean()
    cg, seg, share_g = _regress(np.column_stack([one, tau, yc, tau * yc]), r)
    # the gain drift's own share: beyond what the offset drift and a constant gain explain
    _, _, share_base = _regress(np.column_stack([one, tau, yc]), r)
    return {
        "offset": {
            "rate_per_s": float(c[1] / dur),
            "change_over_record": float(c[1]),
            "t_value": float(c[1] / se[1]) if se[1] > 0 else math.inf,
            "share_of_residual": share,
            "unit": f"{s.unit}/s",
        },
        "gain": {
            "relative_change_over_record": float(cg[3]),
            "relative_rate_per_s": float(cg[3] / dur),
            "t_value": float(cg[3] / seg[3]) if seg[3] > 0 else math.inf,
            "share_of_residual": max(share_g - share_base, 0.0),
            "meaning": f"{s.channel} = model x (1 + rate x (t - t_mid)): a stiffness (or sensor "
            "gain) drifting over the record",
        },
    }


def _binned(r: FloatArray, x: FloatArray) -> tuple[float, FloatArray, FloatArray]:
    """(share of var(r) explained by bin means, bin centres, bin means) in quantile bins of x
    (a signal of few values: one bin per value)."""
    vals = np.unique(x)
    if vals.size <= N_BINS:
        edges = vals
        g = np.searchsorted(vals, x)
        nb = vals.size
    else:
        edges = np.unique(np.quantile(x, np.linspace(0, 1, N_BINS + 1)))
        if edges.size < 3:
            return 0.0, np.zeros(0), np.zeros(0)
        g = np.clip(np.searchsorted(edges[1:-1], x, side="right"), 0, edges.size - 2)
        nb = edges.size - 1
    if nb < 2:
        return 0.0, np.zeros(0), np.zeros(0)
    cnt = np.bincount(g, minlength=nb)
    sums = np.bincount(g, weights=r, minlength=nb)
    means = np.divide(sums, cnt, out=np.zeros(cnt.size), where=cnt > 0)
    xs = np.bincount(g, weights=x, minlength=nb)
    centres = np.divide(xs, cnt, out=np.zeros(cnt.size), where=cnt > 0)
    var = float(np.var(r))
    share = float(np.var(means[g]) / var) if var > 0 else 0.0
    return share, centres[cnt > 0], means[cnt > 0]


def dependence(s: Signals) -> list[dict[str, Any]]:
    """Per signal: the share of the residual variance its binned means explain, best first."""
    out: list[dict[str, Any]] = []
    for name, x in s.signals.items():
        if x.size != s.residual.size or float(np.ptp(x)) <= 0 or not np.all(np.isfinite(x)):
            continue
        share, centres, means = _binned(s.residual, x)
        out.append(
            {
                "signal": name,
                "share_of_residual": share,
                "bin_centres": centres,
                "bin_means": means,
            }
        )
    out.sort(key=lambda d: -float(d["share_of_residual"]))
    return out


def concentration(s: Signals) -> dict[str, Any]:
    """Where in the record the residual sits: the energy share of the worst 10 % of windows."""
    h = float(s.t[1] - s.t[0])
    w = max(1, int(WINDOW_S / h))
    n = (s.residual.size // w) * w
    e = np.sum((s.residual[:n] ** 2).reshape(-1, w), axis=1)
    k = max(1, math.ceil(0.1 * e.size))
    top = float(np.sum(np.sort(e)[::-1][:k]) / np.sum(e)) if np.sum(e) > 0 else 0.0
    frac, worst = above_noise_intervals(s.residual, s.t, s.sigma, WINDOW_S, top=3)
    share_t, _, _ = _binned(s.residual, s.t)
    return {
        "energy_share_worst_10pct_time": top,
        "time_above_2x_noise": frac,
        "worst_windows": worst,
        "share_explained_by_time": share_t,
    }


def _descriptions(
    s: Signals,
    foreign: list[dict[str, Any]],
    tr: dict[str, Any],
    dep: list[dict[str, Any]],
    where: dict[str, Any],
) -> list[tuple[float, str, str]]:
    """The (share, kind, text) of each structure the residual shows (line, drift, signal,
    localized), those of at least :data:`MIN_SHARE`, largest first."""
    cands: list[tuple[float, str, str]] = []
    if foreign:
        ln = foreign[0]
        share = min(sum(x["share_of_residual"] for x in foreign), 1.0)
        cands.append(
            (
                share,
                "spectral_line",
                f"a {ln['frequency_hz']:.4g} Hz line of {ln['amplitude']:.3g} {s.unit} "
                f"(amplitude) on {s.channel}",
            )
        )
    g, o = tr["gain"], tr["offset"]
    if abs(g["t_value"]) > 3 and g["share_of_residual"] >= o["share_of_residual"]:
        ch = 100 * g["relative_change_over_record"]
        word = "rises" if ch > 0 else "falls"
        cands.append(
            (
                g["share_of_residual"],
                "drift",
                f"the gain of {s.channel} (the stiffness) {word} by ~{abs(ch):.3g} % over the "
                f"record ({100 * g['relative_rate_per_s']:+.3g} %/s)",
            )
        )
    elif abs(o["t_value"]) > 3:
        cands.append(
            (
                o["share_of_residual"],
                "drift",
                f"the offset of {s.channel} drifts by {o['change_over_record']:+.3g} {s.unit} "
                f"over the record ({o['rate_per_s']:+.3g} {s.unit}/s)",
            )
        )
    if dep and dep[0]["signal"] != "time":
        d = dep[0]
        cands.append(
            (
                d["share_of_residual"],
                "signal",
                f"the residual of {s.channel} follows the {d['signal']} "
                f"({100 * d['share_of_residual']:.0f} % of its variance)",
            )
        )
    # localized: structure in time beyond a linear drift (a ramp's ends are not a burst)
    share_local = where["share_explained_by_time"] - max(
        o["share_of_residual"] if abs(o["t_value"]) > 3 else 0.0,
        g["share_of_residual"] if abs(g["t_value"]) > 3 else 0.0,
    )
    if share_local > 0 and where["energy_share_worst_10pct_time"] > 0.3:
        w0 = where["worst_windows"][0] if where["worst_windows"] else None
        at = f" (worst at {w0['t_start_s']:.3g}-{w0['t_end_s']:.3g} s)" if w0 else ""
        cands.append(
            (
                share_local,
                "localized",
                f"the residual of {s.channel} concentrates in "
                f"{100 * where['energy_share_worst_10pct_time']:.0f} % of its energy in 10 % "
                f"of the record{at}",
            )
        )
    cands = [c for c in cands if c[0] >= MIN_SHARE]
    cands.sort(key=lambda c: -c[0])
    return cands


def characterise(s: Signals) -> dict[str, Any]:
    """The ``residual_signature`` of one channel (module docstring)."""
    r = s.residual
    rms = float(np.sqrt(np.mean(r * r)))
    lines = spectral_lines(s)
    foreign = [ln for ln in lines if not ln["in_input"]]
    tr = trends(s)
    dep = dependence(s)
    where = concentration(s)
    cands = _descriptions(s, foreign, tr, dep, where)
    band, _ = input_band(s.inputs, float(s.t[1] - s.t[0]))
    found = residual_search.findings(s, band, dep, tr, WINDOW_S)
    var = float(np.var(r)) or 1.0
    top = [f for f in found if f["significant"] and f["explained_var"] >= MIN_SHARE * var]
    if top:  # the general search's strongest significant finding is the headline
        kind = "spectral_line" if top[0]["kind"] == "spectral_line" else str(top[0]["kind"])
        summary = str(top[0]["text"])
    else:
        kind, summary = "none", "no structure found"
    return {
        "channel": s.channel,
        "unit": s.unit,
        "rms": rms,
        "rms_over_noise": rms / s.sigma if s.sigma > 0 else math.inf,
        "kind": kind,
        "summary": summary,
        "descriptions": [{"kind": k, "share_of_residual": sh, "text": tx} for sh, k, tx in cands],
        "spectral_lines": lines,
        "trend": tr,
        "dependence": [
            {k: v for k, v in d.items() if k not in ("bin_centres", "bin_means")} for d in dep
        ],
        "dependence_curve": (
            {
                "signal": dep[0]["signal"],
                "bin_centres": dep[0]["bin_centres"],
                "bin_means": dep[0]["bin_means"],
            }
            if dep
            else None
        ),
        "where": where,
        "findings": [
            {k: v for k, v in f.items() if k not in ("bin_centres", "bin_means")} for f in found
        ],
        "structured": residual_search.structured(found, s.sigma, var),
        "method": "spectral lines: Hann periodogram vs its 101-bin running median (> "
        f"{LINE_POWER:g} x), amplitude by least squares at the refined frequency; trends: least "
        "squares on time (offset) and time x model output (gain), standard errors inflated by the "
        "autocorrelation time of what each regression leaves; dependence: "
        f"{N_BINS} quantile bins per signal; shares are of the residual variance",
    }


def plot(sig: dict[str, Any], s: Signals, path: Any) -> Any:
    """Four panels: the residual over time (with the fitted drift), its spectrum (lines
    marked), its binned dependence on the best signal, and its rolling RMS over the noise."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2, figsize=(11, 7))
    t, r = s.t, s.residual
    step = max(1, r.size // 20000)
    ax[0, 0].plot(t[::step], r[::step], lw=0.4, color="k")
    tr = sig["trend"]
    dur = float(t[-1] - t[0]) or 1.0
    tau = (t - 0.5 * (t[0] + t[-1])) / dur
    ax[0, 0].plot(t, r.mean() + tr["offset"]["change_over_record"] * tau, color="tab:red", lw=1)
    ax[0, 0].set_xlabel("t [s]")
    ax[0, 0].set_ylabel(f"residual {s.channel} [{s.unit}]")
    ax[0, 0].set_title(sig["summary"], fontsize=8)
    h = float(t[1] - t[0])
    f, p = _periodogram(r, h)
    amp = 2.0 * np.sqrt(p) / np.sum(np.hanning(r.size))  # sine amplitude scale
    ax[0, 1].semilogy(f[1:], amp[1:], lw=0.5, color="k")
    for ln in sig["spectral_lines"]:
        ax[0, 1].axvline(
            ln["frequency_hz"], color="tab:grey" if ln["in_input"] else "tab:red", ls=":", lw=1
        )
    ax[0, 1].set_xscale("log")
    ax[0, 1].set_xlabel("frequency [Hz]")
    ax[0, 1].set_ylabel(f"amplitude [{s.unit}]")
    dc = sig["dependence_curve"]
    if dc is not None:
        ax[1, 0].plot(dc["bin_centres"], dc["bin_means"], "o-", color="tab:blue")
        ax[1, 0].set_xlabel(dc["signal"])
    ax[1, 0].axhline(0.0, color="grey", lw=0.5)
    ax[1, 0].set_ylabel(f"mean residual [{s.unit}]")
    w = max(1, int(WINDOW_S / h))
    c = np.cumsum(np.r_[0.0, r * r])
    rms = np.sqrt((c[w:] - c[:-w]) / w)
    ax[1, 1].plot(t[: rms.size][::step], rms[::step] / max(s.sigma, 1e-300), lw=0.6)
    ax[1, 1].axhline(1.0, color="grey", ls=":")
    ax[1, 1].set_xlabel("t [s]")
    ax[1, 1].set_ylabel("rolling RMS / noise floor")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
