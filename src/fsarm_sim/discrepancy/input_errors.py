"""The recorded inputs' own errors on a bench: the step of a quantised channel, a re-measured
copy of a recorded angle, and the output error that re-measuring causes through a model
(:func:`input_error_floor`, the propagated noise floor of :mod:`.selection`'s module docstring:
reported, never used to name an effect)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import candidate_structure, replay, replay_inputs
from fsarm_sim.discrepancy.benchmodel import BenchModel
from fsarm_sim.discrepancy.residuals import noise_floor
from fsarm_sim.records.measured import Dataset

FloatArray = npt.NDArray[np.float64]


def quantisation_step(x: FloatArray) -> float:
    """Step of a quantised channel (encoder counts), 0 when its values are not on a grid."""
    d = np.abs(np.diff(x))
    scale = float(np.max(np.abs(x))) if x.size else 0.0
    nz = d[d > 1e-12 * max(scale, 1e-300)]
    if nz.size < 10:
        return 0.0
    q = float(nz.min())
    frac = nz / q
    on_grid = np.abs(frac - np.round(frac)) < 0.01
    return q if float(np.mean(on_grid)) > 0.95 else 0.0


def remeasure(x: FloatArray, h: float, rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
    """(proxy, re-measured proxy) of a recorded angle: the proxy is the smoothed record; it is
    re-measured on the record's encoder grid (random grid phase) when the record is quantised and
    its noise is what quantisation alone leaves (d4 estimate <= the step), else with white noise
    of the record's noise floor."""
    proxy = replay_inputs.smooth(x, h)
    q = quantisation_step(x)
    sig = noise_floor(x)
    if q > 0.0 and sig <= q:
        off = float(rng.uniform(0.0, q))
        return proxy, np.round((proxy + off) / q) * q - off
    return proxy, proxy + sig * rng.standard_normal(x.size)


def input_error_floor(ds: Dataset, ctx: candidate_structure.Context, model: BenchModel) -> float:
    """RMS (held-out) of the output change a re-measurement of the recorded angles causes in the
    replay of ``model``: the part of the residual that the inputs' own errors explain."""
    names = ["theta_m", "theta_s"] if ds.setup == "series_bench" else ["phi_b"]
    cols_ref = dict(ds.columns)
    cols_new = dict(ds.columns)
    rng = np.random.default_rng(0)
    for nm in names:
        cols_ref[nm], cols_new[nm] = remeasure(np.asarray(ds.columns[nm], float), ds.dt, rng)
    try:
        y_ref = replay.replay(model, replay_inputs.prepare_inputs(replace(ds, columns=cols_ref)))[
            "y"
        ]
        y_new = replay.replay(model, replay_inputs.prepare_inputs(replace(ds, columns=cols_new)))[
            "y"
        ]
    except (ValueError, FloatingPointError):  # an estimate for the report: never fatal
        return 0.0
    d = (y_new - y_ref)[ctx.held]
    return float(np.sqrt(np.mean(d * d))) if np.all(np.isfinite(d)) else 0.0
