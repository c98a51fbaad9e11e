"""Seed 004's validation bench on our tendon-sheath law (studies/reproduce/measure004.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.plant.transmissions import tendon_sheath as ts
from fsarm_sim.studies.reproduce import measure004


@pytest.fixture(scope="module")
def run_pi() -> dict:
    return measure004.position_transmission(math.pi, 0.06)


def test_the_joint_swings_about_zero_from_equal_start_angles(run_pi: dict) -> None:
    # Sec. III: theta_1 and theta_2 start equal, so theta_2 swings about 0 as theta_1 does
    t1, t2 = run_pi["theta1"], run_pi["theta2"]
    assert t1.min() == pytest.approx(-measure004.AMPLITUDE_RAD, abs=2 * measure004.STEP_RAD)
    assert t1.max() == pytest.approx(measure004.AMPLITUDE_RAD, abs=2 * measure004.STEP_RAD)
    # (both sides by a good part of the swing: the joint's range is the motor's less the gap)
    assert t2.min() < -0.15 and t2.max() > 0.15


def test_friction_follows_the_motor_and_the_joint_stops_at_reversals(run_pi: dict) -> None:
    d, z, moving = run_pi["direction"], run_pi["friction_state"], run_pi["moving"]
    # the friction state ends each stroke on the motor's side (the tendon slides with it)
    ends = np.flatnonzero(np.diff(d) != 0)
    assert ends.size == 1
    assert np.sign(z[ends[0]]) == d[ends[0]] and np.sign(z[-1]) == d[-1]
    # seed 004 phases C and F: right after the reversal the joint does not follow the motor
    assert not moving[ends[0] + 1 : ends[0] + 10].any()
    assert moving.mean() > 0.5


def test_gap_is_the_difference_of_the_branch_fits_at_zero(run_pi: dict) -> None:
    f = run_pi["fits"]
    assert run_pi["gap"] == pytest.approx(abs(f["up"]["M"] - f["down"]["M"]))
    assert run_pi["gap"] > 0.05  # a real hysteresis, not the 1e-4 rad of a follow-the-load state


def test_steel_tendon_on_the_arm_defaults_has_a_far_smaller_gap(run_pi: dict) -> None:
    # the arm's rigid-sheath steel tendon, as a single tendon on the same bench
    steel = measure004.position_transmission(
        math.pi,
        0.06,
        overrides={
            "sheath_ea_n": 0.0,
            "routing_wrap_rad": 0.0,
            "mu": float(ts.PARAMS[ts.I_MU].value),
        },
    )
    assert 0.0 < steel["gap"] < 0.1 * run_pi["gap"]


def test_the_bench_meets_both_tables_branch_gaps(run_pi: dict) -> None:
    """SEED004_BENCH is fitted to the six branch gaps of Tables 1-2 (largest relative error
    8.2 %): each gap within 10 % of its table, and the shared point (bend pi, 0.06 rad/s) is the
    one run of both tables."""
    gaps_bend = [
        run_pi["gap"]
        if w == math.pi
        else measure004.position_transmission(w, measure004.DEFAULT_SPEED)["gap"]
        for w in measure004.WRAPS_RAD
    ]
    gaps_speed = [
        run_pi["gap"]
        if v == measure004.DEFAULT_SPEED
        else measure004.position_transmission(math.pi, v)["gap"]
        for v in measure004.SPEEDS_RAD_S
    ]
    for ours, table in (
        *zip(gaps_bend, measure004.TABLE2_GAPS, strict=True),
        *zip(gaps_speed, measure004.TABLE1_GAPS, strict=True),
    ):
        assert abs(ours / table - 1.0) <= 0.10, (ours, table)


def test_a_coarse_joint_encoder_adds_about_a_count_to_eq19s_error(run_pi: dict) -> None:
    exact = run_pi["max_error"]
    # a fine encoder reads the same fit; a coarse one adds up to about one count
    assert measure004.max_error_read(run_pi, 24) == pytest.approx(exact, rel=1e-3)
    q6 = 2.0 * math.pi / 2**6  # 0.098 rad per count
    coarse = measure004.max_error_read(run_pi, 6)
    assert exact + 0.1 * q6 < coarse < exact + q6
    with pytest.raises(ValueError, match="bits"):
        measure004.max_error_read(run_pi, 0)
