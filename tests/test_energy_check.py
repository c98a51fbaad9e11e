"""The free, undamped arm conserves energy with every transmission, bent or not (issue 13)."""

from __future__ import annotations

import math

import pytest

from fsarm_sim.engine.model import build_model
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant import transmissions
from fsarm_sim.studies.energy_check import conservative_config, free_arm_energy_drift

NAMES = transmissions.names()
MAX_DRIFT_J = 1e-6


@pytest.mark.parametrize("name", NAMES)
def test_energy_is_constant_on_the_free_bent_arm(name: str) -> None:
    r = free_arm_energy_drift(name)
    assert r.bend_rad >= math.radians(45.0)
    assert r.bend_swing_rad > 0.5  # joint 2 really moved the bend under the twisted transmission
    assert r.drift_j <= MAX_DRIFT_J, f"{name}: {r.drift_j:.3g} J of {r.energy_j:.3g} J"
    if transmissions.get(name).name in ("flexible-shaft", "rtca"):  # laws that read the bend
        assert r.coupling_work_j > 1000 * MAX_DRIFT_J


def test_without_the_coupling_torque_a_routed_bend_dependent_law_drifts() -> None:
    """The check can fail: switch the -dV/dphi_B term off and the RTCA shaft's energy drifts."""
    on = free_arm_energy_drift("rtca")
    assert on.coupling_work_j > 1e-3  # the RTCA law changes with the bend along the swing
    off = free_arm_energy_drift_without_coupling("rtca")
    assert off > 1e-4 > 100 * MAX_DRIFT_J


def free_arm_energy_drift_without_coupling(name: str) -> float:
    from fsarm_sim.studies import energy_check

    original = energy_check.build_model

    def build_without(cfg, table):  # type: ignore[no-untyped-def]
        m = original(cfg, table)
        m.numeric(layout.PARAMS_NAME).data[layout.P_EN_COUPLING] = 0.0
        return m

    energy_check.build_model = build_without  # type: ignore[assignment]
    try:
        return energy_check.free_arm_energy_drift(name).drift_j
    finally:
        energy_check.build_model = original  # type: ignore[assignment]


@pytest.mark.parametrize("name", NAMES)
def test_coupling_torque_is_minus_the_bend_derivative_of_the_stored_energy(name: str) -> None:
    cfg = conservative_config(name)
    import numpy as np

    table = np.zeros((1, layout.REF_COLS))
    table[0, :3] = (0.0, 0.7, 0.3)
    m = build_model(cfg, table)
    prm = m.numeric(layout.PARAMS_NAME).data
    import mujoco

    d = mujoco.MjData(m)
    from fsarm_sim.engine.model import read_structure

    st = read_structure(m)
    d.qpos[st.qadr[1]] = 0.7
    d.qpos[st.qadr[3]] = 0.15 * cfg.transmission_model().twist_range_rad / st.coef_m
    h = 1e-4
    q = d.qpos.copy()
    q[st.qadr[1]] += h
    v_up = physics.shaft_potential(prm, q, d.act)
    q[st.qadr[1]] -= 2 * h
    v_down = physics.shaft_potential(prm, q, d.act)
    bend_only = physics.bending_torques(prm, d.qpos, d.qvel, d.act)[0]
    expected = -(v_up - v_down) / (2 * h)  # includes the bending spring's own moment
    assert bend_only == pytest.approx(expected, rel=1e-5, abs=1e-8)


@pytest.mark.parametrize("name", NAMES)
def test_every_transmission_states_minus_dv_dbend(name: str) -> None:
    """Each module's bend_torque_nm is -d(potential_j)/d(bend), with its published parameters."""
    import numpy as np

    tr = transmissions.get(name)
    block = (
        tr.block()
        if name != transmissions.DEFAULT
        else conservative_config(name).transmission_blocks()[0]
    )
    rng = np.random.default_rng(7)
    act = np.zeros(8)
    h = 1e-6
    for _ in range(20):
        x = rng.uniform(-0.4, 0.4) * tr.twist_range_rad
        bend = rng.uniform(0.05, 1.5) * rng.choice([-1.0, 1.0])
        v_up = tr.module.potential_j(block, x, bend + h, act, 0)
        v_down = tr.module.potential_j(block, x, bend - h, act, 0)
        got = tr.module.bend_torque_nm(block, x, bend, act, 0)
        assert got == pytest.approx(-(v_up - v_down) / (2 * h), rel=1e-5, abs=1e-9), (x, bend)


def _stuck_elements_drift(unwinding_ratio: float, timestep_s: float):  # type: ignore[no-untyped-def]
    import dataclasses

    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import energy_check

    sh = load_catalogue().shaft(series_hysteresis=True)
    assert sh.bend_friction_per_rad > 0.0
    stuck = dataclasses.replace(
        sh, slip_f=tuple(100.0 * f for f in sh.slip_f), slip_unwinding_ratio=unwinding_ratio
    )
    original = energy_check.conservative_config

    def with_stuck_elements(name: str, dt: float = energy_check.DEFAULT_TIMESTEP_S):  # type: ignore[no-untyped-def]
        cfg = original(name, dt)
        return cfg.with_(shaft=stuck, effects=dataclasses.replace(cfg.effects, slip=True))

    energy_check.conservative_config = with_stuck_elements  # type: ignore[assignment]
    try:
        return energy_check.free_arm_energy_drift("flexible-shaft", timestep_s=timestep_s)
    finally:
        energy_check.conservative_config = original  # type: ignore[assignment]


def test_stuck_slip_elements_conserve_energy_whatever_the_bend() -> None:
    """The shaft's Maxwell-slip elements (band growing with the bend, asymmetric), never slipping
    (slip torques x100): stuck elements are springs whose energy does not depend on the bend, so
    the free arm keeps its energy with them as without them."""
    for ratio in (1.0, 0.6):
        r = _stuck_elements_drift(ratio, 5e-5)
        assert r.coupling_work_j > 1e-3  # eq. 3's own -dV/dphi_B is exercised
        assert r.drift_j <= MAX_DRIFT_J, r
