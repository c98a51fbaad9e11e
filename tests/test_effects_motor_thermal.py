"""Joint 3's motor warming (plant/effects/motor_thermal.py): the thermal node as physics (steady
rise R_th P, time constant R_th C_th, cooling), the torque constant's fall with temperature, and
the law on the arm through the registry (its temperature in the record, native = python)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.discrepancy import arm_synth
from fsarm_sim.engine.model import Effects, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import motor_thermal as mt
from fsarm_sim.plant.effects.base import S_COEF_M, S_OWN, S_TAU_ROTOR
from fsarm_sim.sim.simulation import run_scenario

BLK = np.array([d.default for d in mt.KERNEL_PARAMS])
COEF_M = 1.0 / 16.0


def _state(tau: float, dtemp: float) -> tuple[float, ...]:
    s = [0.0] * (S_OWN + 1)
    s[S_TAU_ROTOR], s[S_COEF_M], s[S_OWN] = tau, COEF_M, dtemp
    return tuple(s)


def _heat(blk: np.ndarray, tau: float, dtemp: float, seconds: float, h: float = 0.05) -> float:
    for _ in range(round(seconds / h)):
        dtemp += h * mt.state_rate(blk, _state(tau, dtemp), 0)
    return dtemp


def test_steady_temperature_is_ambient_plus_r_th_times_the_loss() -> None:
    tau = 0.42  # the motor's continuous need (models/fsarm/README.md)
    blk = BLK.copy()
    blk[5] = 0.0  # constant resistance: P = R_0 (tau / k_t)^2
    rise = _heat(blk, tau, 0.0, 20 * blk[1] * blk[2], h=1.0)  # the fixed point is h's too
    power = blk[4] * (tau / blk[3]) ** 2
    assert rise == pytest.approx(blk[1] * power, rel=1e-6)
    # copper's resistance rises with the temperature: a higher fixed point, still R_th P(T)
    hot = _heat(BLK, tau, 0.0, 20 * BLK[1] * BLK[2], h=1.0)
    assert hot > rise
    assert hot == pytest.approx(mt.steady_rise_k(mt.copper_loss_w(tau, hot, BLK), BLK), rel=1e-6)


def test_the_node_heats_with_its_time_constant_and_cools_to_ambient() -> None:
    blk = BLK.copy()
    blk[5] = 0.0
    tau_th = blk[1] * blk[2]
    final = blk[1] * blk[4] * (0.5 / blk[3]) ** 2
    after = _heat(blk, 0.5, 0.0, tau_th, h=0.01)
    assert after == pytest.approx(final * (1.0 - math.exp(-1.0)), rel=1e-3)
    cooled = _heat(blk, 0.0, after, 10 * tau_th, h=1.0)
    assert 0.0 <= cooled < 1e-3 * after  # no command: back to ambient, never below it


def test_a_hot_motor_gives_less_torque_by_the_torque_constant() -> None:
    tau = 0.8
    blk = BLK.copy()
    assert mt.arm_torques(blk, _state(tau, 0.0)) == (0.0, 0.0, 0.0)  # at 25 C: as commanded
    blk[0] = 20.0  # a warm cabinet
    t2, t3, tm = mt.arm_torques(blk, _state(tau, 30.0))
    assert (t2, t3) == (0.0, 0.0)
    lost_at_rotor = tau * blk[6] * 50.0  # -0.1 %/K over 50 K: 5 % of the command
    assert tm * COEF_M == pytest.approx(lost_at_rotor, rel=1e-12)
    assert lost_at_rotor == pytest.approx(-0.05 * tau)
    assert mt.torque_factor(30.0, blk) == pytest.approx(0.95)


def test_on_the_arm_the_temperature_is_recorded_and_native_matches_python() -> None:
    hot = (("dtemp_amb_k", 100.0), ("c_th_j_per_k", 0.5))  # a small node: visible in 1 s
    cfg = SimConfig(effects=Effects(laws=(("motor_thermal", hot),)))
    runs = {
        b: run_scenario("fig14-sine", cfg, duration_s=1.0, backend=b) for b in ("python", "native")
    }
    base = run_scenario("fig14-sine", SimConfig(), duration_s=1.0)
    col = "motor_thermal.dtemp_k"
    rise = runs["native"].columns[col]
    assert np.array_equal(rise, runs["python"].columns[col])
    assert np.array_equal(runs["native"].columns["theta_m"], runs["python"].columns["theta_m"])
    assert rise[0] == 0.0 and rise[-1] > 0.0 and np.all(rise >= 0.0)
    assert col not in base.columns
    # 10 % less torque per ampere: the speed loop commands more for the same motion
    tau_hot = np.abs(runs["native"].columns["tau_motor"])
    tau_cold = np.abs(base.columns["tau_motor"])
    assert np.mean(tau_hot) > 1.05 * np.mean(tau_cold)


def test_bad_parameters_are_named_errors() -> None:
    with pytest.raises(InvalidParameterError, match=r"motor_thermal.r_th_k_per_w must be within"):
        SimConfig(effects=Effects(laws=(("motor_thermal", (("r_th_k_per_w", 0.0),)),))).validate()


def test_the_arm_diagnosis_vocabulary_knows_it() -> None:
    name, variant, params = arm_synth.parse_arm_effect("motor_thermal=60")
    assert (name, variant) == ("motor_thermal", "j3_motor")
    assert params == {"dtemp_amb_k": 60.0}
