"""Torque-loop bandwidth vs bend and output impedance (seed 001 Sec. 4.1.2, 4.2)."""

from __future__ import annotations

import math

import pytest

from fsarm_sim.arm_metrics import torque_bandwidth
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.model import Gains, SimConfig
from fsarm_sim.transparency import output_impedance


def test_fixed_gains_lose_bandwidth_with_bend_scheduled_gains_do_not() -> None:
    """Seed 001's trend (6.22 Hz straight -> ~4.3 Hz bent, fixed PID): the bent shaft is softer,
    so fixed gains slow the loop; gains scheduled on the stiffness keep it."""
    fixed = SimConfig(gains=Gains(gain_schedule=False))
    sched = SimConfig()
    bw = {
        (name, b): torque_bandwidth(
            cfg, math.radians(b), backend="native", chirp_s=3.0
        ).bandwidth_hz
        for name, cfg in (("fixed", fixed), ("sched", sched))
        for b in (0.0, 120.0)
    }
    assert bw["fixed", 0.0] == pytest.approx(bw["sched", 0.0], rel=1e-3)  # same gains straight
    assert bw["fixed", 120.0] < 0.8 * bw["fixed", 0.0]
    assert bw["sched", 120.0] == pytest.approx(bw["sched", 0.0], rel=0.1)


def test_torque_loop_makes_the_joint_transparent() -> None:
    """With zero commanded torque the joint feels a small fraction of the shaft's stiffness at
    low frequency; with the motor unpowered, only the rotor's inertia (rising as f^2)."""
    cfg = SimConfig()
    z = output_impedance(cfg, backend="native", duration_s=4.0)
    assert z.passive_nm_per_rad > 500.0  # eq. 8 K x i_G2^2 at 45 deg bend
    assert z.low_freq_nm_per_rad < 0.01 * z.passive_nm_per_rad
    assert z.magnitude_nm_per_rad[-1] > z.magnitude_nm_per_rad[0]  # less transparent fast
    free = output_impedance(cfg, backend="native", duration_s=4.0, control=False)
    ratio = free.magnitude_nm_per_rad[3] / free.magnitude_nm_per_rad[0]
    f_ratio = free.freq_hz[3] / free.freq_hz[0]
    assert ratio == pytest.approx(f_ratio**2, rel=0.35)  # inertia: |Z| ~ J w^2


@pytest.mark.parametrize(
    "kwargs",
    [{"amplitude_rad": 0.5}, {"f_start_hz": 5.0, "f_stop_hz": 1.0}, {"duration_s": -1.0}],
)
def test_bad_impedance_requests_are_named_errors(kwargs: dict[str, float]) -> None:
    with pytest.raises(InvalidParameterError):
        output_impedance(SimConfig(), **kwargs)  # type: ignore[arg-type]
