"""Seed 004's controller functions (controllers/tendon_sheath_compliance.py): Algorithms 1-2 as
written and the dual-encoder position loop, alone and on the arm with the tendon-sheath."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.controllers import tendon_sheath_compliance as tsc

# seed 004 Table 2, bend pi/2: (P, Q, M) per direction
RC = (-0.208, 0.916, 0.301)
RA = (-0.030, 0.913, -0.063)


def test_nearer_branch_picks_the_closer_curve() -> None:
    th2 = 0.3
    up = tsc.branch_angle(th2, *RC)
    down = tsc.branch_angle(th2, *RA)
    assert up == pytest.approx(-0.208 * 0.09 + 0.916 * 0.3 + 0.301)
    assert tsc.nearer_branch(up - 0.01, th2, RC, RA) == up
    assert tsc.nearer_branch(down + 0.01, th2, RC, RA) == down
    assert tsc.hand_guiding_command(down + 0.01, th2, RC, RA) == down  # Algorithm 2


def test_collision_monitor_alarms_and_holds_the_motor() -> None:
    th2 = -0.2
    up = tsc.branch_angle(th2, *RC)
    # within delta_a: run normally, theta_c = the nearer branch (line 7)
    delta, theta_c, alarm = tsc.collision_monitor(up + 0.02, th2, 0.5, 0.03, RC, RA)
    assert not alarm and theta_c == up and delta == pytest.approx(-0.02)
    # beyond it (between the branches but far from both): the motor holds theta_1(t-) (line 8)
    mid = 0.5 * (up + tsc.branch_angle(th2, *RA))
    delta, theta_c, alarm = tsc.collision_monitor(mid, th2, 0.123, 0.03, RC, RA)
    assert alarm and theta_c == 0.123 and abs(delta) > 0.03


# ------------------------------------------------------------------ the position loop on the arm


def test_position_command_and_speed_bound() -> None:
    # eq. 14 read forward: the motor leads the joint by the stretch the torque needs
    assert tsc.position_command(1.0, 2.0, 100.0) == pytest.approx(1.02)
    assert tsc.motor_speed_command(1.0, 0.9, 0.5, 60.0, 100.0) == pytest.approx(6.5)
    assert tsc.motor_speed_command(10.0, 0.0, 0.0, 60.0, 32.7) == 32.7
    assert tsc.motor_speed_command(-10.0, 0.0, 0.0, 60.0, 32.7) == -32.7


@pytest.mark.parametrize(("payload", "limit_deg"), [(0.0, 0.05), (15.0, 0.2)])
def test_tendon_sheath_arm_tracks_fig14_without_hunting(payload: float, limit_deg: float) -> None:
    # the check: q3 RMSE <= 1 deg at 0 and 15 kg, the motor within its speed limit
    # (before the seed-004 position loop: 5.65 deg at 0 kg, rotor at 560 rad/s > 523.6)
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim.simulation import run_scenario

    cfg = SimConfig(transmission="tendon-sheath")
    res = run_scenario("fig14-sine", cfg, backend="python", duration_s=2.5, payload_kg=payload)
    c = res.columns
    err = np.degrees(c["q3"] - c["q3_ref"])
    assert math.sqrt(float(np.mean(err**2))) < limit_deg
    rotor = np.max(np.abs(c["omega_m"])) * 16.0  # theta_m = rotor / i_G1, i_G1 = 16
    assert rotor < 523.6
