"""Torque-loop bandwidth vs bend and output impedance (seed 001 Sec. 4.1.2, 4.2)."""

from __future__ import annotations

import math

import pytest

from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies.arm_metrics import torque_bandwidth
from fsarm_sim.studies.transparency import output_impedance

# the shaft's eq. 8 law alone: these tests are about its stiffness and the loop around it
ELASTIC = load_catalogue().shaft(series_hysteresis=False)


def test_fixed_gains_lose_bandwidth_with_bend_scheduled_gains_do_not() -> None:
    """Seed 001's trend (6.22 Hz straight -> ~4.3 Hz bent, fixed PID): the bent shaft is softer,
    so fixed gains slow the loop; gains scheduled on the stiffness keep it."""
    fixed = SimConfig(shaft=ELASTIC, gains=Gains(gain_schedule=False))
    sched = SimConfig(shaft=ELASTIC)
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
    cfg = SimConfig(shaft=ELASTIC)
    z = output_impedance(cfg, backend="native", duration_s=4.0)
    assert z.passive_nm_per_rad > 500.0  # eq. 8 K x i_G2^2 at 45 deg bend
    assert z.low_freq_nm_per_rad < 0.01 * z.passive_nm_per_rad
    assert z.magnitude_nm_per_rad[-1] > z.magnitude_nm_per_rad[0]  # less transparent fast
    free = output_impedance(cfg, backend="native", duration_s=4.0, control=False)
    ratio = free.magnitude_nm_per_rad[3] / free.magnitude_nm_per_rad[0]
    f_ratio = free.freq_hz[3] / free.freq_hz[0]
    assert ratio == pytest.approx(f_ratio**2, rel=0.35)  # inertia: |Z| ~ J w^2


def test_internal_friction_growing_with_bend_makes_the_joint_less_transparent() -> None:
    """Seed 001 Sec. 6: bending the shaft lowers the torque bandwidth (fixed gains) and raises
    the output impedance. The default shaft's internal friction (Maxwell-slip elements whose slip
    torque grows with the bend, effects.bend_friction) is invisible to the virtual torque sensor,
    so the loop cannot cancel it: the bent joint feels more of it."""
    cfg = SimConfig()
    assert cfg.shaft.bend_friction_per_rad > 0.0 and max(cfg.shaft.slip_k) > 0.0
    # seed 001's bends: R = 450/300/150 mm over its 255 mm bent length, 32-97 deg
    bends = (0.0, 45.0, 90.0)
    z = [output_impedance(cfg, math.radians(b), backend="native", duration_s=4.0) for b in bends]
    low = [zi.low_freq_nm_per_rad for zi in z]
    assert low[0] < low[1] < low[2] and low[2] > 1.5 * low[0]
    elastic = output_impedance(SimConfig(shaft=ELASTIC), backend="native", duration_s=4.0)
    assert elastic.low_freq_nm_per_rad < 0.05 * low[1]  # the friction is what the joint feels
    fixed = SimConfig(gains=Gains(gain_schedule=False))
    bw = [
        torque_bandwidth(fixed, math.radians(b), backend="native", chirp_s=3.0).bandwidth_hz
        for b in (0.0, 90.0)
    ]
    assert bw[1] < 0.95 * bw[0]  # the trend; seed 001 number-to-number needs its own cascade


@pytest.mark.parametrize(
    "kwargs",
    [{"amplitude_rad": 0.5}, {"f_start_hz": 5.0, "f_stop_hz": 1.0}, {"duration_s": -1.0}],
)
def test_bad_impedance_requests_are_named_errors(kwargs: dict[str, float]) -> None:
    with pytest.raises(InvalidParameterError):
        output_impedance(SimConfig(), **kwargs)  # type: ignore[arg-type]


def test_bend_note_says_where_the_rtca_holds_mu_flat() -> None:
    """The RTCA's mu is held beyond L_bend / R_mu (58.4°): a table reaching past it says so;
    one that does not, and a transmission without such a hold, say nothing."""
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.plant.transmissions import rtca
    from fsarm_sim.studies.transparency import bend_note

    assert math.degrees(rtca.bend_held_from_rad()) == pytest.approx(58.44, abs=0.01)
    assert rtca.mu(rtca.bend_held_from_rad(), 1.0) == pytest.approx(rtca.mu(2.0, 1.0))
    assert rtca.mu(0.5 * rtca.bend_held_from_rad(), 1.0) > rtca.mu(2.0, 1.0)
    note = bend_note(SimConfig(transmission="rtca"), (0.0, 30.0, 60.0, 90.0))
    assert "58.4°" in note and "60, 90°" in note
    assert bend_note(SimConfig(transmission="rtca"), (0.0, 30.0)) == ""
    assert bend_note(SimConfig(), (0.0, 90.0)) == ""
