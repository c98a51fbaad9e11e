"""Seed 002's QA-Joint bench (eq. 14-15, Table V): throws, eq. 20 adjustment, impact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.plant.transmissions import qa_joint as qa
from fsarm_sim.studies import qa_joint_experiments as qx

DEG = math.pi / 180.0


def test_batched_joint_torque_is_the_transmission_kernel() -> None:
    rng = np.random.default_rng(1)
    b = qx.bench(7.0)
    p = qx._p(b)
    x = rng.uniform(-0.15, 0.15, 50)
    sig = rng.uniform(3 * DEG, 15 * DEG, 50)
    z = rng.uniform(-1.0, 1.0, 50)
    tau, _ = qx.joint_torque(p, x, sig, z)
    ref = [
        qa.torque_nm(b.block, xi, 0.0, 0.0, np.array([si, zi]), 0)
        for xi, si, zi in zip(x, sig, z, strict=True)
    ]
    assert tau == pytest.approx(ref, rel=1e-12, abs=1e-12)


def test_table_v_is_the_bench() -> None:
    b = qx.bench(9.0)
    assert (b.link_inertia, b.motor_inertia) == (0.523808, 0.993374)
    assert (b.kp, b.kd, b.tau_m_max) == (25371.0, 288.0, 160.0)
    assert b.block[qa.I_SIGMA_CMD] == pytest.approx(9.0 * DEG)
    assert b.block[qa.I_A_S] == qa.TABLE_IV[9.0][0]


def test_best_throw_reaches_the_deflection_limit_and_amplifies_speed() -> None:
    t75 = qx.best_throw(qx.bench(7.0), 75.0)
    t90 = qx.best_throw(qx.bench(7.0), 90.0)
    for t in (t75, t90):
        assert t.feasible
        # the premise: maximum deflection, never beyond the end stop (within the slack)
        assert 0.98 * 7.0 <= t.phi_max_deg <= 1.02 * 7.0
        assert t.tau_j_max_nm <= qx.TAU_J_MAX_NM
        assert 1.0 < t.epsilon < 4.0  # one switch: at most 1 + 3 for a linear spring
    # with the deflection amplitude pinned at sigma, the spring adds the same speed on top of v
    gain75 = t75.link_velocity_deg_s - 75.0
    gain90 = t90.link_velocity_deg_s - 90.0
    assert gain75 == pytest.approx(gain90, rel=0.03)
    assert t90.epsilon < t75.epsilon  # Sec. VI: epsilon degrades with motor velocity


def test_too_fast_for_the_stiff_preset_is_infeasible() -> None:
    t = qx.best_throw(qx.bench(3.0), 120.0)
    assert not t.feasible and math.isnan(t.epsilon)


def test_eq20_adjustment_speeds_the_link_up() -> None:
    b = qx.bench(9.0)
    const = qx.best_throw(b, 90.0)
    ideal = qx.best_throw(b, 90.0, adjust="ideal")
    drive = qx.best_throw(b, 90.0, adjust="drive")
    assert const.link_velocity_deg_s < drive.link_velocity_deg_s < ideal.link_velocity_deg_s


def test_adjustment_trace_follows_the_deflection_in_relaxation() -> None:
    b = qx.bench(9.0)
    batch = qx.simulate_throws(b, 90 * DEG, np.array([0.1]), adjust="ideal", keep_trace=True)
    phi, sig = batch.traces["phi"][:, 0], batch.traces["sigma"][:, 0]
    t = batch.traces["t"][:, 0]
    changed = (np.abs(sig - 9 * DEG) > 1e-9) & (t <= batch.t_final[0])
    assert changed.sum() > 100
    # where the preset moved (until the final time), it is the clamped deflection a step before
    idx = np.flatnonzero(changed)
    idx = idx[idx > 0]
    expect = np.clip(phi[idx - 1], 3 * DEG, 15 * DEG)
    assert sig[idx] == pytest.approx(expect, abs=1e-12)


def test_impact_softer_preset_lowers_the_joint_torque() -> None:
    stiff = qx.impact(3.0, 0.3, duration_s=0.25)
    soft = qx.impact(15.0, 0.3, duration_s=0.25)
    assert soft.peak_joint_torque_nm < stiff.peak_joint_torque_nm
    assert stiff.peak_contact_force_n > 1000.0  # a rigid metal contact: kN (Sec. VII: up to 5 kN)


def test_bad_arguments_raise_named_errors() -> None:
    b = qx.bench(7.0)
    with pytest.raises(qx.QaExperimentError):
        qx.bench(8.0)  # no Table IV row
    with pytest.raises(qx.QaExperimentError):
        qx.simulate_throws(b, 0.0, np.array([0.0]))
    with pytest.raises(qx.QaExperimentError):
        qx.simulate_throws(b, 1.0, np.array([-0.1]))
    with pytest.raises(qx.QaExperimentError):
        qx.simulate_throws(b, 1.0, np.array([0.0]), adjust="fast")
    with pytest.raises(qx.QaExperimentError):
        qx.impact(7.0, 0.0)
