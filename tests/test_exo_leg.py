"""Seed 001's exoskeleton leg (fsarm_sim.studies.exo_leg): inverse dynamics of point masses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.studies import exo_leg as el
from fsarm_sim.studies import gait_profile as gp


def _energy(
    masses: tuple[el.PointMass, ...], q1: np.ndarray, q2: np.ndarray, w1: np.ndarray, w2: np.ndarray
) -> np.ndarray:
    """Kinetic + potential energy of the point masses (hip fixed at the origin)."""
    e = np.zeros_like(q1)
    phi, wphi = q1 - q2, w1 - w2
    for m, link, d in masses:
        if link == "thigh":
            vx, vy = d * w1 * np.cos(q1), d * w1 * np.sin(q1)
            y = -d * np.cos(q1)
        else:
            vx = el.THIGH_M * w1 * np.cos(q1) + d * wphi * np.cos(phi)
            vy = el.THIGH_M * w1 * np.sin(q1) + d * wphi * np.sin(phi)
            y = -el.THIGH_M * np.cos(q1) - d * np.cos(phi)
        e += 0.5 * m * (vx**2 + vy**2) + m * el.GRAVITY * y
    return e


@pytest.mark.parametrize("masses", [el.RTCA_MASSES, el.INLINE_MASSES])
def test_joint_power_is_the_rate_of_the_masses_energy(masses: tuple[el.PointMass, ...]) -> None:
    hip, knee = gp.fourier_fit("hip"), gp.fourier_fit("knee")
    t = np.linspace(0.0, gp.STRIDE_S, 2401)
    q1, q2, w1, w2 = hip.eval(t), knee.eval(t), hip.eval(t, 1), knee.eval(t, 1)
    tau = el.walking_torques(masses, samples=2400)
    tq = el.joint_torques(
        masses,
        q1,
        q2,
        t,
        hip_rate=w1,
        knee_rate=w2,
        hip_acc=hip.eval(t, 2),
        knee_acc=knee.eval(t, 2),
    )
    np.testing.assert_allclose(tq.hip_nm[:-1], tau.hip_nm, atol=1e-9)
    power = tq.hip_nm * w1 + tq.knee_nm * w2
    de_dt = np.gradient(_energy(masses, q1, q2, w1, w2), t)
    assert float(np.max(np.abs(power - de_dt)[5:-5])) < 1e-3 * float(np.max(np.abs(power)))


def test_static_torques_are_the_weights_moments() -> None:
    q1, q2 = np.array([0.4]), np.array([0.9])
    z = np.zeros(1)
    tq = el.joint_torques(
        el.INLINE_MASSES, q1, q2, z, hip_rate=z, knee_rate=z, hip_acc=z, knee_acc=z
    )
    x_knee = el.THIGH_M * math.sin(0.4)
    x_ankle = x_knee + el.SHANK_M * math.sin(0.4 - 0.9)
    assert tq.hip_nm[0] == pytest.approx(el.GRAVITY * x_ankle, rel=1e-12)
    # the knee holds the foot's moment about itself (flexion +: the foot behind the knee)
    assert tq.knee_nm[0] == pytest.approx(-el.GRAVITY * (x_ankle - x_knee), rel=1e-12)


def test_knee_carries_only_the_shank_masses() -> None:
    thigh_only = el.walking_torques(((2.0, "thigh", 0.3),))
    assert float(np.max(np.abs(thigh_only.knee_nm))) == 0.0
    assert float(np.max(np.abs(thigh_only.hip_nm))) > 0.5
    red = el.reductions(el.RTCA_MASSES_THIGH_SIDE)
    assert red["knee"].percent("peak") == pytest.approx(100.0)


def test_lighter_and_closer_masses_need_less_torque() -> None:
    red = el.reductions()
    for joint in ("hip", "knee"):
        assert red[joint].percent("peak") > 0.0
    heavy = el.reductions(((1.4, "thigh", 0.1), (2.2, "shank", 0.1)))
    assert heavy["knee"].percent("peak") < red["knee"].percent("peak")


def test_bad_inputs_raise_named_errors() -> None:
    with pytest.raises(gp.GaitError, match="link"):
        el.walking_torques(((1.0, "foot", 0.1),))
    with pytest.raises(gp.GaitError, match="distance"):
        el.walking_torques(((1.0, "shank", 0.5),))
    with pytest.raises(gp.GaitError, match="samples"):
        el.walking_torques(el.RTCA_MASSES, samples=3)
    with pytest.raises(gp.GaitError, match="joint"):
        el.walking_torques(el.RTCA_MASSES).peaks("ankle")
    with pytest.raises(gp.GaitError, match="which"):
        el.reductions()["hip"].percent("both")
