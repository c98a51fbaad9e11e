"""The normative walking profile (fsarm_sim.studies.gait_profile)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.studies import gait_profile as gp


@pytest.mark.parametrize("joint", gp.JOINTS)
def test_fourier_series_passes_near_its_key_values_and_is_periodic(joint: str) -> None:
    f = gp.fourier_fit(joint)
    t = np.asarray(gp.KEY_PERCENT) / 100.0 * gp.STRIDE_S
    err = np.degrees(f.eval(t)) - np.asarray(gp.KEY_ANGLES_DEG[joint])
    assert float(np.max(np.abs(err))) < 2.0  # a smoothing, within 2° of every read value
    assert f.eval(0.0) == pytest.approx(f.eval(gp.STRIDE_S), abs=1e-12)


@pytest.mark.parametrize("joint", gp.JOINTS)
def test_rates_and_accelerations_are_the_angles_derivatives(joint: str) -> None:
    f = gp.fourier_fit(joint)
    t = np.linspace(0.0, gp.STRIDE_S, 241)
    h = 1e-5
    np.testing.assert_allclose(f.eval(t, 1), (f.eval(t + h) - f.eval(t - h)) / (2 * h), atol=1e-5)
    np.testing.assert_allclose(
        f.eval(t, 2), (f.eval(t + h, 1) - f.eval(t - h, 1)) / (2 * h), atol=1e-4
    )


def test_knee_has_its_loading_and_swing_peaks() -> None:
    t = np.arange(1200) * gp.STRIDE_S / 1200
    knee = np.degrees(gp.profile("knee", t))
    swing = int(np.argmax(knee))
    assert 0.65 < t[swing] / gp.STRIDE_S < 0.8 and knee[swing] > 55.0
    loading = int(np.argmax(knee[:300]))
    assert 0.1 < t[loading] / gp.STRIDE_S < 0.2 and 12.0 < knee[loading] < 25.0


def test_a_slower_stride_scales_the_rates() -> None:
    a, b = gp.fourier_fit("hip", 1.2), gp.fourier_fit("hip", 2.4)
    assert b.eval(1.0, 1) == pytest.approx(0.5 * a.eval(0.5, 1), rel=1e-12)


def test_bad_inputs_raise_named_errors() -> None:
    with pytest.raises(gp.GaitError, match="unknown joint"):
        gp.fourier_fit("elbow")
    with pytest.raises(gp.GaitError, match="stride"):
        gp.fourier_fit("hip", -1.0)
    with pytest.raises(gp.GaitError, match="stride"):
        gp.fourier_fit("hip", math.nan)
    with pytest.raises(gp.GaitError, match="harmonics"):
        gp.fourier_fit("hip", harmonics=10)
    with pytest.raises(gp.GaitError, match="derivative"):
        gp.fourier_fit("hip").eval(0.0, 3)
