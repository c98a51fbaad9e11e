"""Seed 001's transparency with walking profiles (fsarm_sim.studies.rtca_walking)."""

from __future__ import annotations

import math

import pytest

from fsarm_sim.studies import gait_profile
from fsarm_sim.studies import rtca_bench as rb
from fsarm_sim.studies import rtca_walking as rw

ACT = rb.Rtca001()
PID = rb.Pid(kp=34.6, ki=961.0, kd=0.31)  # about the bench's Ziegler-Nichols gains


def test_interaction_torque_scales_with_the_profiles_speed_and_rises_with_bend() -> None:
    normal = rw.walking(ACT, PID, "knee", strides=2, stride_s=1.2)
    slow = rw.walking(ACT, PID, "knee", strides=2, stride_s=2.4)
    bent = rw.walking(ACT, PID, "knee", strides=2, stride_s=1.2, radius_m=0.2)
    # a transparent loop resists motion by its impedance: half the speed, about half the torque
    assert 0.35 < slow.max_sensor_nm / normal.max_sensor_nm < 0.7
    assert bent.max_sensor_nm > 1.01 * normal.max_sensor_nm
    # the loop holds its estimate at 0 better than the sensor (it does not see the friction)
    assert normal.max_est_nm < normal.max_sensor_nm
    assert normal.rms_sensor_nm < normal.max_sensor_nm


def test_bad_inputs_raise_named_errors() -> None:
    with pytest.raises(rb.BenchError, match="settle_strides"):
        rw.walking(ACT, PID, "hip", strides=1, settle_strides=1)
    with pytest.raises(rb.BenchError, match="whole"):
        rw.walking(ACT, PID, "hip", strides=2.5)  # type: ignore[arg-type]
    with pytest.raises(rb.BenchError, match="bend radius"):
        rw.walking(ACT, PID, "hip", radius_m=-1.0, strides=2)
    with pytest.raises(gait_profile.GaitError, match="stride"):
        rw.walking(ACT, PID, "hip", stride_s=math.inf)
