"""Tendon-sheath transmission (seed 004): seed equations and tables, kernel physics, interface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.plant.transmissions import tendon_sheath as ts
from fsarm_sim.plant.transmissions.base import N_STATES, N_TR, Transmission, TransmissionError

from conftest import make_jitable

TR = Transmission("tendon-sheath", 4, ts)
DT = 1e-3


def act_at(z: float) -> np.ndarray:
    return np.array([z, 0.0, 0.0])


# ------------------------------------------------------------------ seed equations and tables


@pytest.mark.parametrize("bend", [0.0, 1.0, -1.0, 2.1])
def test_branch_stiffness_ratio_is_the_capstan_ratio(bend: float) -> None:
    # eq. 8: Phi_p = exp(+mu Theta), Phi_r = exp(-mu Theta); the wrap over joint 2 adds |phi_B|
    tr = TR.block()
    wrap = math.pi / 2.0 + abs(bend)
    assert ts.total_wrap_rad(tr, bend) == pytest.approx(wrap)
    ratio = ts.branch_stiffness_pull(tr, bend) / ts.branch_stiffness_release(tr, bend)
    assert ratio == pytest.approx(math.exp(0.15 * wrap), rel=1e-12)
    assert ratio == pytest.approx(ts.capstan_ratio(0.15, wrap), rel=1e-12)


def test_capstan_ratio_at_the_seed_bends() -> None:
    # seed 004 Table 2 bends pi/2, pi, 3pi/2 (mu = 0.15 estimate): Phi_p = 1.266, 1.603, 2.028
    got = [ts.capstan_ratio(0.15, w) for w in sorted(ts.TABLE_2_BEND)]
    assert got == pytest.approx([1.2657, 1.6019, 2.0276], abs=1e-4)
    assert ts.capstan_ratio(0.15, math.pi) * ts.capstan_ratio(-0.15, math.pi) == pytest.approx(1.0)


@pytest.mark.parametrize("bend", [0.0, 1.5])
def test_eq11_closed_form_matches_quadrature_of_eq9(bend: float) -> None:
    # eq. 9: Delta L = int F(x)/(EA) dx along the tendon; uniform curvature over the sheath, free
    # tendon split equally between the ends; F referred to the actuator end (eq. 10)
    tr = TR.block()
    mu, theta = 0.15, ts.total_wrap_rad(tr, bend)
    ea = 193e9 * math.pi * 0.6e-3**2
    ls, lf = 0.8, 0.4
    s = np.linspace(0.0, ls, 20001)  # distance from the actuator end of the sheath
    kappa = theta / ls
    for sign, compliance in ((1.0, ts.compliance_pull), (-1.0, ts.compliance_release)):
        f_sheath = np.exp(-sign * mu * kappa * s)  # pulling: tension falls toward the joint
        f_joint_end = f_sheath[-1]
        integral = float(np.sum(0.5 * (f_sheath[1:] + f_sheath[:-1]) * np.diff(s)))
        stretch = (0.5 * lf * 1.0 + integral + 0.5 * lf * f_joint_end) / ea
        assert compliance(tr, bend) == pytest.approx(stretch, rel=1e-8)
    # mu -> 0: both branches are the plain tendon, L_t / (E A)
    tr0 = TR.block({"mu": 0.0})
    assert ts.compliance_pull(tr0, bend) == pytest.approx(1.2 / ea, rel=1e-12)
    assert ts.compliance_release(tr0, bend) == pytest.approx(1.2 / ea, rel=1e-12)
    assert TR.stiffness(tr0, 0.0, bend) == pytest.approx(0.025**2 * ea / 1.2, rel=1e-12)


def _separations(row: dict[str, tuple[float, float, float, float]]) -> tuple[float, float, float]:
    (pc, qc, mc, _), (pa, qa_, ma, _) = row["RC"], row["RA"]
    return pc - pa, qc - qa_, mc - ma


@pytest.mark.parametrize(
    "row",
    [*ts.TABLE_2_BEND.values(), ts.TABLE_1_VELOCITY[0.04], ts.TABLE_1_VELOCITY[0.06]],
)
def test_tables_follow_eq_20_22_with_a_calibrated_joint_encoder(row: dict) -> None:
    # eq. 20-22 (c2 = 0, b2 = 1): the branches differ only through Theta_p - Theta_r, so
    # dQ ~ 0 and dM = -2 dP (the load Mgl cos(theta2) and its Taylor term, eq. 17-18)
    dp, dq, dm = _separations(row)
    assert dp < 0.0 < dm  # every row: the same hysteresis orientation
    assert abs(dq) < 0.04
    assert dm == pytest.approx(-2.0 * dp, rel=0.15)


@pytest.mark.parametrize("bend", sorted(ts.TABLE_2_BEND))
def test_table_2_branches_meet_at_zero_load(bend: float) -> None:
    # at zero load (theta2 = pi/2, cos = 0) the two branches of eq. 19 meet within 0.071 rad
    # (full load: 0.36-0.59 rad apart): no dead band separate from the capstan hysteresis
    dp, dq, dm = _separations(ts.TABLE_2_BEND[bend])
    sep0 = dp * (math.pi / 2) ** 2 + dq * (math.pi / 2) + dm
    assert abs(sep0) < 0.071 < 0.2 * dm


def test_table_1_slowest_row_is_the_outlier() -> None:
    # the 0.02 rad/s row of Table 1 does not follow dM = -2 dP (0.206 vs 0.092): reported
    dp, _, dm = _separations(ts.TABLE_1_VELOCITY[0.02])
    assert dm == pytest.approx(0.206, abs=1e-9) and -2.0 * dp == pytest.approx(0.092, abs=1e-9)


def test_hysteresis_grows_with_bend_like_table_2() -> None:
    # Table 2: full-load branch separation dM = 0.364, 0.484, 0.585 rad at pi/2, pi, 3pi/2;
    # the model's hysteresis K_d/K_m = tanh(mu Theta / 2) grows in the same order
    seps = [_separations(ts.TABLE_2_BEND[w])[2] for w in sorted(ts.TABLE_2_BEND)]
    assert seps == pytest.approx([0.364, 0.484, 0.585], abs=1e-9)
    tr = TR.block({"wrap_rad": 0.0})
    widths = []
    for w in sorted(ts.TABLE_2_BEND):
        kp, kr = ts.branch_stiffness_pull(tr, w), ts.branch_stiffness_release(tr, w)
        widths.append((kp - kr) / (kp + kr))
        assert widths[-1] == pytest.approx(math.tanh(0.15 * w / 2.0), rel=1e-9)
    assert widths == sorted(widths) and seps == sorted(seps)


def test_position_transmission_eq19() -> None:
    p, q, m, _ = ts.TABLE_2_BEND[math.pi]["RC"]
    assert ts.position_transmission_rad(0.5, p, q, m) == pytest.approx(
        -0.266 * 0.25 + 0.911 * 0.5 + 0.361
    )


# ------------------------------------------------------------------ kernel physics


@pytest.mark.parametrize("backlash", [0.0, 0.02])
@pytest.mark.parametrize("bend", [0.0, 1.2])
def test_stiffness_is_derivative_of_sensor_torque(backlash: float, bend: float) -> None:
    tr = TR.block({"backlash_rad": backlash})
    h = 1e-7
    for x in (-0.12, -0.03, 0.005, 0.02, 0.14):
        num = (TR.sensor_torque(tr, x + h, bend) - TR.sensor_torque(tr, x - h, bend)) / (2 * h)
        assert TR.stiffness(tr, x, bend) == pytest.approx(num, rel=1e-6, abs=1e-9)
    if backlash > 0.0:  # inside the play: no torque, no stiffness
        assert TR.sensor_torque(tr, 0.009, bend) == 0.0
        assert TR.stiffness(tr, -0.009, bend) == 0.0


@pytest.mark.parametrize("backlash", [0.0, 0.03])
def test_potential_derivative_is_elastic_torque(backlash: float) -> None:
    tr = TR.block({"backlash_rad": backlash, "scale": 1.3})
    act = act_at(0.0)
    h = 1e-7
    for x in (-0.1, -0.02, 0.0, 0.04, 0.12):
        for bend in (0.0, -1.8):
            dv = (
                ts.potential_j(tr, x + h, bend, act, 0) - ts.potential_j(tr, x - h, bend, act, 0)
            ) / (2 * h)
            tau = ts.torque_nm(tr, x, 0.0, bend, act, 0)
            assert dv == pytest.approx(tau, rel=1e-6, abs=1e-7)
            assert tau == pytest.approx(TR.sensor_torque(tr, x, bend), abs=1e-12)


def test_saturated_friction_state_gives_the_two_branches() -> None:
    # the joint end sees the tension after the sheath's friction: while the motor pulls (z = the
    # taut twist's sign) the softer branch K_rel x, while it releases K_pull x; the motor end
    # carries e^(+-mu Theta) of it: K_pull x pulling, K_rel x releasing (eq. 7-8)
    tr = TR.block()
    for x in (0.05, -0.05):
        pull, rel = act_at(1.0 if x > 0 else -1.0), act_at(-1.0 if x > 0 else 1.0)
        kp, kr = ts.branch_stiffness_pull(tr, 0.7), ts.branch_stiffness_release(tr, 0.7)
        assert abs(ts.torque_nm(tr, x, 0.0, 0.7, pull, 0)) == pytest.approx(kr * 0.05, rel=1e-12)
        assert abs(ts.torque_nm(tr, x, 0.0, 0.7, rel, 0)) == pytest.approx(kp * 0.05, rel=1e-12)
        assert abs(ts.motor_torque_nm(tr, x, 0.0, 0.7, pull, 0)) == pytest.approx(
            kp * 0.05, rel=1e-12
        )
        assert abs(ts.motor_torque_nm(tr, x, 0.0, 0.7, rel, 0)) == pytest.approx(
            kr * 0.05, rel=1e-12
        )
        # the virtual sensor (centre line) lies between the branches
        joint = [abs(ts.torque_nm(tr, x, 0.0, 0.7, a, 0)) for a in (pull, rel)]
        assert joint[0] < abs(TR.sensor_torque(tr, x, 0.7)) < joint[1]


def _cycle(tr: np.ndarray, amp: float, offset: float, bend: float) -> tuple[float, float]:
    """Joint held, the motor end x = offset + amp sin(2 pi t), 3 cycles; explicit Euler on z
    with the state limit.

    Returns (work the motor does on the transmission over the last cycle, largest |z|).
    """
    act = act_at(0.0)
    n = round(1.0 / DT)
    work, zmax = 0.0, 0.0
    for k in range(3 * n):
        t = k * DT
        x = offset + amp * math.sin(2 * math.pi * t)
        xdot = 2 * math.pi * amp * math.cos(2 * math.pi * t)
        if k >= 2 * n:
            work += ts.motor_torque_nm(tr, x, xdot, bend, act, 0) * xdot * DT
        rate = ts.state_rate(tr, x, xdot, bend, act, 0, 0, xdot)
        act[0] = min(1.0, max(-1.0, act[0] + DT * rate))
        zmax = max(zmax, abs(act[0]))
    return work, zmax


@pytest.mark.parametrize(("amp", "offset"), [(0.05, 0.0), (0.04, 0.06), (0.03, -0.05)])
def test_friction_dissipates_and_grows_with_bend(amp: float, offset: float) -> None:
    tr = TR.block({"backlash_rad": 0.01})
    w_straight, z1 = _cycle(tr, amp, offset, 0.0)
    w_bent, z2 = _cycle(tr, amp, offset, 2.0)
    w_frictionless, _ = _cycle(TR.block({"backlash_rad": 0.01, "mu": 0.0}), amp, offset, 2.0)
    assert 0.0 < w_straight < w_bent  # more wrap, more capstan friction
    assert abs(w_frictionless) < 1e-3 * w_straight
    assert max(z1, z2) <= 1.0


def _stick_slip_loop_area(tr: np.ndarray, bend: float, x1: float, x2: float) -> float:
    """Area of the ideal quasi-static capstan loop between twists x1 < x2 (both loaded, > 0).

    Loading along K_p x, unloading along K_r x; at each reversal the joint-side tension holds
    while the actuator end changes by exp(+-2 mu Theta): straight lines of slope K_p + K_r
    from (x2, K_p x2) to (x2/e, K_r x2/e) and from (x1, K_r x1) to (x1 e, K_p x1 e).
    """
    kp, kr = ts.branch_stiffness_pull(tr, bend), ts.branch_stiffness_release(tr, bend)
    e = kp / kr
    poly = [(x1, kr * x1), (x1 * e, kp * x1 * e), (x2, kp * x2), (x2 / e, kr * x2 / e)]
    return 0.5 * abs(
        sum(poly[i][0] * poly[i - 1][1] - poly[i - 1][0] * poly[i][1] for i in range(4))
    )


@pytest.mark.parametrize("bend", [0.0, 1.0, 2.0])
@pytest.mark.parametrize(("x1", "x2"), [(0.02, 0.1), (0.03, 0.12)])
def test_dahl_loop_matches_the_stick_slip_capstan_loop(bend: float, x1: float, x2: float) -> None:
    tr = TR.block({"friction_speed_rad_s": 0.0})  # all the friction mobilised while sliding
    work, _ = _cycle(tr, 0.5 * (x2 - x1), 0.5 * (x1 + x2), bend)
    ideal = _stick_slip_loop_area(tr, bend, x1, x2)
    assert work == pytest.approx(ideal, rel=0.1)


def test_friction_state_follows_the_tendons_sliding() -> None:
    # delta0 = 0.1 mrad: the floor's share of the stick rate's denominator stays below 2 %
    tr = TR.block({"friction_speed_rad_s": 0.0, "presliding_rad": 1e-4})
    # the state moves with the sum of the ends' speeds u = vm + vj (vj = vm - x'): with the joint
    # held that is the motor's travel (eq. 5, phases C/F); it stops at +-1 and holds at rest
    stick = ts.stick_rate(tr, 0.05, 0.0, 0.2)
    assert ts.state_rate(tr, 0.05, 0.5, 0.0, act_at(0.2), 0, 0, 0.5) == pytest.approx(0.5 * stick)
    # both ends moving forward: u = 0.5 + 3.5
    assert ts.state_rate(tr, 0.05, -3.0, 0.0, act_at(0.2), 0, 0, 0.5) == pytest.approx(4.0 * stick)
    # the motor held, the joint pushed back: the tendon slides back, z falls
    assert ts.state_rate(tr, 0.05, 0.5, 0.0, act_at(0.2), 0, 0, 0.0) == pytest.approx(-0.5 * stick)
    # the ends moving apart at equal speeds: no net sliding
    assert ts.state_rate(tr, 0.05, 1.0, 0.0, act_at(0.2), 0, 0, 0.5) == 0.0
    assert ts.state_rate(tr, 0.05, -3.0, 0.0, act_at(1.0), 0, 0, 0.5) == 0.0
    assert ts.state_rate(tr, 0.05, 3.0, 0.0, act_at(-1.0), 0, 0, -0.5) == 0.0
    assert ts.state_rate(tr, 0.05, 0.0, 0.0, act_at(0.3), 0, 0, 0.0) == 0.0
    # the stick rate holds the joint's torque while the motor reverses (seed 004 phases C, F)
    kp, kr = ts.branch_stiffness_pull(tr, 0.0), ts.branch_stiffness_release(tr, 0.0)
    for x, z, dth in ((0.05, 1.0, -1e-6), (0.05, -0.4, 1e-6), (-0.05, -1.0, 1e-6)):
        act = act_at(z)
        tau0 = ts.torque_nm(tr, x, 0.0, 0.0, act, 0)
        act[0] = z + dth * ts.stick_rate(tr, x, 0.0, z)
        slope = (ts.torque_nm(tr, x + dth, 0.0, 0.0, act, 0) - tau0) / dth
        assert abs(slope) < 0.03 * kr  # ~0 against the branches (delta0 floor)
    # the full switch at constant joint torque takes the ideal travel x (1 - K_rel / K_pull)
    x, z = 0.05, 1.0
    tau = ts.torque_nm(tr, x, 0.0, 0.0, act_at(z), 0)
    while z > -1.0:
        z = ts.friction_step(tr, x, -1e-5, 0.0, z)
        x -= 1e-5
    assert x == pytest.approx(0.05 * kr / kp, rel=0.03)
    assert ts.torque_nm(tr, x, 0.0, 0.0, act_at(-1.0), 0) == pytest.approx(tau, rel=0.03)
    assert ts.state_rate(tr, 0.0, 1.0, 0.0, act_at(0.0), 0, 1, 1.0) == 0.0  # unused slot
    assert TR.state_limits(tr) == [(-1.0, 1.0), None, None]
    assert TR.initial_states(tr, 0.02, 1.0) == [0.0, 0.0, 0.0]
    assert len(ts.STATES) <= N_STATES


def _power_lost(tr: np.ndarray, x: float, vm: float, vj: float, bend: float, z: float) -> float:
    """Power into the transmission minus the rate of its stored energy, at twist x."""
    act, h = act_at(z), 1e-7
    tau_m = ts.motor_torque_nm(tr, x, vm - vj, bend, act, 0)
    tau_j = ts.torque_nm(tr, x, vm - vj, bend, act, 0)
    dv = (ts.potential_j(tr, x + h, bend, act, 0) - ts.potential_j(tr, x - h, bend, act, 0)) / 2 / h
    return tau_m * vm - tau_j * vj - dv * (vm - vj)


def test_sliding_friction_never_returns_energy() -> None:
    # while sliding (z at its target sgn(vm + vj)) the power lost is K_d |x| |vm + vj| >= 0 for
    # every pair of end speeds: also with the joint pushed back faster than the motor pulls
    # (vj < -vm), where z following the motor end alone (0.4.0) returned energy
    tr = TR.block({"friction_speed_rad_s": 0.0})
    rng = np.random.default_rng(4)
    kd = 0.5 * (ts.branch_stiffness_pull(tr, 1.0) - ts.branch_stiffness_release(tr, 1.0))
    for _ in range(200):
        x = float(rng.choice([-1.0, 1.0]) * rng.uniform(0.005, 0.1))
        vm, vj = (float(v) for v in rng.uniform(-2.0, 2.0, 2))
        z = math.copysign(1.0, vm + vj)
        lost = _power_lost(tr, x, vm, vj, 1.0, z)
        assert lost >= -1e-9
        assert lost == pytest.approx(kd * abs(x) * abs(vm + vj), rel=1e-5)
    # the 0.4.0 reading (z = sgn(vm)) returns energy in that case
    assert _power_lost(tr, 0.05, 0.1, -0.5, 1.0, 1.0) < 0.0


def _push_cycle(tr: np.ndarray, bend: float, x1: float, x2: float) -> float:
    """The motor held after a pull (z = +1); the joint pushed back from twist x1 to x2 and
    returned, twice (explicit Euler on z). Returns the hand's work on the transmission over
    the last cycle."""
    act = act_at(1.0)
    n = round(1.0 / DT)
    amp = 0.5 * (x2 - x1)
    work = 0.0
    for k in range(2 * n):
        t = k * DT
        x = x1 + amp * (1.0 - math.cos(2 * math.pi * t))  # joint pushed back: x grows
        vj = -amp * 2 * math.pi * math.sin(2 * math.pi * t)
        if k >= n:
            work -= ts.torque_nm(tr, x, -vj, bend, act, 0) * vj * DT
        act[0] = min(1.0, max(-1.0, act[0] + DT * ts.state_rate(tr, x, -vj, bend, act, 0, 0, 0.0)))
    return work


@pytest.mark.parametrize("bend", [0.0, 1.0, 2.0])
def test_pushing_the_joint_against_a_held_motor_shows_the_capstan_loop(bend: float) -> None:
    # hand guiding / a collision with the motor held: the tendon slides at the joint end, so the
    # friction reverses and the hand meets the capstan loop (loading along K_pull, unloading
    # along K_rel, the reversals at constant motor-end tension: the same polygon as the motor
    # driven loop). 0.4.0's z followed the motor alone, stayed at +1, and the joint saw a
    # lossless spring.
    tr = TR.block({"friction_speed_rad_s": 0.0})
    work = _push_cycle(tr, bend, 0.06, 0.14)
    assert work == pytest.approx(_stick_slip_loop_area(tr, bend, 0.06, 0.14), rel=0.1)
    frictionless = _push_cycle(TR.block({"friction_speed_rad_s": 0.0, "mu": 0.0}), bend, 0.06, 0.14)
    assert abs(frictionless) < 1e-3 * work


# ------------------------------------------------------------------ interface


def test_block_and_errors() -> None:
    tr = TR.block()
    assert tr.shape == (N_TR,)
    assert tr[ts.I_MU] == 0.15 and tr[ts.I_RADIUS] == 0.025
    with pytest.raises(TransmissionError, match="no parameter"):
        TR.block({"friction": 0.1})
    with pytest.raises(TransmissionError, match="finite"):
        TR.block({"mu": float("nan")})
    assert TR.routed_over_joint2
    assert all(p.source for p in ts.PARAMS)


def test_twist_for_torque_and_max_stiffness_for_the_arm() -> None:
    tr = TR.block()
    k0 = TR.stiffness(tr, 0.0, 0.0)
    assert k0 == pytest.approx(114.04, abs=0.01)  # r^2 K_m; straight K(mu=0) = 113.7 N*m/rad
    x = TR.twist_for_torque(tr, 7.1, 0.0)
    assert x == pytest.approx(7.1 / k0, rel=1e-9)
    tr_play = TR.block({"backlash_rad": 0.05})
    assert TR.twist_for_torque(tr_play, -7.1, 1.0) == pytest.approx(
        -7.1 / TR.stiffness(tr, 0.0, 1.0) - 0.025, rel=1e-9
    )
    # the stiffest bend (|phi_B| = 2.1 rad) - still far below the 1 ms limit (~1000 N*m/rad)
    assert TR.max_stiffness(tr) == pytest.approx(115.58, abs=0.01)
    assert TR.max_stiffness(tr) == pytest.approx(TR.stiffness(tr, 0.0, 2.1), rel=1e-12)


def test_kernels_compile_with_numba() -> None:
    numba = pytest.importorskip("numba")
    make_jitable(ts)

    @numba.njit(error_model="numpy")
    def run(tr: np.ndarray, act: np.ndarray, x: float, bend: float) -> np.ndarray:
        out = np.empty(6)
        out[0] = ts.torque_nm(tr, x, 0.2, bend, act, 0)
        out[1] = ts.sensor_torque_nm(tr, x, bend)
        out[2] = ts.stiffness_nm_per_rad(tr, x, bend)
        out[3] = ts.state_rate(tr, x, 0.2, bend, act, 0, 0, -0.3)
        out[4] = ts.potential_j(tr, x, bend, act, 0)
        out[5] = ts.motor_torque_nm(tr, x, 0.2, bend, act, 0)
        return out

    tr = TR.block({"backlash_rad": 0.01})
    act = act_at(0.3)
    for x in (0.004, -0.04):
        got = run(tr, act, x, -1.1)
        want = [
            ts.torque_nm(tr, x, 0.2, -1.1, act, 0),
            ts.sensor_torque_nm(tr, x, -1.1),
            ts.stiffness_nm_per_rad(tr, x, -1.1),
            ts.state_rate(tr, x, 0.2, -1.1, act, 0, 0, -0.3),
            ts.potential_j(tr, x, -1.1, act, 0),
            ts.motor_torque_nm(tr, x, 0.2, -1.1, act, 0),
        ]
        np.testing.assert_allclose(got, want, rtol=1e-12)


# ------------------------------------------------------------------ single tendon, sheath, routing


def test_single_tendon_only_pulls() -> None:
    # seed 004 Sec. II-B: a single TSA only pulls; slack (negative twist) carries nothing
    single = TR.block({"single_tendon": 1.0})
    pair = TR.block()
    for z in (-1.0, 0.0, 1.0):
        for x in (-0.05, -0.001):
            assert ts.torque_nm(single, x, 0.3, 0.5, act_at(z), 0) == 0.0
            assert ts.potential_j(single, x, 0.5, act_at(z), 0) == 0.0
        assert ts.torque_nm(single, 0.03, 0.3, 0.5, act_at(z), 0) == pytest.approx(
            ts.torque_nm(pair, 0.03, 0.3, 0.5, act_at(z), 0), rel=1e-12
        )
    assert TR.sensor_torque(single, -0.02, 0.0) == 0.0 and TR.stiffness(single, -0.02, 0.0) == 0.0
    assert TR.sensor_torque(pair, -0.02, 0.0) < 0.0  # the pull-pull pair drives both ways
    with pytest.raises(TransmissionError, match="single_tendon"):
        TR.block({"single_tendon": 2.0})


def test_sheath_compliance_is_in_series_over_the_sheath_length() -> None:
    ea_t = 193e9 * math.pi * 0.6e-3**2
    rigid = TR.block({"mu": 0.0})
    soft = TR.block({"mu": 0.0, "sheath_ea_n": 5e4})
    # mu = 0: C = L_t / EA_t + L_s / EA_sheath
    assert ts.compliance_pull(rigid, 0.0) == pytest.approx(1.2 / ea_t, rel=1e-12)
    assert ts.compliance_pull(soft, 0.0) == pytest.approx(1.2 / ea_t + 0.8 / 5e4, rel=1e-12)
    # the capstan ratio between the branches stays exact with a compliant sheath
    tr = TR.block({"sheath_ea_n": 5e4})
    ratio = ts.compliance_release(tr, 0.4) / ts.compliance_pull(tr, 0.4)
    assert ratio == pytest.approx(math.exp(0.15 * (math.pi / 2 + 0.4)), rel=1e-12)


def test_routing_wrap_adds_to_the_total_bend() -> None:
    tr = TR.block({"routing_wrap_rad": 1.0})
    assert ts.total_wrap_rad(tr, -0.5) == pytest.approx(1.0 + math.pi / 2 + 0.5)


def test_valid_twist_is_the_elastic_limit_on_the_soft_branch() -> None:
    tr = TR.block()
    f_lim = ts.ELASTIC_STRAIN * 193e9 * math.pi * 0.6e-3**2
    assert TR.valid_twist_rad(tr) == pytest.approx(f_lim * ts.compliance_release(tr, 0.0) / 0.025)
    # a compliant sheath twists further before the tendon reaches the same tension
    assert TR.valid_twist_rad(TR.block({"sheath_ea_n": 5e3})) > 10.0 * TR.valid_twist_rad(tr)


def test_friction_step_is_the_exact_solution_of_the_state_rate() -> None:
    tr = TR.block({"friction_speed_rad_s": 0.0})
    x, z, dx = 0.04, -0.3, 2e-3
    n = 2000
    zz = z
    for _ in range(n):  # fine explicit integration at constant x (presliding held fixed)
        zz += (dx / n) * ts.state_rate(tr, x, 1.0, 0.0, act_at(zz), 0, 0, 1.0)
    assert ts.friction_step(tr, x, dx, 0.0, z) == pytest.approx(zz, rel=1e-3)
    assert ts.friction_step(tr, x, 0.0, 0.0, z) == z


def test_mobilised_friction_grows_with_the_sliding_speed() -> None:
    # friction_speed_rad_s (Table 1's rate effect): the ramp's target is |v| / (|v| + v0)
    # (the default v0 is fitted to Tables 1-2 on seed 004's bench: tests/test_reproduce_measure004)
    tr = TR.block({"friction_speed_rad_s": 0.1})
    assert ts.friction_fraction(tr, 0.02) / ts.friction_fraction(tr, 0.06) == pytest.approx(
        4.0 / 9.0
    )  # (0.02 / 0.12) / (0.06 / 0.16)
    assert ts.friction_fraction(tr, -0.04) / ts.friction_fraction(tr, 0.06) == pytest.approx(
        0.7619, abs=1e-4
    )  # (0.04 / 0.14) / (0.06 / 0.16): the sign of v does not matter
    assert ts.friction_fraction(TR.block({"friction_speed_rad_s": 0.0}), 1e-6) == 1.0
    # a slow step stops at its target; at rest the state holds
    z = ts.friction_step(tr, 0.05, 0.5, 0.0, -1.0, 25.0)  # 0.02 rad/s
    assert z == pytest.approx(ts.friction_fraction(tr, 0.02))
    assert ts.state_rate(tr, 0.05, 0.0, 0.3, act_at(0.8), 0, 0, 0.0) == 0.0
    assert ts.friction_step(tr, 0.05, 0.0, 0.3, 0.8, 28.0) == 0.8
    # a fast step (the arm's motor speeds) mobilises ~all of it
    assert ts.friction_step(tr, 0.05, 0.5, 0.0, -1.0, 0.1) > 0.98
    default = TR.block()
    assert ts.friction_step(default, 0.05, 0.5, 0.0, -1.0, 0.1) > 0.97


def test_play_inside_the_data_range_is_not_resolved() -> None:
    # gap(theta2) = dP th^2 + dQ th + dM ~ G cos(theta2) + b = (G + b) - G th^2 / 2: b = dM + 2 dP,
    # evaluated from the fitted terms themselves (no extrapolation beyond the data)
    rows = [*ts.TABLE_2_BEND.values(), *ts.TABLE_1_VELOCITY.values()]
    b = []
    for row in rows:
        dp, _, dm = _separations(row)
        b.append(dm + 2.0 * dp)
    assert b == pytest.approx([0.008, 0.062, 0.067, 0.114, 0.013, -0.001], abs=1e-9)
    mean, spread = float(np.mean(b)), float(np.std(b))
    largest_me = max(v[3] for row in rows for v in row.values())
    assert mean == pytest.approx(0.044, abs=1e-3) and spread > 0.9 * mean
    assert spread < largest_me  # within the fits' own maximal error: no play resolved
    assert TR.block()[ts.I_BACKLASH] == 0.0
