"""The arm's ``unexplained``, ``residual_signature`` and confidence intervals (issue 16).

The bench setups' modules do the work: :mod:`.unexplained` characterises a residual given a
:class:`.unexplained.Signals`; this module prepares the arm's (one per fitting-basis channel:
q3, the shaft twist theta_m - i_G2 q3, the bend q2) and computes the arm's Fisher intervals with
the replay's own secant Jacobian (:func:`.arm_fit.jacobian_column`).

**Unexplained** (:func:`unexplained`): on some basis channel the held-out residual RMS is above
:data:`UNEXPLAINED` x that channel's noise floor, i.e. what lies above the noise there is at
least as large as the noise itself - the size an extra effect must explain to be named
(:data:`.selection.MIN_EXPLAINED_EXTRA`), the benches' rule per recorded channel. Per channel,
not on the channel average the selection scores: the channels are different sensors, and a
disturbance of one (a pickup line on the motor encoder) is not made smaller by the others being
clean; the twist's floor is the joint-3 encoder's noise x i_G2, so the channel average would hide
on the twist what stands out on q3.

**Signature** (:func:`signature`): every basis channel characterised; the headline is the
channel whose residual stands highest above its own noise floor (its ``kind`` / ``summary``),
the others under ``channels``.

**Intervals** (:func:`intervals`): the Gauss-Newton Fisher information of the weighted teaching
residual (``J`` by secants of the closed-loop replay, :data:`SECANT` of each parameter's
typical magnitude; measurement parameters analytically), ``sigma^2`` the weighted teaching
residual's mean square (1 at the noise floor), covariance ``sigma^2 tau (J^T J)^-1`` inflated by
the residual's integrated autocorrelation time; 95 % normal intervals clipped to the bounds.
One closed-loop run per plant parameter.

A quantised channel that dwells on few counts (joint 2 held at a pose, say) does not average its
rounding away. Rounding a value u of a cell plus Gaussian noise sigma errs on average by
``b(u) = (q / pi) sum_k (-1)^(k+1) / k exp(-2 pi^2 k^2 sigma^2 / q^2) sin(2 pi k u / q)`` (the
sawtooth, damped by the noise's characteristic function: Widrow's quantisation theory); over an
unknown u its RMS is ``q / (pi sqrt 2) sqrt(sum_k exp(-4 pi^2 k^2 sigma^2 / q^2) / k^2)``,
``q / sqrt 12`` without noise (:func:`rounding_bias_rms`). A signal that spans m counts (its span
beyond the noise's +-3 sigma) averages m such errors: a common offset of that RMS / sqrt(m). It is
not in ``sigma^2`` (it is not noise) and biases the fit (seen as ``kb_scale`` 5 SD off on a
tendon-sheath record with nothing hidden); each recorded channel's offset (q2 on q2; q3 on q3
and, times -i_G2, on the twist; theta_m on the twist) is carried through the least-squares
solution, ``(J^T J)^-1 J^T e``, and added to the covariance (:func:`rounding_offsets`; q from
:func:`.arm_fit.quantum`; sigma^2 the fit's teaching residual's mean square on the channel less
the rounding's own q^2 / 12 - a difference-based noise floor reads a quantised slow channel's
mostly-zero changes as little noise - and without a residual of its own, the noise floor's).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import replay_inputs
from fsarm_sim.discrepancy.arm_fit import (
    BASIS,
    ArmContext,
    ArmFit,
    FloatArray,
    bounds_of,
    jacobian_column,
    quantum,
    secant_model,
)
from fsarm_sim.discrepancy.residuals import noise_floor, tau_int
from fsarm_sim.discrepancy.uncertainty import LEVEL, Z
from fsarm_sim.discrepancy.unexplained import Signals, characterise

UNEXPLAINED = math.sqrt(2.0)  # held-out residual RMS / noise floor (channel average)
SECANT = 0.1  # secant step of the Jacobian, in units of each parameter's typical magnitude
METHOD = (
    "Fisher information: Jacobian of the noise-weighted replayed channels (q3, twist, q2) by "
    "secants of the closed-loop replay (measurement parameters analytically), sigma^2 from the "
    "weighted teaching residual, covariance sigma^2 tau (J^T J)^-1 inflated by the residual's "
    "integrated autocorrelation time tau, plus the common offset the encoders' rounding leaves on "
    "channels that dwell on few counts, carried through the least-squares solution; 95 % "
    "normal intervals"
)


def rounding_bias_rms(q: float, sigma: float, terms: int = 8) -> float:
    """RMS over the cell of the mean rounding error of a quantiser of step ``q`` whose input
    carries Gaussian noise ``sigma`` (module docstring); ``q / sqrt(12)`` at ``sigma = 0``."""
    if sigma == 0.0:
        return q / math.sqrt(12.0)
    k = np.arange(1, terms + 1, dtype=np.float64)
    damp = np.exp(-4.0 * math.pi**2 * k * k * (sigma / q) ** 2)
    return q / (math.pi * math.sqrt(2.0)) * math.sqrt(float(np.sum(damp / (k * k))))


def rounding_offsets(ctx: ArmContext, fit: ArmFit) -> list[FloatArray]:
    """Per quantised recorded channel, its rounding's common offset as a vector of the weighted
    teaching residual (the basis channels end to end, as :meth:`.arm_fit.ArmContext.wresid`):
    :func:`rounding_bias_rms` over the square root of the counts it spans (module docstring)."""
    n = int(np.count_nonzero(ctx.teach))
    enters = {"q2": {"q2": 1.0}, "q3": {"q3": 1.0, "twist": -ctx.coef_s}, "theta_m": {"twist": 1.0}}
    out = []
    for ch, weights in enters.items():
        y = ctx.raw[ch]
        q = quantum(y)
        if q <= 0.0:
            continue
        x = y[ctx.teach]
        spread = noise_floor(y) ** 2
        if ch in fit.pred:  # q2, q3: the fit's own residual on the channel
            spread = max(spread, float(np.mean((x - fit.pred[ch][ctx.teach]) ** 2)))
        sigma = math.sqrt(max(spread - q * q / 12.0, 0.0))
        counts = 1.0 + max(float(np.ptp(x)) - 6.0 * sigma, 0.0) / q
        sd = rounding_bias_rms(q, sigma) / math.sqrt(counts)
        out.append(
            np.concatenate([np.full(n, sd * weights.get(c, 0.0) / ctx.sigma[c]) for c in BASIS])
        )
    return out


def over_noise(ctx: ArmContext, fit: ArmFit) -> dict[str, float]:
    """Held-out residual RMS / noise floor per basis channel."""
    return {c: math.sqrt(fit.mse_held[c]) / ctx.sigma[c] for c in BASIS}


def unexplained(ctx: ArmContext, fit: ArmFit) -> bool:
    """True when the final model leaves the held-out residual of some channel clearly above
    its noise floor (module docstring)."""
    return bool(max(over_noise(ctx, fit).values()) > UNEXPLAINED)


def signal_set(ctx: ArmContext, fit: ArmFit, channel: str) -> Signals:
    """One basis channel's residual (warm-up excluded) and the signals it may depend on: the
    model's replay of the arm's states (q3, twist, bend and their rates), not their measurements
    - a channel's residual binned by its own measurement follows that measurement's noise and
    quantisation (a bend held still sits on a few encoder counts), not anything missing."""
    h = ctx.run.h
    use = ctx.teach | ctx.held
    q3 = fit.pred["q3"]
    twist = fit.pred["twist"]
    q3d = replay_inputs.derivative(q3, h)
    twd = replay_inputs.derivative(twist, h)
    cand = {
        "twist": twist,
        "twist rate": twd,
        "joint-3 speed": q3d,
        "direction": np.sign(q3d) * (np.abs(q3d) > 0.05 * float(np.std(q3d))),
        "|twist|": np.abs(twist),
        "q3": q3,
        "bend": fit.pred["q2"],
        "joint-3 acceleration": replay_inputs.derivative(q3d, h),
        "model output": fit.pred[channel],
    }
    signals: dict[str, Any] = {}
    for name, v in cand.items():
        v = np.asarray(v, dtype=np.float64)[use]
        if float(np.ptp(v)) <= 0 or any(_same(v, w) for w in signals.values()):
            continue  # the same signal by another name (e.g. q3's model output and q3)
        signals[name] = v
    refs = [
        np.asarray(ctx.ds.columns[c], dtype=np.float64)[use]
        for c in ("q3_ref", "q2_ref")
        if c in ctx.ds.columns
    ]
    return Signals(
        channel=channel,
        unit="rad",
        t=ctx.run.t[use],
        residual=(ctx.y[channel] - fit.pred[channel])[use],
        output=fit.pred[channel][use],
        sigma=ctx.sigma[channel],
        inputs=refs or [ctx.y["q3"][use]],
        signals=signals,
    )


def _same(a: Any, b: Any) -> bool:
    """Two signals that carry the same information for a binned dependence (|corr| > 0.999)."""
    sa, sb = float(np.std(a)), float(np.std(b))
    if sa <= 0 or sb <= 0:
        return False
    return abs(float(np.mean((a - a.mean()) * (b - b.mean()))) / (sa * sb)) > 0.999


def signature(ctx: ArmContext, fit: ArmFit) -> dict[str, Any]:
    """The ``residual_signature`` of the arm (module docstring)."""
    per = {ch: characterise(signal_set(ctx, fit, ch)) for ch in BASIS}
    head = max(BASIS, key=lambda ch: float(per[ch]["rms_over_noise"]))
    return {**per[head], "channels": per}


def intervals(ctx: ArmContext, fit: ArmFit) -> dict[str, Any]:
    """``{"method", "level", "tau_int", "parameters": [{name, value, sd, lower, upper}]}`` of
    every fitted parameter of ``fit`` (module docstring)."""
    keys = list(fit.free)
    r = ctx.wresid(fit.pred, ctx.teach)
    sigma2 = float(np.mean(r * r))
    # tau per channel block (the channels are concatenated end to end): the largest
    n = int(np.count_nonzero(ctx.teach))
    tau = max(tau_int(r[i * n : (i + 1) * n]) for i in range(len(BASIS)))
    ctx.prefetch([secant_model(ctx, fit.model, k, SECANT) for k in keys])  # side by side
    cols: list[Any] = []
    for k in keys:
        c = jacobian_column(ctx, fit.model, fit.pred, fit.raw, k, SECANT)
        cols.append(None if c is None else np.where(np.isfinite(c), c, 0.0))
    params = []
    good = [i for i, c in enumerate(cols) if c is not None and float(np.sum(c * c)) > 0]
    cov = np.full((len(keys), len(keys)), math.inf)
    if good:
        j = np.column_stack([cols[i] for i in good])
        scale = np.sqrt(np.sum(j * j, axis=0))
        inv = np.linalg.pinv((j / scale).T @ (j / scale)) / np.outer(scale, scale)
        shifts = [inv @ (j.T @ e) for e in rounding_offsets(ctx, fit)]
        cov[np.ix_(good, good)] = inv * sigma2 * tau + sum(
            (np.outer(d, d) for d in shifts), np.zeros_like(inv)
        )
    for i, k in enumerate(keys):
        lo, hi, unit = bounds_of(ctx, k)
        v = fit.model.v(k)
        var = cov[i, i]
        sd = math.sqrt(var) * unit if math.isfinite(var) and var >= 0 else math.inf
        params.append(
            {
                "name": k,
                "value": v,
                "sd": sd,
                "lower": max(v - Z * sd, lo),
                "upper": min(v + Z * sd, hi),
            }
        )
    return {"method": METHOD, "level": LEVEL, "tau_int": tau, "parameters": params}
