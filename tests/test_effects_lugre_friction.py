"""LuGre friction at joint 3 (plant/effects/lugre_friction.py): the law as physics (Stribeck curve
at steady sliding, a sigma_0 spring in presliding, dissipation, a stable stiff step), and the law
on the arm through the registry (its own state in data.act and in the record, native = python)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.discrepancy import arm_synth
from fsarm_sim.engine.model import Effects, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import lugre_friction as lg
from fsarm_sim.plant.effects.base import S_OWN, S_QD3, S_TIMESTEP
from fsarm_sim.sim.simulation import run_scenario

BLK = np.array([d.default for d in lg.KERNEL_PARAMS])
H = 1e-3


def _state(v: float, z: float, h: float = H) -> tuple[float, ...]:
    s = [0.0] * (S_OWN + 1)
    s[S_QD3], s[S_TIMESTEP], s[S_OWN] = v, h, z
    return tuple(s)


def _settle(v: float, z: float, blk: np.ndarray, steps: int, h: float = H) -> float:
    for _ in range(steps):
        z += h * lg.state_rate(blk, _state(v, z, h), 0)
    return z


@pytest.mark.parametrize("v", [-1.0, -0.02, -0.005, 0.003, 0.01, 0.05, 1.3])
def test_steady_sliding_friction_is_the_stribeck_curve(v: float) -> None:
    blk = BLK.copy()
    blk[5] = 0.05  # with a viscous part
    # the step is exact at frozen v, so long steps settle it: >= 100 time constants g / (sigma_0 |v|)
    z = _settle(v, 0.0, blk, 400, h=0.05)
    _, tau3, _ = lg.arm_torques(blk, _state(v, z, 0.05))
    g = blk[0] + (blk[1] - blk[0]) * math.exp(-((v / blk[2]) ** 2))
    assert -tau3 == pytest.approx(math.copysign(g, v) + 0.05 * v, rel=1e-9)
    assert -tau3 == pytest.approx(lg.steady_friction_nm(v, blk), rel=1e-9)
    assert abs(z) == pytest.approx(g / blk[3], rel=1e-9)  # bristles bent to g / sigma_0


def test_the_stribeck_dip_lies_between_breakaway_and_coulomb() -> None:
    f = [lg.steady_friction_nm(v, BLK) for v in (1e-5, BLK[2], 10 * BLK[2])]
    assert f[0] == pytest.approx(BLK[1], rel=1e-6)  # F_s near rest
    assert BLK[0] < f[1] < BLK[1]
    assert f[2] == pytest.approx(BLK[0], rel=1e-9)  # F_c well past v_s


def test_at_rest_presliding_is_a_spring_sigma0() -> None:
    """A small displacement (far below F_c / sigma_0) bends the bristles as far: F = sigma_0 x,
    and at v = 0 the bristles hold (dz/dt = 0) whatever their deflection below g / sigma_0."""
    x_total = 0.01 * BLK[0] / BLK[3]
    n = 200
    z = 0.0
    for _ in range(n):
        z += H * lg.state_rate(BLK, _state(x_total / (n * H), z), 0)
    force = lg.friction_nm(0.0, z, BLK, H)  # at rest after the move
    assert force == pytest.approx(BLK[3] * x_total, rel=0.02)
    assert lg.state_rate(BLK, _state(0.0, z), 0) == 0.0
    assert lg.arm_torques(BLK, _state(0.0, z))[1] == pytest.approx(-BLK[3] * z, rel=1e-12)


def test_the_bristles_dissipate_over_a_cycle() -> None:
    """Net work of the friction on the joint over whole periods of an oscillation is negative."""
    w, amp, work, z = 2 * math.pi, 0.05, 0.0, 0.0
    for k in range(2000):  # two periods at 1 Hz
        v = amp * w * math.cos(w * k * H)
        work += H * lg.arm_torques(BLK, _state(v, z))[1] * v
        z += H * lg.state_rate(BLK, _state(v, z), 0)
    assert work < -2 * 4 * amp * BLK[0] * 0.9  # at least ~F_c per unit path


def test_a_stiff_step_lands_on_the_exact_solution_and_never_overshoots() -> None:
    """sigma_0 |v| h / g = 3000: one explicit step of the raw rate would overshoot 3000-fold."""
    blk = BLK.copy()
    blk[3] = 1e6
    v, z = 1.0, -0.3 / 1e6  # bristles bent the other way (a reversal)
    z1 = z + H * lg.state_rate(blk, _state(v, z), 0)
    g = lg.stribeck_nm(v, blk[0], blk[1], blk[2])
    a = blk[3] * abs(v) / g
    exact = v / a + (z - v / a) * math.exp(-a * H)
    assert z1 == pytest.approx(exact, rel=1e-12)
    assert abs(z1) <= g / blk[3] * (1 + 1e-12)


@pytest.mark.parametrize(("f_c", "f_s"), [(0.0, 0.1), (0.1, 0.0)])
def test_a_vanishing_stribeck_curve_never_kicks_the_joint(f_c: float, f_s: float) -> None:
    """g -> 0 at speed (F_c = 0) or at rest (F_s = 0): eq. 3's raw rate diverges there; the
    torque stays within sigma_0 |z| + 2 sigma_1 |z| / h of bristles bent at most g_max / sigma_0."""
    blk = BLK.copy()
    blk[0], blk[1] = f_c, f_s
    z, worst = 0.0, 0.0
    for v in np.concatenate([np.linspace(0.0, 2.0, 400), np.linspace(2.0, -2.0, 800)]):
        worst = max(worst, abs(lg.arm_torques(blk, _state(v, z))[1]))
        z += H * lg.state_rate(blk, _state(v, z), 0)
    bound = 0.1 / blk[3] * (blk[3] + 2 * blk[4] / H)  # |z| <= 0.1 / sigma_0, |z_ss - z| twice
    assert worst <= bound * (1 + 1e-9)


def test_without_friction_the_law_is_only_viscous() -> None:
    blk = BLK.copy()
    blk[0] = blk[1] = 0.0
    blk[5] = 0.2
    assert lg.arm_torques(blk, _state(0.5, 0.0))[1] == pytest.approx(-0.1)
    assert lg.state_rate(blk, _state(0.5, 0.01), 0) == pytest.approx(-0.01 / H)


def test_on_the_arm_the_bristle_state_is_recorded_and_native_matches_python() -> None:
    cfg = SimConfig(effects=Effects(laws=(("lugre_friction", (("f_c_nm", 0.8),)),)))
    runs = {
        b: run_scenario("step-q3", cfg, duration_s=0.7, backend=b) for b in ("python", "native")
    }
    base = run_scenario("step-q3", SimConfig(), duration_s=0.7)
    z = runs["native"].columns["lugre_friction.z_rad"]
    assert np.array_equal(z, runs["python"].columns["lugre_friction.z_rad"])
    assert np.array_equal(runs["native"].columns["q3"], runs["python"].columns["q3"])
    assert np.max(np.abs(z)) <= 0.8 * 1.5 / 1000.0 * (1 + 1e-9)  # |z| <= F_s / sigma_0
    assert np.max(np.abs(z)) > 0.0
    assert "lugre_friction.z_rad" not in base.columns
    assert not np.array_equal(runs["native"].columns["q3"], base.columns["q3"])


def test_bad_parameters_are_named_errors() -> None:
    with pytest.raises(InvalidParameterError, match=r"lugre_friction.f_c_nm must be within"):
        SimConfig(effects=Effects(laws=(("lugre_friction", (("f_c_nm", -1.0),)),))).validate()
    with pytest.raises(InvalidParameterError, match=r"lugre_friction.sigma0_nm_per_rad must be"):
        bad = (("sigma0_nm_per_rad", 1e9),)
        SimConfig(effects=Effects(laws=(("lugre_friction", bad),))).validate()


def test_the_arm_diagnosis_vocabulary_knows_it() -> None:
    name, variant, params = arm_synth.parse_arm_effect("lugre_friction=0.4,0.6")
    assert (name, variant) == ("lugre_friction", "q3")
    assert params == {"f_c_nm": 0.4, "f_s_nm": 0.6}
