"""Delay: one recorded channel lags the others by a constant time ``d``.

Typical causes on a bench: a torque amplifier's filter group delay, a bus/DAQ buffer, encoders and
torque sensor read by different devices. ``d > 0``: the measured output lags the input (the model
is driven by ``u(t - d)``); ``d < 0``: the input channel is the one that lags. To first order a
delay on the output looks like *negative* damping and a lagging input like positive damping
(``y(t + d) ~ y + d dy/dt``): the discrepancy workflow must tell the two apart.
Samples are interpolated linearly, so ``d`` need not be a whole number of samples.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


def delayed_sample(y: FloatArray, index: int, delay_samples: float) -> float:
    """``y`` at fractional index ``index - delay_samples`` (linear interpolation, ends held)."""
    n = y.shape[0]
    x = index - delay_samples
    if x <= 0.0:
        return y[0]
    if x >= n - 1:
        return y[n - 1]
    i = int(x)
    f = x - i
    return y[i] + f * (y[i + 1] - y[i])


def delayed_signal(y: FloatArray, delay_samples: float) -> FloatArray:
    """The whole signal delayed by ``delay_samples`` (may be negative: an advance)."""
    n = y.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = delayed_sample(y, i, delay_samples)
    return out
