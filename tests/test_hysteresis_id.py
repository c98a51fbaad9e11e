"""Identification of the controller's Maxwell-slip model from series-bench records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.engine import hysteresis_model as hm
from fsarm_sim.studies.hysteresis_id import IdentificationError, identify, model_torque

TRUE = (13.0, -3.0, 11.0, -2.0, 9.0, 5.0, 3.0, 0.14, 0.24, 0.36, 0.6, 0.45)


def _records(values: tuple[float, ...]) -> list[dict[str, np.ndarray]]:
    """Synthetic series-test records: a decaying-amplitude chirp of twist at three held bends,
    torque from the model itself (a known truth the fit must find)."""
    t = np.arange(0.0, 2.0, 1e-3)
    x = 0.45 * (1.0 - 0.4 * t / 2.0) * np.sin(2 * math.pi * (0.5 * t + 1.5 * t * t))
    out = []
    for b in (0.0, math.pi / 4, math.pi / 2):
        bend = np.full_like(t, b)
        out.append(
            {
                "t": t,
                "theta_m": x,
                "theta_s": np.zeros_like(t),
                "phi_b": bend,
                "tau_s": model_torque(values, x, bend),
            }
        )
    return out


def test_identify_recovers_a_known_model() -> None:
    fit = identify(_records(TRUE), starts=1, max_nfev=40)
    assert fit.rmse_nm < 0.02 * fit.eq8_rmse_nm + 1e-3, (fit.rmse_nm, fit.eq8_rmse_nm)
    got = fit.as_dict()
    want = dict(zip(hm.NAMES, TRUE, strict=True))
    assert got["unwinding_ratio"] == pytest.approx(want["unwinding_ratio"], rel=0.1)
    assert got["bend_friction_per_rad"] == pytest.approx(want["bend_friction_per_rad"], rel=0.15)
    # the total slip torque and the spring are what the loop shows most directly
    assert got["f1"] + got["f2"] + got["f3"] == pytest.approx(0.74, rel=0.1)
    assert got["k_pos"] == pytest.approx(13.0, rel=0.1)


def test_one_bend_leaves_the_bend_dependence_at_zero_and_says_so() -> None:
    fit = identify(_records(TRUE)[1:2], starts=1, max_nfev=20)  # 45 deg only
    got = fit.as_dict()
    assert got["s_pos"] == got["s_neg"] == got["bend_friction_per_rad"] == 0.0
    assert fit.notes and "one bend only" in fit.notes[0]
    # the spring is the one at that bend
    assert got["k_pos"] == pytest.approx(13.0 - 3.0 * math.pi / 4, rel=0.1)


def test_identify_refuses_records_that_twist_one_way_only() -> None:
    rec = _records(TRUE)[0]
    rec["theta_m"] = np.abs(rec["theta_m"]) + 0.01
    with pytest.raises(IdentificationError, match="both ways"):
        identify([rec])
    with pytest.raises(IdentificationError, match="lacks the column"):
        identify([{"theta_m": rec["theta_m"]}])
