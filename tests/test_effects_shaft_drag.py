"""Shaft drag in the casing (plant/effects/shaft_drag.py): the law, and the law on the arm through
the registry (layout block, generated dispatch, SimConfig, native path, arm diagnosis vocabulary)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.discrepancy import arm_synth
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import Effects, SimConfig, build_model
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.effects import shaft_drag
from fsarm_sim.sim.simulation import run_scenario

DRAG = (("drag_nm", 0.05), ("mu_per_rad", 0.5))


def test_drag_opposes_the_input_speed_and_dissipates() -> None:
    for w in (-30.0, -1.0, -0.01, 0.01, 1.0, 30.0):
        tau = shaft_drag.drag_torque_nm(w, 0.3, 0.2, 0.5, 1.0)
        assert tau * w < 0.0  # power into the shaft input is negative
    assert shaft_drag.drag_torque_nm(0.0, 0.3, 0.2, 0.5, 1.0) == 0.0


def test_drag_is_coulomb_like_and_grows_with_bend_as_a_capstan() -> None:
    fast = shaft_drag.drag_torque_nm(20.0, 0.0, 0.2, 0.5, 1.0)
    assert fast == pytest.approx(-0.2, rel=1e-12)  # saturated: T_0
    for bend in (0.5, -0.5, 1.2):
        ratio = shaft_drag.drag_torque_nm(20.0, bend, 0.2, 0.5, 1.0) / fast
        assert ratio == pytest.approx(math.exp(0.5 * abs(bend)), rel=1e-12)
    assert shaft_drag.drag_torque_nm(20.0, 1.2, 0.2, 0.0, 1.0) == pytest.approx(fast)  # mu=0


def test_on_the_arm_the_drag_lands_on_the_rotor_only() -> None:
    ref = np.zeros((2, layout.REF_COLS))
    with_drag = build_model(SimConfig(effects=Effects(laws=(("shaft_drag", DRAG),))), ref)
    without = build_model(SimConfig(), ref)
    rotor = mujoco.mj_name2id(without, mujoco.mjtObj.mjOBJ_JOINT, "j3_rotor")
    q2 = mujoco.mj_name2id(without, mujoco.mjtObj.mjOBJ_JOINT, "q2")
    out = []
    for m in (with_drag, without):
        d = mujoco.MjData(m)
        d.qpos[m.jnt_qposadr[q2]] = 0.6  # bent route
        d.qvel[m.jnt_dofadr[rotor]] = 80.0  # rotor speed, theta_m_dot = 5 rad/s
        with callbacks.active("python"):
            mujoco.mj_forward(m, d)
        out.append(d.qfrc_passive.copy())
    diff = out[0] - out[1]
    coef_m = 1.0 / 16.0
    expected = coef_m * shaft_drag.drag_torque_nm(80.0 * coef_m, 0.6, 0.05, 0.5, 1.0)
    dof = without.jnt_dofadr[rotor]
    assert diff[dof] == pytest.approx(expected, rel=1e-9)
    assert np.count_nonzero(np.delete(diff, dof)) == 0


def test_drag_costs_motor_work_and_native_matches_python() -> None:
    cfg = SimConfig(effects=Effects(laws=(("shaft_drag", DRAG),)))
    runs = {
        b: run_scenario("fig14-sine", cfg, duration_s=1.0, backend=b) for b in ("python", "native")
    }
    base = run_scenario("fig14-sine", SimConfig(), duration_s=1.0, backend="native")
    assert runs["native"].metrics["motor_energy_j"] > base.metrics["motor_energy_j"]
    for key in ("motor_energy_j", "tau_estimate_rmse_nm"):
        assert runs["python"].metrics[key] == runs["native"].metrics[key]


def test_bad_drag_parameters_are_named_errors() -> None:
    with pytest.raises(InvalidParameterError, match=r"shaft_drag.drag_nm must be within \[0, 2\]"):
        SimConfig(effects=Effects(laws=(("shaft_drag", (("drag_nm", 5.0),)),))).validate()
    with pytest.raises(InvalidParameterError, match="shaft_drag has no parameter 'f'"):
        SimConfig(effects=Effects(laws=(("shaft_drag", (("f", 0.1),)),))).validate()


def test_the_arm_diagnosis_vocabulary_knows_it() -> None:
    name, variant, params = arm_synth.parse_arm_effect("shaft_drag=0.05,0.5")
    assert (name, variant) == ("shaft_drag", "casing")
    assert params == {"drag_nm": 0.05, "mu_per_rad": 0.5}
