"""Controllers are pure functions: measurements in, commands out."""

from __future__ import annotations

import pytest

from fsarm_sim.controllers.joint3_torque import speed_loop, torque_pid
from fsarm_sim.controllers.joint_position import clamp, computed_torque


def test_computed_torque_feedforward_only_on_reference() -> None:
    assert computed_torque(0.3, 0.1, 0.3, 0.1, 2.0, 0.5, 4.0, 20.0, 1.0) == pytest.approx(
        0.5 * 2.0 + 4.0
    )
    # restoring: positive error -> positive torque
    assert computed_torque(0.0, 0.0, 0.1, 0.0, 0.0, 1.0, 0.0, 10.0, 1.0) == pytest.approx(10.0)


def test_clamp() -> None:
    assert clamp(5.0, 2.0) == 2.0
    assert clamp(-5.0, 2.0) == -2.0
    assert clamp(1.0, 2.0) == 1.0


def test_torque_pid_terms_and_feedforward() -> None:
    omega, integ, e, p, _i, d = torque_pid(
        1.0, 0.5, 0.0, 0.0, 0.0, 0.001, 4.0, 40.0, 0.0, 3.0, 100.0
    )
    assert e == pytest.approx(0.5)
    assert p == pytest.approx(2.0)
    assert integ == pytest.approx(0.0005)
    assert omega == pytest.approx(3.0 + 2.0 + 40.0 * 0.0005)
    assert d == 0.0  # first tick: no derivative kick


def test_torque_pid_antiwindup() -> None:
    omega, integ, *_ = torque_pid(100.0, 0.0, 0.5, 0.0, 1.0, 0.001, 4.0, 40.0, 0.0, 0.0, 10.0)
    assert omega == 10.0
    assert integ == 0.5  # held while saturated


def test_speed_loop_limits_and_antiwindup() -> None:
    tau, integ = speed_loop(1000.0, 0.0, 0.2, 0.001, 0.009, 0.3, 1.0)
    assert tau == 1.0
    assert integ == 0.2
    tau, integ = speed_loop(10.0, 9.0, 0.0, 0.001, 0.009, 0.3, 1.0)
    assert tau == pytest.approx(0.009 * 1.0 + 0.3 * 0.001)


def test_scheduled_gains_keep_the_bandwidth() -> None:
    from fsarm_sim.controllers.joint3_torque import scheduled_gains

    for k in (1.0, 15.0, 45.0):
        kp, ki, kd = scheduled_gains(60.0, 10.0, 0.0, k)
        assert kp * k == pytest.approx(60.0)  # bandwidth K kp is independent of the shaft
        assert ki * k == pytest.approx(600.0)
        assert kd == 0.0
