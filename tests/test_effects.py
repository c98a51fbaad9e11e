"""Constitutive laws, one module each: forces are minus the gradient of their energies, and
dissipative elements dissipate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.plant.effects import bending, conduit_viscoelastic, maxwell_slip, series_stiffness

K = (15.0, -2.86, 12.0, -2.15)  # k_pos, s_pos, k_neg, s_neg of the prototype


@pytest.mark.parametrize("twist", [-0.4, -0.01, 0.01, 0.4])
@pytest.mark.parametrize("bend", [-1.2, 0.3, 1.9])
def test_series_torque_is_energy_gradient(twist: float, bend: float) -> None:
    h = 1e-6
    dv = (
        series_stiffness.potential_j(twist + h, bend, *K)
        - series_stiffness.potential_j(twist - h, bend, *K)
    ) / (2 * h)
    assert series_stiffness.elastic_torque_nm(twist, bend, *K) == pytest.approx(dv, rel=1e-7)
    # the coupling torque on the bend coordinate is -dV/dphi
    dvb = (
        series_stiffness.potential_j(twist, bend + h, *K)
        - series_stiffness.potential_j(twist, bend - h, *K)
    ) / (2 * h)
    assert series_stiffness.bend_coupling_torque_nm(twist, bend, K[1], K[3]) == pytest.approx(
        -dvb, rel=1e-6
    )


def test_series_sides_and_static_twist() -> None:
    # static twist = tau / K on each side (eq. 8)
    for tau, k in ((3.0, K[0]), (-3.0, K[2])):
        twist = tau / k
        assert series_stiffness.elastic_torque_nm(twist, 0.0, *K) == pytest.approx(tau)
    assert series_stiffness.elastic_torque_nm(0.0, 1.0, *K) == 0.0
    # damping (eq. 1) dissipates on both sides
    for twist in (-0.1, 0.1):
        assert series_stiffness.damping_torque_nm(twist, 2.0, 0.1, 0.05) * 2.0 > 0.0


def test_bending_moment_gradient_and_stiffening() -> None:
    kb, beta, h = 4.0, 0.1, 1e-6
    for phi in (-1.5, 0.2, 1.5):
        dv = (bending.potential_j(phi + h, kb, beta) - bending.potential_j(phi - h, kb, beta)) / (
            2 * h
        )
        assert bending.elastic_moment_nm(phi, kb, beta) == pytest.approx(dv, rel=1e-7)
    # stiffens at large bends: secant stiffness grows with bend
    sec = [bending.elastic_moment_nm(p, kb, beta) / p for p in (0.2, 0.8, 1.6)]
    assert sec[0] < sec[1] < sec[2]


def _loop_area(x: np.ndarray, y: np.ndarray) -> float:
    """Work done on the element over a closed path: integral of y dx."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


@pytest.mark.parametrize("freq", [0.2, 1.0, 5.0])
def test_conduit_loop_dissipates_and_depends_on_rate(freq: float) -> None:
    k, tau = 2.0, 0.15
    t = np.linspace(0.0, 3.0 / freq, 30001)
    phi = 1.0 * np.sin(2 * math.pi * freq * t)
    z = np.zeros_like(t)
    for i in range(1, len(t)):
        z[i] = z[i - 1] + (t[i] - t[i - 1]) * conduit_viscoelastic.branch_rate(
            phi[i - 1], z[i - 1], tau
        )
    m = np.array(
        [conduit_viscoelastic.branch_moment_nm(p, zz, k) for p, zz in zip(phi, z, strict=True)]
    )
    last = t >= t[-1] - 1.0 / freq
    area = _loop_area(phi[last], m[last])
    assert area > 0.0
    # rate dependence: the analytic loop area of one Maxwell branch at amplitude 1
    w = 2 * math.pi * freq
    expected = math.pi * k * (w * tau) / (1.0 + (w * tau) ** 2)
    assert area == pytest.approx(expected, rel=0.02)


def test_maxwell_slip_is_rate_independent_and_dissipative() -> None:
    k, f = 10.0, 0.3
    zmax = maxwell_slip.slip_limit_rad(k, f)
    areas = []
    for freq in (0.1, 2.0):
        t = np.linspace(0.0, 2.0 / freq, 40001)
        x = 0.2 * np.sin(2 * math.pi * freq * t)
        z = np.zeros_like(t)
        for i in range(1, len(t)):
            z[i] = np.clip(
                z[i - 1] + (x[i] - x[i - 1]) * maxwell_slip.element_rate(1.0), -zmax, zmax
            )
        tau = maxwell_slip.element_torque_nm(z, k)
        last = t >= t[-1] - 1.0 / freq
        areas.append(_loop_area(x[last], tau[last]))
    assert areas[0] > 0.0
    assert areas[0] == pytest.approx(areas[1], rel=1e-3)
    # elasto-slip loop: 4 f (A - zmax) per cycle
    assert areas[0] == pytest.approx(4 * f * (0.2 - zmax), rel=1e-2)
    assert maxwell_slip.slip_limit_rad(0.0, 1.0) == 0.0
