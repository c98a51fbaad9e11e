"""The residual statistics of discrepancy/residuals.py: the autocorrelation time's window sum."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.discrepancy.residuals import tau_int


def _tau_int_by_loop(r: np.ndarray, max_lag: int = 2000) -> float:
    """Sokal's self-consistent window (c = 5) summed lag by lag, the definition."""
    x = r - r.mean()
    n = x.size
    if n < 20 or float(np.dot(x, x)) == 0.0:
        return 1.0
    m = 1 << math.ceil(math.log2(2 * n))
    f = np.fft.rfft(x, m)
    acf = np.fft.irfft(f * np.conj(f), m)[: min(n, max_lag + 1)]
    acf = acf / acf[0]
    t = 1.0
    for k in range(1, acf.size):
        t += 2.0 * acf[k]
        if k >= 5.0 * t:
            break
    return float(min(max(t, 1.0), n / 20.0))


def _ar1(phi: float, n: int, rng: np.random.Generator) -> np.ndarray:
    e = rng.standard_normal(n)
    x = np.empty(n)
    acc = 0.0
    for i in range(n):
        acc = phi * acc + e[i]
        x[i] = acc
    return x


@pytest.mark.parametrize("phi", [0.0, 0.6, 0.97, 0.999, -0.7])
@pytest.mark.parametrize("n", [19, 40, 3000])
def test_tau_int_is_the_window_sum_lag_by_lag(phi: float, n: int) -> None:
    """The vectorised sum gives the loop's value to the last bit (white noise stops at once,
    slowly correlated noise runs to the lag limit or the n/20 cap)."""
    rng = np.random.default_rng(int(1000 * abs(phi)) + n)
    r = _ar1(phi, n, rng)
    for max_lag in (2000, 30, 1):
        assert tau_int(r, max_lag) == _tau_int_by_loop(r, max_lag)


def test_tau_int_of_a_constant_and_of_white_noise() -> None:
    assert tau_int(np.ones(100)) == 1.0
    r = np.random.default_rng(3).standard_normal(20000)
    assert 0.8 < tau_int(r) < 1.3
