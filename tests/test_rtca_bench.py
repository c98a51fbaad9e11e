"""Seed 001's actuator on its single-joint bench (fsarm_sim.studies.rtca_bench)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.transmissions import rtca
from fsarm_sim.studies import rtca_bench as rb

ACT = rb.Rtca001()
KP = 8.5  # about the bench's calibrated P gain (calibrate_kp at the defaults)


def _steps(seconds: float) -> int:
    return round(seconds / ACT.ctrl_dt_s)


def test_bad_inputs_raise_named_errors() -> None:
    td = np.zeros(_steps(0.1))
    with pytest.raises(rb.BenchError, match="bend radius"):
        rb.run(ACT, rb.Pid(1.0, 0.0, 0.0), td, radius_m=0.0)
    with pytest.raises(rb.BenchError, match="kp"):
        rb.run(ACT, rb.Pid(-1.0, 0.0, 0.0), td)
    with pytest.raises(rb.BenchError, match="finite"):
        rb.run(ACT, rb.Pid(1.0, 0.0, 0.0), np.full(10, math.nan))
    with pytest.raises(rb.BenchError, match="theta_s"):
        rb.run(ACT, rb.Pid(1.0, 0.0, 0.0), td, theta_s=np.zeros(3))
    with pytest.raises(rb.BenchError, match="bend_rad"):
        rb.run(ACT, rb.Pid(1.0, 0.0, 0.0), td, bend_rad=np.full(td.size, -0.1))
    with pytest.raises(rb.BenchError, match="quadrature"):
        rb.with_(ACT, quadrature=3)
    with pytest.raises(rb.BenchError, match="velocity_bw_hz"):
        rb.with_(ACT, velocity_bw_hz=400.0)
    with pytest.raises(FsarmError):
        rb.tracking(ACT, rb.Pid(1.0, 0.0, 0.0), amplitude_nm=20.0)
    with pytest.raises(rb.BenchError, match="target offset"):
        rb.calibrate_kp(ACT, math.nan)
    with pytest.raises(rb.BenchError, match="no P gain"):
        rb.calibrate_kp(ACT, 1.0)  # faster than the loop's delays allow


def test_estimate_is_the_law_at_quantised_encoder_twist() -> None:
    td = np.full(_steps(1.0), 3.0)
    r = rb.run(ACT, rb.Pid(KP, 0.0, 0.0), td)
    q = 2.0 * math.pi / (ACT.shaft_cpt * ACT.quadrature)
    tr = np.asarray(ACT.block)
    counts = np.floor(r.theta_m / q)  # theta_s = 0 (blocked output)
    expected = [rtca.sensor_torque_nm(tr, float(c * q), 0.0) for c in counts]
    np.testing.assert_allclose(r.tau_est, expected, atol=1e-12)
    # a P loop on a velocity-sourced motor settles on the set-point (an integrator in the loop)
    assert abs(float(np.mean(r.tau_est[-200:])) - 3.0) < 0.02


def test_speed_limit_of_the_motor_holds() -> None:
    t = np.arange(_steps(2.0)) * ACT.ctrl_dt_s
    td = 6.0 * np.sign(np.sin(2.0 * math.pi * 2.0 * t))  # a square wave: saturates the loop
    r = rb.run(ACT, rb.Pid(50.0, 0.0, 0.0), td)
    assert r.saturated > 0.1
    assert np.max(np.abs(r.omega_cmd)) <= ACT.speed_limit_rad_s + 1e-12
    speed = np.abs(np.diff(r.theta_m)) / ACT.ctrl_dt_s
    assert np.max(speed) < 1.1 * ACT.speed_limit_rad_s


def test_tracking_lag_shrinks_with_gain_and_residual_sets_the_estimate_error() -> None:
    slow = rb.tracking(ACT, rb.Pid(KP, 0.0, 0.0), periods=2)
    fast = rb.tracking(ACT, rb.Pid(3.0 * KP, 0.0, 0.0), periods=2)
    assert 15.0 < slow.offset_ms < 40.0  # near the paper's 25 ms (the gain was set for it)
    assert fast.offset_ms < 0.6 * slow.offset_ms
    assert fast.rmse_nm < slow.rmse_nm
    ideal = rb.tracking(rb.with_(ACT, residual_friction=False), rb.Pid(KP, 0.0, 0.0), periods=2)
    # without the shaft's unmodelled residual only the encoders' quantisation is left
    assert ideal.estimate_error_nm < 0.4 * slow.estimate_error_nm
    assert slow.estimate_error_nm == pytest.approx(ACT.residual_nm(math.inf), rel=0.6)


def test_residual_grows_with_bend_between_the_published_points() -> None:
    a_straight = ACT.residual_nm(math.inf)
    assert a_straight == pytest.approx(rb.NRMSE_STRAIGHT * 10.0)
    assert ACT.residual_nm(0.150) == pytest.approx(rb.NRMSE_R150 * 10.0)
    assert ACT.residual_nm(0.100) == ACT.residual_nm(0.150)  # held beyond the tightest bend
    assert a_straight < ACT.residual_nm(0.450) < ACT.residual_nm(0.300) < ACT.residual_nm(0.150)


def test_calibration_hits_its_offset() -> None:
    kp = rb.calibrate_kp(ACT, 40.0)
    assert rb.tracking(ACT, rb.Pid(kp, 0.0, 0.0), periods=2).offset_ms == pytest.approx(
        40.0, abs=1.0
    )


def test_second_order_fit_recovers_a_known_transfer_function() -> None:
    w = 2.0 * math.pi * np.linspace(0.1, 10.0, 100)
    b1, b0, a1, a0 = 3.0, 900.0, 40.0, 1000.0
    h = ((b1 * 1j * w + b0) / ((1j * w) ** 2 + a1 * 1j * w + a0)).astype(np.complex128)
    coef, fit = rb.fit_second_order(w, h)
    np.testing.assert_allclose(coef, (b1, b0, a1, a0), rtol=1e-6)
    assert fit > 99.9


def test_bandwidth_falls_with_bend_at_fixed_gain() -> None:
    pid = rb.Pid(KP, 0.0, 0.0)
    straight = rb.torque_bandwidth(ACT, pid, realizations=1)
    bent = rb.torque_bandwidth(ACT, pid, radius_m=0.150, realizations=1)
    assert 2.0 < straight.bandwidth_hz < 10.0
    assert bent.bandwidth_hz < 0.95 * straight.bandwidth_hz


def test_impedance_of_a_p_loop_is_its_inverse_gain_and_a_pi_loop_peaks_lower_when_bent() -> None:
    z = rb.output_impedance(ACT, rb.Pid(KP, 0.0, 0.0), duration_s=30.0)
    # the bands begin where the analysed sweep begins (after the fade-in of 1/f_lo = 10 s the
    # log sweep 0.1 -> 10 Hz over 30 s is at 0.1 * 100^(10/30) = 0.46 Hz): no band of leakage
    assert z.freq_hz[0] >= 0.1 * 100.0 ** (10.0 / 30.0)
    mid = (z.freq_hz > 0.5) & (z.freq_hz < 1.5)
    np.testing.assert_allclose(z.magnitude[mid], 1.0 / KP, rtol=0.2)  # T = -θ̇_s / Kp
    # ... and 1/Kp down to the lowest band (the estimate's quantisation aside)
    assert z.magnitude[0] == pytest.approx(1.0 / KP, rel=0.2)
    pi = rb.Pid(7.4, 3.0 * 7.4, 0.0)
    straight = rb.output_impedance(ACT, pi, duration_s=30.0)
    bent = rb.output_impedance(ACT, pi, radius_m=0.200, duration_s=30.0)
    assert bent.peak_hz < straight.peak_hz  # sqrt(mu K Ki) falls with mu


def test_ziegler_nichols_table() -> None:
    zn = rb.ziegler_nichols(ACT)
    assert 5.0 < zn.ultimate_gain < 500.0 and 0.005 < zn.ultimate_period_s < 1.0
    assert zn.pid.kp == pytest.approx(0.6 * zn.ultimate_gain)
    assert zn.pid.ki == pytest.approx(zn.pid.kp / (zn.ultimate_period_s / 2.0))
    assert zn.pid.kd == pytest.approx(zn.pid.kp * zn.ultimate_period_s / 8.0)


def test_bench_friction_is_the_transmissions_bend_friction_element() -> None:
    from fsarm_sim.plant.effects import bend_friction
    from fsarm_sim.plant.transmissions import rtca

    assert ACT.residual_nm(math.inf) == pytest.approx(rtca.SLIP_F_NM)
    phi = 0.255 / 0.300  # R = 300 mm on the 255 mm bend
    g = bend_friction.factor(phi, rtca.BEND_FRICTION_PER_RAD)
    assert ACT.residual_nm(0.300) == pytest.approx(rtca.SLIP_F_NM * g)
    off = rb.with_(ACT, residual_friction=False)
    assert off.residual_nm(0.300) == 0.0
    assert off.shaft_block()[rtca.I_SLIP_F] == 0.0


def test_estimate_based_impedance_does_not_see_the_shaft_friction_the_load_feels() -> None:
    """Seed 001's Z = T̂/θ̇_s reads the twist, which the velocity-sourced motor sets: the shaft's
    bend friction changes it by < 1 %, while the torque the load feels (the sensor) rises."""
    pid = rb.Pid(8.5, 0.0, 0.0)
    kw = {"radius_m": 0.2, "f_lo": 0.5, "f_hi": 5.0, "duration_s": 12.0}
    on = rb.output_impedance(ACT, pid, **kw)
    off = rb.output_impedance(rb.with_(ACT, residual_friction=False), pid, **kw)
    assert on.level == pytest.approx(off.level, rel=0.01)
    assert on.interaction_rms_nm > 1.1 * off.interaction_rms_nm


def test_on_slow_motion_the_load_feels_the_bend_friction_the_estimate_does_not() -> None:
    """Sec. 4.2.2: 'as the bend radius was reduced, the interaction torques increased' (the
    torque sensor); on a slow stand-in motion the felt torque rises with bend, T̂ does not."""
    pid = rb.Pid(8.5, 0.0, 0.0)
    straight = rb.interaction(ACT, pid, periods=2)
    bent = rb.interaction(ACT, pid, radius_m=0.2, periods=2)
    assert bent.felt_rms_nm > 1.05 * straight.felt_rms_nm
    assert bent.estimate_rms_nm <= straight.estimate_rms_nm
    for bad in ({"amplitude_rad": 0.0}, {"period_s": math.nan}, {"periods": 1}):
        with pytest.raises(rb.BenchError):
            rb.interaction(ACT, pid, **bad)


ZN_LIKE = rb.Pid(34.6, 961.0, 0.312)  # about the bench's Ziegler-Nichols PID at the defaults


def test_set_point_delay_adds_to_the_lag_one_for_one() -> None:
    """Sec. 4.1.1's 25 ms: outside the loop, the delay shifts both torques alike."""
    own = rb.tracking(ACT, ZN_LIKE, periods=2)
    delay = rb.calibrate_reference_delay(ACT, ZN_LIKE, 25.0)
    assert delay == pytest.approx(0.025 - own.offset_ms / 1000.0, abs=0.001)
    late = rb.tracking(rb.with_(ACT, reference_delay_s=delay), ZN_LIKE, periods=2)
    assert late.offset_ms == pytest.approx(25.0, abs=1.0)
    # the estimate and the sensor still agree (the paper: 0.0456 N*m while lagging 25 ms)
    assert late.estimate_error_nm == pytest.approx(own.estimate_error_nm, rel=0.3)
    # a pure 25 ms lag of 6 N*m at 1 Hz alone: 6 sqrt(2) sin(pi 0.025) = 0.666 N*m RMSE
    assert late.rmse_nm > 0.9 * 6.0 * math.sqrt(2.0) * math.sin(math.pi * 0.025)
    with pytest.raises(rb.BenchError, match="target offset"):
        rb.calibrate_reference_delay(ACT, ZN_LIKE, math.nan)
    with pytest.raises(rb.BenchError, match="reference_delay_s"):
        rb.with_(ACT, reference_delay_s=-0.01)


def test_transport_delay_is_dead_time_in_the_loop() -> None:
    assert ACT.delay_cycles == ACT.bus_delay_cycles
    assert rb.with_(ACT, transport_delay_s=0.010).delay_cycles == ACT.bus_delay_cycles + 10


def test_load_servo_follows_slow_motion_and_keeps_its_speed_limit() -> None:
    load = rb.LoadServo()
    assert load.speed_limit_rad_s == pytest.approx(7000.0 * 2.0 * math.pi / 60.0 / 113.0)
    dt = ACT.ctrl_dt_s
    t = np.arange(_steps(2.0)) * dt
    amp = math.radians(20.0)
    fast = rb.load_motion(load, amp * np.sin(2.0 * math.pi * 10.0 * t), dt)
    assert np.max(np.abs(np.diff(fast))) / dt <= load.speed_limit_rad_s + 1e-9
    slow_ref = amp * np.sin(2.0 * math.pi * 0.2 * t)
    slow = rb.load_motion(load, slow_ref, dt)
    assert np.max(np.abs(slow - slow_ref)) < 0.01 * amp
    assert rb.load_motion(None, slow_ref, dt) is not None
    with pytest.raises(rb.BenchError, match="motor_speed_rpm"):
        rb.load_motion(rb.LoadServo(motor_speed_rpm=0.0), slow_ref, dt)


def test_fig12_p_loop_falls_with_frequency_and_the_pid_rises() -> None:
    """Fig. 12 obs. 2 needs integral action: with a P loop T̂/θ̇_s = μK/(s + μK Kp) falls."""
    fig = rb.fig12(
        ACT,
        {"P": rb.Pid(KP, 0.0, 0.0), "PID": ZN_LIKE},
        (math.inf,),
        duration_s=12.0,
        f_lo=0.5,
        f_hi=5.0,
    )
    p, pid = fig.by("P")[0], fig.by("PID")[0]
    np.testing.assert_array_equal(p.freq_hz, pid.freq_hz)
    assert p.magnitude[-1] < p.magnitude[0]
    assert pid.magnitude[-1] > 2.0 * pid.magnitude[0]
    assert "PID straight" in fig.table()
    with pytest.raises(rb.BenchError, match="per_decade"):
        rb.output_impedance(ACT, ZN_LIKE, per_decade=1)


def test_core_friction_is_felt_by_the_load_and_not_read_by_the_estimate() -> None:
    core = rb.with_(ACT, friction_site="core")
    straight = rb.interaction(core, ZN_LIKE, periods=2)
    bent = rb.interaction(core, ZN_LIKE, radius_m=0.2, periods=2)
    assert bent.felt_rms_nm > 1.3 * straight.felt_rms_nm
    assert bent.estimate_rms_nm == pytest.approx(straight.estimate_rms_nm, rel=0.1)
    with pytest.raises(rb.BenchError, match="friction_site"):
        rb.with_(ACT, friction_site="casing")


def test_fig12_rise_below_peak_reads_the_bands_below_every_bends_peak() -> None:
    f = np.array([0.5, 1.0, 2.0, 4.0, 8.0])

    def row(r: float, mag: list[float], peak: float) -> rb.Fig12Row:
        return rb.Fig12Row("PID", r, f, np.array(mag), peak, 0.0)

    fig = rb.Fig12(
        (
            row(math.inf, [1.0, 2.0, 3.0, 9.0, 4.0], 4.0),
            row(0.2, [1.1, 2.2, 3.3, 8.0, 5.0], 3.0),
        )
    )
    bands = fig.rise_below_peak("PID")
    assert list(bands) == ["0.5 Hz", "1 Hz", "2 Hz"]  # below the lower (bent) peak only
    assert bands["2 Hz"] == [3.0, 3.3]
    np.testing.assert_array_equal(fig.rows[0].side(below=False), [4])


def test_a_bend_per_cycle_is_the_bend_of_its_radius_and_moves_the_estimate() -> None:
    td = 3.0 * np.sin(2.0 * math.pi * np.arange(_steps(0.3)) * ACT.ctrl_dt_s)
    pid = rb.Pid(KP, 0.0, 0.0)
    bend = rb.bend_of(0.300, ACT.shaft_block())
    held = rb.run(ACT, pid, td, radius_m=0.300)
    per_cycle = rb.run(ACT, pid, td, bend_rad=np.full(td.size, bend))
    np.testing.assert_array_equal(held.tau_est, per_cycle.tau_est)
    # the knee bending halfway through: the first half as straight, the second as bent
    half = np.where(np.arange(td.size) < td.size // 2, 0.0, bend)
    moving = rb.run(ACT, pid, td, bend_rad=half)
    straight = rb.run(ACT, pid, td)
    k = td.size // 2
    np.testing.assert_array_equal(moving.tau_est[:k], straight.tau_est[:k])
    assert not np.array_equal(moving.tau_est[k:], straight.tau_est[k:])


def test_core_segments_split_the_friction_and_the_estimate_does_not_read_it() -> None:
    # the load moves the output slowly at a 0 N*m set-point: the core's friction against its
    # casing, split over 1 or 3 joints, is felt at the output; T̂ (the twist end to end) is set
    # by the loop and the motion, the same wherever the friction sits
    t = np.arange(_steps(1.2)) * ACT.ctrl_dt_s
    out = 0.3 * np.sin(2.0 * math.pi * t / 1.2)
    pid = rb.Pid(kp=34.6, ki=961.0, kd=0.31)
    twist = rb.run(ACT, pid, np.zeros(t.size), radius_m=0.2, theta_s=out)
    runs = [
        rb.run(
            rb.with_(ACT, friction_site="core", core_segments=n, substeps=s),
            pid,
            np.zeros(t.size),
            radius_m=0.2,
            theta_s=out,
        )
        for n, s in ((2, 5), (4, 20))
    ]
    for r in runs:
        np.testing.assert_allclose(r.tau_est, twist.tau_est, atol=2e-3)
        assert float(np.max(np.abs(r.tau_sensor))) > 1.5 * float(np.max(np.abs(r.tau_est)))


def test_a_diverging_core_is_a_named_error() -> None:
    act = rb.with_(ACT, friction_site="core", core_segments=8, substeps=1)
    t = np.arange(_steps(0.3)) * ACT.ctrl_dt_s
    with pytest.raises(rb.BenchError, match="diverged"):
        rb.run(act, rb.Pid(34.6, 961.0, 0.31), np.zeros(t.size), theta_s=0.3 * np.sin(5.0 * t))
    with pytest.raises(rb.BenchError, match="core_segments"):
        rb.with_(ACT, core_segments=1)
