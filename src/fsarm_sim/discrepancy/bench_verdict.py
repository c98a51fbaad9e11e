"""A bench diagnosis's verdict: the floor below which a held-out residual is noise (output noise,
the recorded inputs' own errors, the replay's own error: :func:`replay_error_floor`), whether
what is left is ``unexplained`` (:func:`unexplained`) and the one sentence that says what was
named (:func:`verdict`). The bench as a setup is :mod:`.bench_setup`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import (
    candidate_structure,
    replay,
    replay_inputs,
    residual_search,
)
from fsarm_sim.discrepancy.residuals import (
    gap_excess,
    nrmse,
    nrmse_floor,
)
from fsarm_sim.discrepancy.uncertainty import RICHARDSON

WITHIN_NOISE = 1.15  # a held-out residual RMS up to this x the noise floor is "within noise"
UNEXPLAINED = math.sqrt(2.0)  # residual RMS / noise floor from which the rest is "unexplained"


def replay_error_floor(
    ctx: candidate_structure.Context,
    final: candidate_structure.Fit,
    half: replay_inputs.ReplayInputs,
) -> float:
    """The replay's own error on the held-out samples: the recorded angles are smoothed and
    differentiated before they drive the model (:func:`.replay_inputs.prepare_inputs`), which rounds off
    fast motion (steps at 500 Hz: ~0.6 x the output noise on a plain record). Estimated as in
    :mod:`.uncertainty`: the RMS change of the final model's replay with every filter window
    halved, times :data:`.uncertainty.RICHARDSON`. Like the inputs' own errors, part of the floor
    below which a residual is not ``unexplained``; never used to name an effect."""
    d = (final.yhat - replay.replay(final.model, half)["y"])[ctx.held]
    d = d[np.isfinite(d)]
    return float(RICHARDSON * np.sqrt(np.mean(d * d))) if d.size else 0.0


def unexplained(
    ctx: candidate_structure.Context,
    final: candidate_structure.Fit,
    sigma_in: float = 0.0,
    sig: dict[str, Any] | None = None,
) -> bool:
    """True when the final model leaves a held-out residual clearly above the noise floor: what
    lies above the noise (output noise and the recorded inputs' own errors together, in
    variance) is at least as large as the noise itself - the size an extra effect must explain
    to be named (:data:`.selection.MIN_EXPLAINED_EXTRA` = 1 noise variance). Without a
    signature: residual RMS above :data:`UNEXPLAINED` x that floor. Given the residual signature
    ``sig``: the residual's mean square minus the floors' (output noise, the inputs' errors, the
    replay's own error) at least ``UNEXPLAINED^2 - 1`` output-noise variances, *and* the general
    search found structure in it (:func:`.residual_search.structured`: a finding significant at
    the false-alarm rate :data:`.residual_search.ALPHA` against noise of the record's own colour
    that explains at least :data:`.residual_search.MIN_STRUCT` noise variances). The floor of
    the first test is the white part of the noise; coloured noise, quantisation and the
    replay's own error raise the residual above it without structure, which the second test
    tells apart."""
    rms = math.sqrt(final.mse_held)
    total = math.hypot(ctx.sigma_y, sigma_in)
    if sig is None or "structured" not in sig:
        return bool(rms > UNEXPLAINED * total)
    # with the structure test: what lies above the floors (output noise, the inputs' errors,
    # the replay's own error) must be at least (UNEXPLAINED^2 - 1) output-noise variances
    excess = rms * rms - total * total
    return bool(excess >= (UNEXPLAINED**2 - 1.0) * ctx.sigma_y**2 and sig["structured"])


def verdict(
    ctx: candidate_structure.Context,
    nom: candidate_structure.Fit,
    final: candidate_structure.Fit,
    named: Sequence[str],
    sigma_in: float = 0.0,
    unexp: bool | None = None,
) -> str:
    """One honest sentence: what was named, the gap before / after, the noise floor and the
    gap above it (independent noise adds in variance)."""
    y, held = ctx.inp.y, ctx.held
    floor = nrmse_floor(y, ctx.sigma_y, held)
    gap_b, gap_a = nrmse(y, nom.yhat, held), nrmse(y, final.yhat, held)
    rms = math.sqrt(final.mse_held)
    ratio = rms / ctx.sigma_y if ctx.sigma_y > 0 else math.inf
    within = ratio <= WITHIN_NOISE
    if unexp is None:
        unexp = unexplained(ctx, final, sigma_in)
    above = rms * rms - sigma_in * sigma_in >= UNEXPLAINED**2 * ctx.sigma_y**2
    why_not = (
        "what lies above the white-noise floor holds no structure the residual search finds "
        f"at its {100 * residual_search.ALPHA:g} % false-alarm rate (coloured noise, quantisation, the "
        "replay's own error)"
        if above
        else "what lies above the noise is smaller than the noise"
    )
    floor_txt = (
        f"noise floor {100 * floor:.3g} %; gap above the floor "
        f"{100 * gap_excess(gap_b, floor):.3g} % -> {100 * gap_excess(gap_a, floor):.3g} %"
    )
    if not named:
        if within or not unexp:
            return (
                "nothing is missing within noise: the refit nominal model leaves a held-out "
                f"residual of {rms:.4g} (noise floor {ctx.sigma_y:.4g}"
                + ("" if within else f"; {why_not}")
                + "); no candidate earns its place"
            )
        return (
            f"no library effect earns its place, but the refit nominal model leaves "
            f"{ratio:.2g} x the noise floor (held-out NRMSE {100 * gap_a:.3g} %, {floor_txt}): "
            "something outside the library or the recorded inputs' own errors"
        )
    total = math.hypot(ctx.sigma_y, sigma_in)
    if within:
        rest = "the rest is within noise"
    elif total > 0 and rms <= WITHIN_NOISE * total:
        rest = (
            f"a residual of {ratio:.2g} x the output noise floor remains, within what the output "
            f"noise and the recorded inputs' own errors (quantisation / noise, propagated: "
            f"{100 * nrmse_floor(y, sigma_in, held):.3g} % NRMSE) explain together"
        )
    elif not unexp:
        rest = f"a residual of {ratio:.2g} x the noise floor remains; {why_not}"
    else:
        rest = f"a residual of {ratio:.2g} x the noise floor remains that no further effect claims"
    return (
        f"missing: {', '.join(named)}; held-out NRMSE {100 * gap_b:.3g} % -> {100 * gap_a:.3g} % "
        f"({floor_txt}); {rest}"
    )
