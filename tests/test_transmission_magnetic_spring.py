"""Magnetic-spring transmission (seed 003): published ranges, eq. 2, kernel invariants, interface."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from fsarm_sim.plant.transmissions import magnetic_spring as ms
from fsarm_sim.plant.transmissions.base import N_STATES, Transmission, TransmissionError

from conftest import check_free_oscillation

ACT = np.zeros(N_STATES)
TR = ms.default_block()
DEG = math.pi / 180.0


def _eq1(tr: np.ndarray, phi_r_deg: float) -> float:
    """Eq. 1 exactly as printed (phi_r in degrees), torque on the output ring."""
    d = tr[ms.I_D]
    p = 1 + tr[ms.I_A1] * d + tr[ms.I_A2] * d**2 + tr[ms.I_A3] * d**3 + tr[ms.I_A4] * d**4
    return -p * (
        tr[ms.I_B1] * math.sin(math.pi / 60 * phi_r_deg)
        + tr[ms.I_B2] * math.sin(math.pi / 30 * phi_r_deg)
        + tr[ms.I_B3] * math.sin(math.pi / 15 * phi_r_deg)
    )


# ------------------------------------------------------------------ published numbers


def test_kernel_is_eq1_with_phi_r_equal_minus_twist() -> None:
    """theta_s - theta_m = phi_r = -x: the torque on the output is eq. 1 at -x (deg)."""
    tr = ms.default_block({"d": 0.006})
    for x in (-0.9, -0.3, 0.05, 0.4, 1.7):
        assert ms.sensor_torque_nm(tr, x, 0.0) == pytest.approx(_eq1(tr, -x / DEG), rel=1e-12)


@pytest.mark.parametrize("d", [0.0, 0.004, 0.012])
def test_stable_range_is_31_5_deg_with_maximal_torque_and_zero_stiffness(d: float) -> None:
    """Sec. 7.1 / Fig. 17: stable range +-31.5 deg at d = 0; the product form keeps it for any d."""
    x_s = ms.stable_range_rad(d)
    assert x_s / DEG == pytest.approx(31.5, abs=0.02)
    tr = ms.default_block({"d": d})
    assert ms.stiffness_nm_per_rad(tr, x_s, 0.0) == pytest.approx(0.0, abs=1e-9)
    peak = ms.sensor_torque_nm(tr, x_s, 0.0)
    assert peak == pytest.approx(ms.max_torque_nm(d))
    for x in np.linspace(-1.0, 1.0, 2001):  # the largest torque anywhere (one period and more)
        assert abs(ms.sensor_torque_nm(tr, float(x), 0.0)) <= peak * (1 + 1e-12)
    # stable (positive stiffness) inside, negative stiffness beyond, up to the unstable point
    for deg in np.linspace(-31.0, 31.0, 125):
        assert ms.stiffness_nm_per_rad(tr, deg * DEG, 0.0) > 0.0
    for deg in np.linspace(32.0, 88.0, 113):
        assert ms.stiffness_nm_per_rad(tr, deg * DEG, 0.0) < 0.0
        assert ms.stiffness_nm_per_rad(tr, -deg * DEG, 0.0) < 0.0


def test_linear_range_is_19_7_deg_and_the_pure_sine_gives_the_theoretical_30_deg() -> None:
    """Sec. 7.1: linear range 19.7 deg (66 % of 30 deg); stable 31.5 deg = 105 % of the
    theoretical 30 deg of a sinusoid, whose linear range is 10.5 deg (arc spring [42]: ~11 deg)."""
    assert ms.linear_range_rad(0.0) / DEG == pytest.approx(19.7, abs=0.02)
    assert ms.stable_range_rad(0.0) / 30.0 / DEG == pytest.approx(1.05, abs=1e-3)
    assert ms.linear_range_rad(0.0) / 30.0 / DEG == pytest.approx(0.66, abs=5e-3)
    sine = ms.default_block({"b2": 0.0, "b3": 0.0})
    assert ms.stable_range_rad(0.0, sine) / DEG == pytest.approx(30.0, abs=1e-6)
    assert ms.linear_range_rad(0.0, sine) / DEG == pytest.approx(10.54, abs=0.01)
    # inside the linear range torque stays within 5 % of k_sp x, just beyond it does not
    k0 = ms.stiffness_at_equilibrium(0.0)
    x_lin = ms.linear_range_rad(0.0)
    for x in np.linspace(1e-4, x_lin, 200):
        assert abs(ms.sensor_torque_nm(TR, float(x), 0.0) - k0 * x) <= 0.05 * k0 * x + 1e-12
    x_out = x_lin + 0.5 * DEG
    assert abs(ms.sensor_torque_nm(TR, x_out, 0.0) - k0 * x_out) > 0.05 * k0 * x_out


def test_stiffness_in_stable_equilibrium_is_eq2() -> None:
    """Eq. 2: k_sp(d) = (b1 pi/60 + b2 pi/30 + b3 pi/15) P(d), per degree -> per rad."""
    for d in (0.0, 0.005, 0.015):
        tr = ms.default_block({"d": d})
        per_deg = (
            tr[ms.I_B1] * math.pi / 60 + tr[ms.I_B2] * math.pi / 30 + tr[ms.I_B3] * math.pi / 15
        ) * (1 + tr[ms.I_A1] * d)
        assert ms.stiffness_at_equilibrium(d) == pytest.approx(per_deg / DEG, rel=1e-12)
        assert ms.stiffness_nm_per_rad(tr, 0.0, 0.0) == pytest.approx(per_deg / DEG, rel=1e-12)
    assert ms.stiffness_at_equilibrium(0.0) == pytest.approx(2.4816, abs=1e-3)


def test_ring_distance_lowers_stiffness_down_to_decoupling() -> None:
    """Sec. 2: moving the rings apart lowers the stiffness; fully apart is zero stiffness."""
    ks = [ms.stiffness_at_equilibrium(float(d)) for d in np.linspace(0.0, 0.019, 20)]
    assert all(b < a for a, b in itertools.pairwise(ks))
    assert ms.decoupling_distance_m() == pytest.approx(0.020, abs=1e-5)
    with pytest.raises(ms.MagneticSpringParamError, match="decouples"):
        ms.default_block({"d": 0.025})
    with pytest.raises(ms.MagneticSpringParamError, match=">= 0"):
        ms.stable_range_rad(-0.001)


def test_three_stable_equilibria_per_turn_and_odd_torque() -> None:
    """Sec. 6.1 'all three stable equilibria': a 120 deg period; the law is odd in the twist."""
    for x in np.linspace(-1.0, 1.0, 41):
        t = ms.sensor_torque_nm(TR, float(x), 0.0)
        assert ms.sensor_torque_nm(TR, float(x) + ms.PERIOD_RAD, 0.0) == pytest.approx(t, abs=1e-12)
        assert ms.sensor_torque_nm(TR, -float(x), 0.0) == pytest.approx(-t, abs=1e-12)
    for k in range(3):
        x_eq = k * ms.PERIOD_RAD
        assert ms.sensor_torque_nm(TR, x_eq, 0.0) == pytest.approx(0.0, abs=1e-12)
        assert ms.stiffness_nm_per_rad(TR, x_eq, 0.0) > 0.0


def test_output_side_friction_is_smooth_dissipative_and_0_05nm() -> None:
    """Sec. 7.1: kinetic friction about 0.05 N*m; model C-F's tanh form is smooth through 0."""
    assert ms.output_side_torque_nm(TR, 0.3, 0.0) == 0.0
    assert ms.output_side_torque_nm(TR, 0.3, 10.0) == pytest.approx(-0.05, rel=1e-9)
    assert ms.output_side_torque_nm(TR, 0.3, -10.0) == pytest.approx(0.05, rel=1e-9)
    for v in np.linspace(-2.0, 2.0, 81):
        assert ms.output_side_torque_nm(TR, 1.0, float(v)) * v <= 0.0
    h = 1e-7  # smooth: finite slope tau_fr v at zero speed
    slope = (ms.output_side_torque_nm(TR, 0.0, h) - ms.output_side_torque_nm(TR, 0.0, -h)) / (2 * h)
    assert slope == pytest.approx(-TR[ms.I_TAU_FR] * TR[ms.I_V], rel=1e-6)
    ecc = ms.default_block({"w": 0.02, "x_e": 0.5, "tau_fr": 0.0})
    assert ms.output_side_torque_nm(ecc, 1.0, 0.0) == pytest.approx(0.02 * math.sin(1.5))


# ------------------------------------------------------------------ kernel invariants


def test_stiffness_and_potential_are_consistent_derivatives() -> None:
    h = 1e-6
    for d in (0.0, 0.01):
        tr = ms.default_block({"d": d, "scale": 4.0})
        assert ms.potential_j(tr, 0.0, 0.0, ACT, 0) == 0.0
        for x in np.linspace(-2.0, 2.0, 161):
            x = float(x)
            num_k = (ms.sensor_torque_nm(tr, x + h, 0.0) - ms.sensor_torque_nm(tr, x - h, 0.0)) / (
                2 * h
            )
            assert num_k == pytest.approx(ms.stiffness_nm_per_rad(tr, x, 0.0), rel=1e-6, abs=1e-8)
            num_t = (
                ms.potential_j(tr, x + h, 0.0, ACT, 0) - ms.potential_j(tr, x - h, 0.0, ACT, 0)
            ) / (2 * h)
            assert num_t == pytest.approx(ms.sensor_torque_nm(tr, x, 0.0), rel=1e-6, abs=1e-9)
            assert ms.potential_j(tr, x, 0.0, ACT, 0) >= 0.0  # x = 0 is the energy minimum


def test_relative_damping_dissipates_and_sensor_is_the_static_torque() -> None:
    rng = np.random.default_rng(3)
    for x, xdot in zip(rng.uniform(-1.5, 1.5, 200), rng.uniform(-30, 30, 200), strict=True):
        tau = ms.torque_nm(TR, x, xdot, 0.0, ACT, 0)
        static = ms.sensor_torque_nm(TR, x, 0.0)
        assert (tau - static) * xdot >= 0.0
        assert tau - static == pytest.approx(TR[ms.I_Z] * xdot, rel=1e-9, abs=1e-15)
        assert ms.torque_nm(TR, x, 0.0, 0.0, ACT, 0) == static
        assert ms.torque_nm(TR, x, xdot, 1.7, ACT, 0) == tau  # no bend dependence


def test_free_oscillation_conserves_energy_without_damping_and_loses_it_with() -> None:
    # an output inertia of 1e-4 kg*m^2; input held
    check_free_oscillation(
        ms,
        (ms.default_block({"z": 0.0}), TR),
        ACT,
        (1e-4, 25.0 * DEG, 1e-4, 4000),
        drift=1e-5,
        rise=1e-15,
        final=0.9,
    )


# ------------------------------------------------------------------ interface and scale


def test_transmission_interface_and_the_torque_limit() -> None:
    t = Transmission("magnetic_spring", 3, ms)
    np.testing.assert_array_equal(t.block(), TR)
    assert not t.routed_over_joint2
    assert t.states == ()
    assert t.state_limits(TR) == [None] * N_STATES
    assert t.initial_states(TR, 0.1, 0.0) == [0.0] * N_STATES
    for i in range(N_STATES):
        assert ms.state_rate(TR, 0.1, 1.0, 0.0, ACT, 0, i) == 0.0
    # 0 kg payload (0.46 N*m) fits the published-size spring; 15 kg (7.1 N*m) does not
    x = t.twist_for_torque(TR, 0.46, 0.0)
    assert t.sensor_torque(TR, x, 0.0) == pytest.approx(0.46, rel=1e-9)
    assert x / DEG == pytest.approx(10.6, abs=0.1)
    with pytest.raises(TransmissionError, match="cannot hold"):
        t.twist_for_torque(TR, 7.1, 0.0)
    with pytest.raises(TransmissionError, match="cannot hold"):
        t.twist_for_torque(TR, -1.01, 0.0)  # just above the 1.0 N*m peak
    # with enough springs in parallel, 7.1 N*m sits inside the linear range
    scale = ms.scale_for_torque(7.1, within="linear")
    assert scale == pytest.approx(8.76, abs=0.01)
    assert ms.scale_for_torque(7.1, within="stable") == pytest.approx(7.1, rel=1e-3)
    tr_n = t.block({"scale": scale})
    x = t.twist_for_torque(tr_n, -7.1, 0.0)
    assert abs(x) == pytest.approx(ms.linear_range_rad(0.0), rel=1e-6)
    assert (
        ms.stiffness_at_equilibrium(0.0)
        < t.max_stiffness(TR)
        < 1.01 * ms.stiffness_at_equilibrium(0.0)
    )
    with pytest.raises(TransmissionError, match="no parameter"):
        t.block({"gap": 0.001})


def test_safe_range_and_bad_arguments() -> None:
    x_safe = ms.safe_range_rad(0.0, 0.9)
    assert ms.linear_range_rad(0.0) < x_safe < ms.stable_range_rad(0.0)
    assert ms.sensor_torque_nm(TR, x_safe, 0.0) == pytest.approx(0.9 * ms.max_torque_nm(0.0))
    assert issubclass(ms.MagneticSpringParamError, ValueError)
    with pytest.raises(ms.MagneticSpringParamError, match="torque_fraction"):
        ms.safe_range_rad(0.0, 1.2)
    with pytest.raises(ms.MagneticSpringParamError, match="within"):
        ms.scale_for_torque(1.0, within="safe")
    with pytest.raises(ms.MagneticSpringParamError, match="> 0"):
        ms.scale_for_torque(-1.0)
    for bad in ({"z": -1.0}, {"scale": 0.0}, {"b1": -1.0}, {"tau_fr": -0.1}):
        with pytest.raises(ms.MagneticSpringParamError):
            ms.default_block(bad)
    assert len(ms.PARAMS) <= 24
