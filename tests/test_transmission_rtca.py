"""RTCA transmission (seed 001): Table 1 reproduced, bend scaling, kernel invariants, interface."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from fsarm_sim.plant.effects import nonlinear_stiffness
from fsarm_sim.plant.transmissions import rtca
from fsarm_sim.plant.transmissions.base import N_STATES, N_TR, Transmission, TransmissionError

from conftest import check_free_oscillation

ACT = np.zeros(N_STATES)
TR = rtca.default_block()
BEND_250 = 0.255 / 0.250  # joint-2 angle that bends the shaft to R = 250 mm (L_bend = 255 mm)


def _table1_deg(x_deg: float) -> float:
    """Eq. 1 evaluated exactly as printed: Δθ in degrees, Table 1 coefficients."""
    if x_deg >= 0.0:
        w = 0.03322
        return 4.202 - 4.201 * math.cos(w * x_deg) + 0.1622 * math.sin(w * x_deg)
    w = 0.04357
    return (
        -3.107
        + 2.335 * math.cos(w * x_deg)
        + 0.7484 * math.cos(2 * w * x_deg)
        + 0.02559 * math.cos(3 * w * x_deg)
        - 1.487 * math.sin(w * x_deg)
        + 0.3618 * math.sin(2 * w * x_deg)
        + 0.1976 * math.sin(3 * w * x_deg)
    )


def _twists() -> np.ndarray:
    """Twists over the law's range, away from the kinks at 0 and at the dead-zone edge."""
    xs = np.linspace(-rtca.TWIST_RANGE_RAD, rtca.TWIST_RANGE_RAD, 97)
    keep = (np.abs(xs) > 1e-3) & (np.abs(xs + TR[rtca.I_XDEAD_NEG]) > 1e-3)
    return xs[keep]


# ------------------------------------------------------------------ published numbers


def test_table1_branches_pass_through_origin_within_rounding() -> None:
    """Sec. 3.3: both branches were forced through the origin; printed digits miss by <= 2 mN*m."""
    assert abs(rtca.curve(0.0, 1.0)) == pytest.approx(0.001, abs=1e-12)
    assert abs(rtca.curve(0.0, -1.0)) == pytest.approx(0.00199, abs=1e-12)


@pytest.mark.parametrize("x_deg", [5.0, 20.0, 45.0, 51.0, -3.0, -20.0, -45.0, -75.0])
def test_kernel_reproduces_table1_in_degrees(x_deg: float) -> None:
    """The kernel (rad, SI) equals Table 1's series in degrees, shifted to pass through 0."""
    zero = 4.202 - 4.201 if x_deg > 0.0 else -3.107 + 2.335 + 0.7484 + 0.02559  # branch at 0
    expected = _table1_deg(x_deg) - zero
    x = math.radians(x_deg)
    assert rtca.sensor_torque_nm(TR, x, 0.0) == pytest.approx(expected, rel=1e-12, abs=1e-12)
    assert rtca.curve(x, math.copysign(1.0, x_deg)) == pytest.approx(_table1_deg(x_deg), rel=1e-12)


def test_positive_twist_is_the_stiffer_tol_direction() -> None:
    """Sec. 3.1: one direction (TOL) is stiffer; in Table 1 it is x >= 0 (8.0 vs 4.33 N*m/rad)."""
    pos = [
        rtca.stiffness_nm_per_rad(TR, x, 0.0) for x in np.linspace(0.0, TR[rtca.I_XFIT_POS], 200)
    ]
    neg = [
        rtca.stiffness_nm_per_rad(TR, -x, 0.0) for x in np.linspace(0.0, TR[rtca.I_XFIT_NEG], 200)
    ]
    assert max(pos) == pytest.approx(8.0, abs=0.02)
    assert max(neg) == pytest.approx(4.33, abs=0.02)
    # asymmetric, not odd: the same twist gives different torques on the two sides
    assert rtca.sensor_torque_nm(TR, 0.8, 0.0) > 1.4 * -rtca.sensor_torque_nm(TR, -0.8, 0.0)


def test_fitted_range_ends_at_the_5nm_characterisation_limit_then_linear() -> None:
    """Sec. 3.2 kept |T| <= 5 N*m; beyond, the law continues with the end slope."""
    lo, hi = rtca.fitted_range_rad()
    assert math.degrees(hi) == pytest.approx(51.88, abs=0.01)
    assert math.degrees(lo) == pytest.approx(-75.97, abs=0.01)
    assert rtca.sensor_torque_nm(TR, hi, 0.0) == pytest.approx(5.0, abs=1e-9)
    assert rtca.sensor_torque_nm(TR, lo, 0.0) == pytest.approx(-5.0, abs=1e-9)
    for end in (lo, hi):
        k_end = rtca.stiffness_nm_per_rad(TR, end, 0.0)
        for dx in (0.1, 0.5):
            x = end + math.copysign(dx, end)
            assert rtca.stiffness_nm_per_rad(TR, x, 0.0) == pytest.approx(k_end, rel=1e-12)
            assert rtca.sensor_torque_nm(TR, x, 0.0) == pytest.approx(
                math.copysign(5.0, end) + k_end * (x - end), rel=1e-12
            )


def test_mu_at_250mm_gives_the_published_torque_losses() -> None:
    """Sec. 6.1: at R = 250 mm mu = 0.705 (TOL) and 0.82 (LOL): losses of 29.5 % and 18 %."""
    assert rtca.bend_radius_m(BEND_250) == pytest.approx(0.250)
    assert rtca.mu(BEND_250, 1.0) == pytest.approx(0.705)
    assert rtca.mu(BEND_250, -1.0) == pytest.approx(0.82)
    for x, loss in ((0.6, 0.295), (-0.9, 0.18)):
        bent = rtca.sensor_torque_nm(TR, x, BEND_250)
        straight = rtca.sensor_torque_nm(TR, x, 0.0)
        assert 1.0 - bent / straight == pytest.approx(loss, abs=1e-12)
    assert rtca.mu(0.0, 1.0) == 1.0
    assert rtca.mu(0.0, -1.0) == 1.0


def test_mu_falls_linearly_with_curvature_is_even_and_held_beyond_250mm() -> None:
    bends = np.linspace(0.0, 2.1, 43)
    for sign in (1.0, -1.0):
        mus = [rtca.mu(float(b), sign) for b in bends]
        assert all(b <= a + 1e-15 for a, b in itertools.pairwise(mus))
        assert rtca.mu(0.5 * BEND_250, sign) == pytest.approx(0.5 * (1.0 + rtca.mu(BEND_250, sign)))
        assert rtca.mu(2.0, sign) == rtca.mu(BEND_250, sign)
        assert rtca.mu(-0.7, sign) == rtca.mu(0.7, sign)


def test_stiffness_scales_with_mu_as_eq4() -> None:
    for x in (-1.5, -0.4, 0.2, 0.7, 1.4):
        for bend in (0.3, 1.0, 2.0):
            k_bent = rtca.stiffness_nm_per_rad(TR, x, bend)
            k_straight = rtca.stiffness_nm_per_rad(TR, x, 0.0)
            assert k_bent == pytest.approx(rtca.mu(bend, math.copysign(1.0, x)) * k_straight)


def test_agrees_with_the_masterflex08_effect_within_the_fitted_range() -> None:
    """effects.nonlinear_stiffness holds the same Table 1 coefficients: same curve, same slope."""
    lo, hi = rtca.fitted_range_rad()
    x_dead = TR[rtca.I_XDEAD_NEG]
    xs = [x for x in np.linspace(lo, hi, 301) if not -x_dead <= x < 0.0]
    for x in xs:
        assert rtca.sensor_torque_nm(TR, float(x), 0.0) == pytest.approx(
            nonlinear_stiffness.masterflex08_torque_nm(float(x), 1.0), abs=1e-12
        )
        assert rtca.stiffness_nm_per_rad(TR, float(x), 0.0) == pytest.approx(
            nonlinear_stiffness.masterflex08_stiffness(float(x), 1.0), rel=1e-9, abs=1e-12
        )
    np.testing.assert_allclose(nonlinear_stiffness.MF08_POS, rtca.TABLE1_POS)
    np.testing.assert_allclose(nonlinear_stiffness.MF08_NEG, rtca.TABLE1_NEG)


def test_dead_zone_replaces_the_wrong_way_bump_of_the_negative_branch() -> None:
    """The printed x < 0 series is positive for |x| < 1.45 deg; the law holds 0 there instead."""
    x_dead = TR[rtca.I_XDEAD_NEG]
    assert math.degrees(x_dead) == pytest.approx(1.447, abs=0.01)
    assert rtca.curve(-0.5 * x_dead, -1.0) - rtca.curve(0.0, -1.0) > 0.0  # the printed bump
    for x in np.linspace(-x_dead, -1e-9, 20):
        assert rtca.sensor_torque_nm(TR, float(x), 0.0) == 0.0
        assert rtca.stiffness_nm_per_rad(TR, float(x), 0.0) == 0.0
    for x in np.linspace(-rtca.TWIST_RANGE_RAD, rtca.TWIST_RANGE_RAD, 801):
        assert rtca.stiffness_nm_per_rad(TR, float(x), 1.3) >= 0.0
        assert rtca.sensor_torque_nm(TR, float(x), 1.3) * x >= 0.0


# ------------------------------------------------------------------ kernel invariants


def test_stiffness_is_the_derivative_of_the_sensor_torque() -> None:
    h = 1e-6
    for bend in (0.0, 0.8, 2.0):
        for x in _twists():
            num = (
                rtca.sensor_torque_nm(TR, x + h, bend) - rtca.sensor_torque_nm(TR, x - h, bend)
            ) / (2 * h)
            k = rtca.stiffness_nm_per_rad(TR, x, bend)
            assert num == pytest.approx(k, rel=1e-6, abs=1e-8)


def test_potential_derivative_is_the_elastic_torque_and_energy_is_stored() -> None:
    h = 1e-6
    for bend in (0.0, 1.5):
        assert rtca.potential_j(TR, 0.0, bend, ACT, 0) == 0.0
        for x in _twists():
            num = (
                rtca.potential_j(TR, x + h, bend, ACT, 0)
                - rtca.potential_j(TR, x - h, bend, ACT, 0)
            ) / (2 * h)
            assert num == pytest.approx(rtca.sensor_torque_nm(TR, x, bend), rel=1e-6, abs=1e-9)
            assert rtca.potential_j(TR, x, bend, ACT, 0) >= 0.0


def test_damping_term_dissipates_and_sensor_is_the_static_torque() -> None:
    rng = np.random.default_rng(1)
    for x, xdot, bend in zip(
        rng.uniform(-2, 2, 200), rng.uniform(-20, 20, 200), rng.uniform(-2.1, 2.1, 200), strict=True
    ):
        tau = rtca.torque_nm(TR, x, xdot, bend, ACT, 0)
        tau_static = rtca.sensor_torque_nm(TR, x, bend)
        dissipative = tau - tau_static
        assert dissipative * xdot >= 0.0
        c_eff = rtca.mu(bend, math.copysign(1.0, x)) * TR[rtca.I_C]
        assert dissipative == pytest.approx(c_eff * xdot, rel=1e-9, abs=1e-15)
        assert rtca.torque_nm(TR, x, 0.0, bend, ACT, 0) == tau_static
    # Table 1: c = 0.00003 N*m per deg/s
    assert TR[rtca.I_C] * math.radians(1.0) == pytest.approx(3e-5)


def test_free_oscillation_conserves_energy_without_damping_and_loses_it_with() -> None:
    """An inertia on the shaft's output (input held): RK4, energy drift tiny; with c, it falls."""
    check_free_oscillation(
        rtca,
        (rtca.default_block({"c": 0.0}), TR),
        ACT,
        (2e-3, 0.6, 2e-4, 5000),  # j = 2e-3 kg*m^2
        drift=1e-4,
        rise=1e-12,
        final=0.99,
    )


def test_scale_multiplies_every_torque() -> None:
    tr3 = rtca.default_block({"scale": 3.0})
    for x, xdot, bend in ((0.5, 1.0, 0.4), (-1.1, -3.0, 1.9)):
        assert rtca.torque_nm(tr3, x, xdot, bend, ACT, 0) == pytest.approx(
            3.0 * rtca.torque_nm(TR, x, xdot, bend, ACT, 0)
        )
        assert rtca.potential_j(tr3, x, bend, ACT, 0) == pytest.approx(
            3.0 * rtca.potential_j(TR, x, bend, ACT, 0)
        )


# ------------------------------------------------------------------ interface


def test_transmission_interface_block_twist_for_torque_and_max_stiffness() -> None:
    t = Transmission("rtca", 1, rtca)
    np.testing.assert_array_equal(t.block(), TR)
    assert t.block({"scale": 2.0})[rtca.I_SCALE] == 2.0
    assert t.routed_over_joint2
    assert t.states == ("slip",)
    lim = t.state_limits(TR)
    assert lim[1:] == [None] * (N_STATES - 1)
    assert lim[0] is not None and lim[0][0] == pytest.approx(-lim[0][1])
    assert t.initial_states(TR, 0.3, 0.5) == [0.0] * N_STATES
    assert rtca.state_rate(TR, 0.3, 1.0, 0.5, ACT, 0, 0) == 1.0  # stuck: follows the twist
    for rate_slot in range(1, N_STATES):
        assert rtca.state_rate(TR, 0.3, 1.0, 0.5, ACT, 0, rate_slot) == 0.0
    # the arm's fig14-sine torques (0.46 N*m at 0 kg, 7.1 N*m at 15 kg), both signs and bends
    for tau in (0.46, -0.46, 6.0, -6.0, 7.1):
        for bend in (0.0, 1.0, 2.1):
            x = t.twist_for_torque(TR, tau, bend)
            assert t.sensor_torque(TR, x, bend) == pytest.approx(tau, rel=1e-9)
    assert t.twist_for_torque(TR, 0.46, 0.0) == pytest.approx(0.2287, abs=1e-4)
    # the law's largest slope plus the stuck friction element (0.032 N*m over 5 deg)
    assert t.max_stiffness(TR) == pytest.approx(8.0016 + 0.032 / math.radians(5.0), abs=1e-3)
    # beyond the law's range on the soft side at a strong bend: cannot be held
    with pytest.raises(TransmissionError, match="cannot hold"):
        t.twist_for_torque(TR, -7.1, 2.1)
    with pytest.raises(TransmissionError, match="no parameter"):
        t.block({"length": 0.5})


def test_bad_parameters_raise_named_errors() -> None:
    assert issubclass(rtca.RtcaParamError, ValueError)
    for bad in (
        {"mu_pos": 1.2},
        {"mu_neg": 0.0},
        {"bend_length": 0.0},
        {"c": -1.0},
        {"scale": 0.0},
    ):
        with pytest.raises(rtca.RtcaParamError):
            rtca.default_block(bad)
    with pytest.raises(rtca.RtcaParamError, match="no parameter"):
        rtca.default_block({"twist_scale": 2.0})
    with pytest.raises(rtca.RtcaParamError, match="sign"):
        rtca.curve(0.1, 0.5)
    with pytest.raises(rtca.RtcaParamError, match="finite"):
        rtca.bend_radius_m(math.nan)
    assert len(rtca.PARAMS) <= N_TR
    assert rtca._dead_end_rad(1.0) == 0.0  # the x >= 0 branch needs no dead zone


# ------------------------------------------------------------------ bend-dependent friction


def _loop(tr: np.ndarray, bend: float, amp: float = 1.5, n: int = 4000) -> tuple[float, float]:
    """Quasi-static twist cycle 0 -> +amp -> -amp -> +amp with the friction state integrated
    (explicit Euler on state_rate); returns (torque at 0 going up - going down) / 2 and the
    energy dissipated per cycle, from the element alone (law and c term excluded: xdot = 0 in c)."""
    act = np.zeros(N_STATES)
    xs = np.concatenate(
        [np.linspace(0, amp, n), np.linspace(amp, -amp, 2 * n), np.linspace(-amp, amp, 2 * n)]
    )
    up = down = 0.0
    work = 0.0
    for k in range(1, xs.size):
        dx = xs[k] - xs[k - 1]
        dt = 1e-4  # below maxwell_slip.SLIP_RELAX_S: explicit Euler stays stable
        act[0] += dt * rtca.state_rate(tr, xs[k - 1], dx / dt, bend, act, 0, 0)
        tau_f = rtca.torque_nm(tr, xs[k], 0.0, bend, act, 0) - rtca.sensor_torque_nm(
            tr, xs[k], bend
        )
        if k >= 3 * n:
            work += tau_f * dx
        if abs(xs[k]) < 0.6 * amp / n:  # at zero twist, amp past either reversal
            if dx > 0:
                up = tau_f
            else:
                down = tau_f
    return 0.5 * (up - down), work


def test_friction_element_grows_with_bend_as_bend_friction_factor() -> None:
    from fsarm_sim.plant.effects import bend_friction

    f0, _ = _loop(TR, 0.0)
    assert f0 == pytest.approx(0.032, rel=1e-3)  # Sec. 3.3: 0.32 % of the 10 N*m span
    for bend in (0.6, -1.0, 1.5):
        fb, _ = _loop(TR, bend)
        g = bend_friction.factor(bend, rtca.BEND_FRICTION_PER_RAD)
        assert fb == pytest.approx(0.032 * g, rel=1e-3)
    # 2.3 % of the span at R = 150 mm (phi = 0.255 / 0.15 = 1.7 rad): the sizing, reproduced
    assert math.isclose(rtca.BEND_FRICTION_PER_RAD, 1.160, abs_tol=1e-3)
    assert 0.032 * bend_friction.factor(1.7, rtca.BEND_FRICTION_PER_RAD) == pytest.approx(0.23)
    # held beyond the tightest measured bend (R = 150 mm: phi = 1.7 rad)
    assert _loop(TR, 2.5)[0] == pytest.approx(_loop(TR, 1.7)[0], rel=1e-6)


def test_friction_element_dissipates_more_when_bent_and_switches_off() -> None:
    _, w0 = _loop(TR, 0.0)
    _, w1 = _loop(TR, 1.0)
    assert w0 > 0.0 and w1 > 2.0 * w0  # slip dissipates, more with the bend
    off = rtca.default_block({"slip_f": 0.0})
    assert _loop(off, 1.0) == (0.0, 0.0)
    assert rtca.default_block(rtca.HYSTERESIS_OFF)[rtca.I_SLIP_F] == 0.0
    assert rtca.CONSERVATIVE["slip_f"] == 0.0
    act = np.array([0.01, 0.0, 0.0])
    # the element's energy does not read the bend: bend_torque is the law's alone
    assert rtca.potential_j(TR, 0.3, 0.4, act, 0) - rtca.potential_j(
        TR, 0.3, 0.4, ACT, 0
    ) == pytest.approx(
        rtca.potential_j(TR, 0.3, 1.2, act, 0) - rtca.potential_j(TR, 0.3, 1.2, ACT, 0)
    )
    with pytest.raises(rtca.RtcaParamError, match="slip_f"):
        rtca.default_block({"slip_f": -0.1})
