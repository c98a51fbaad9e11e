"""The transmission interface and registry, and every transmission on the arm.

Per-seed published numbers are tested in tests/test_transmission_<name>.py; here: the interface
contract for every registered transmission, its wiring into the simulator, and physics on the
arm (energy without dissipation, dissipation with it, determinism, start in equilibrium).
"""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.cli.transmissions import parse_params
from fsarm_sim.engine.model import Effects, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.plant.transmissions.base import N_STATES, TransmissionError
from fsarm_sim.sim.simulation import initial_state, run_scenario

from conftest import hold_table, joint3_gravity_balance, run_fsarm

NAMES = transmissions.names()


def test_registry_names_and_errors() -> None:
    assert NAMES[0] == transmissions.DEFAULT == "flexible-shaft"
    assert len(set(NAMES)) == len(NAMES) == 5
    with pytest.raises(TransmissionError, match="known: flexible-shaft"):
        transmissions.get("harmonic-drive")
    for n in NAMES:
        assert transmissions.by_kind(transmissions.get(n).kind).name == n


@pytest.mark.parametrize("name", NAMES)
def test_interface_contract(name: str) -> None:
    """Sources stated, stiffness = d(sensor torque)/d(twist), potential' = torque, at rest the
    true torque equals the sensor's, a block rejects unknown/non-finite overrides."""
    tr = transmissions.get(name)
    assert tr.title and tr.source and tr.params
    assert all(p.source for p in tr.params)
    assert len(tr.states) <= N_STATES
    block = tr.block()
    with pytest.raises(TransmissionError, match="allowed"):
        tr.block({"no_such_parameter": 1.0})
    with pytest.raises(TransmissionError, match="finite"):
        tr.block({tr.params[0].name: math.nan})
    act = np.zeros(8)
    for i, v in enumerate(tr.initial_states(block, 0.0, 0.0)):
        act[2 + i] = v
    r = tr.twist_range_rad
    for bend in (0.0, 0.7) if tr.routed_over_joint2 else (0.0,):
        for x in np.linspace(-0.8 * r, 0.8 * r, 16):  # not at 0: a law may have a kink there
            h = 1e-6 * max(r, 1e-3)
            num = (tr.sensor_torque(block, x + h, bend) - tr.sensor_torque(block, x - h, bend)) / (
                2 * h
            )
            k = tr.stiffness(block, x, bend)
            assert k == pytest.approx(num, rel=1e-4, abs=1e-6 * max(1.0, abs(k)))
            dv = (
                tr.module.potential_j(block, x + h, bend, act, 2)
                - tr.module.potential_j(block, x - h, bend, act, 2)
            ) / (2 * h)
            if hasattr(tr.module, "spring"):
                # a spring carrying less than eq. 8 (the rest sits in slip elements, which
                # initial_states loads at rest): potential' = the spring's torque, and at rest
                # spring + elements = the sensor's torque
                kp, sp, kn, sn = tr.module.spring(block)
                k_sp = kp + sp * abs(bend) if x >= 0.0 else kn + sn * abs(bend)
                assert dv == pytest.approx(k_sp * x, rel=1e-4, abs=1e-7)
                rest = np.zeros(8)
                rest[2 : 2 + N_STATES] = tr.initial_states(block, x, bend)
                true = tr.module.torque_nm(block, x, 0.0, bend, rest, 2)
                # up to half the rating (near the rating the elements would slip before they take
                # their full share: the start falls short there by up to ~2 %)
                if abs(tr.sensor_torque(block, x, bend)) <= 0.5 * tr.rating_nm(block):
                    assert true == pytest.approx(tr.sensor_torque(block, x, bend), rel=1e-9)
            else:
                assert dv == pytest.approx(tr.sensor_torque(block, x, bend), rel=1e-4, abs=1e-7)
    assert tr.rating_nm(block) > 0.0
    assert tr.max_stiffness(block) > 0.0


def test_flexible_shaft_view_matches_the_shaft() -> None:
    sh = load_catalogue().shaft()
    cfg = SimConfig()
    tr = cfg.transmission_model()
    block, _ = cfg.transmission_blocks()
    for x, b in ((0.2, 0.0), (-0.3, 1.0), (0.05, -0.6)):
        side = 1 if x >= 0 else -1
        assert tr.sensor_torque(block, x, b) == pytest.approx(sh.k_series(b, side) * x)
    assert tr.twist_for_torque(block, 3.0, 0.5) == pytest.approx(3.0 / sh.k_series(0.5, 1))
    assert cfg.rating_nm() == sh.rating_nm


def test_config_errors_are_named() -> None:
    with pytest.raises(TransmissionError):
        build_model(SimConfig(transmission="nope"), hold_table(0, 0.5, 0.3))
    # the flexible shaft takes overrides of its catalogue values like any transmission, checked
    with pytest.raises(TransmissionError, match=r"eq\. 3 must stay > 0"):
        build_model(SimConfig(transmission_params=(("k_pos", 1.0),)), hold_table(0, 0.5, 0.3))
    plant, ctrl = SimConfig(transmission_params=(("k_pos", 250.0),)).transmission_blocks()
    assert plant[0] == ctrl[0] == 250.0  # None for the controller: it knows the plant's law
    with pytest.raises(TransmissionError, match="dissipative"):  # the module's own validation
        build_model(
            SimConfig(transmission="rtca", transmission_params=(("c", -1.0),)),
            hold_table(0, 0.5, 0.3),
        )
    assert parse_params(["a=1", " b = 2.5"]) == (("a", 1.0), ("b", 2.5))
    for bad in ("a", "a=", "=3", "a=nan", "a=x"):
        with pytest.raises(InvalidParameterError):
            parse_params([bad])


@pytest.mark.parametrize("name", NAMES)
def test_transmission_is_wired_into_the_kernels(name: str) -> None:
    """The arm's kernels apply exactly the module's torque, and the controller reads its law."""
    cfg = SimConfig(transmission=name, effects=Effects(control=False))
    m = build_model(cfg, hold_table(0.0, 0.6, 0.4))
    prm = m.numeric(layout.PARAMS_NAME).data
    st = read_structure(m)
    tr = cfg.transmission_model()
    block = cfg.transmission_blocks()[0]
    assert prm[layout.P_TRANS] == tr.kind
    d = mujoco.MjData(m)
    initial_state(m, d, st)
    rng = np.random.default_rng(1)
    for _ in range(10):
        x = rng.uniform(-0.5, 0.5) * tr.twist_range_rad
        xdot = rng.uniform(-1.0, 1.0)
        d.qpos[st.qadr[3]] = (st.coef_s * d.qpos[st.qadr[2]] + x) / st.coef_m
        d.qvel[st.dof[3]] = (st.coef_s * d.qvel[st.dof[2]] + xdot) / st.coef_m
        bend = d.qpos[st.qadr[1]]
        expected = tr.module.torque_nm(block, x, xdot, bend, d.act, st.act_slip)
        assert physics.shaft_torque(prm, d.qpos, d.qvel, d.act) == pytest.approx(
            expected, rel=1e-9, abs=1e-12
        )


@pytest.mark.parametrize("name", NAMES)
def test_every_transmission_starts_in_equilibrium_and_runs_fig14(name: str) -> None:
    """Start: the transmission holds joint 3's gravity torque; then fig14-sine runs to the end,
    deterministic, and the native path reproduces the Python path bit for bit."""
    cfg = SimConfig(transmission=name)
    held, gravity = joint3_gravity_balance(build_model(cfg, hold_table(0.0, math.radians(45), 0.0)))
    assert held == pytest.approx(gravity, rel=1e-6, abs=1e-9)
    a = run_scenario("fig14-sine", cfg, duration_s=2.0, backend="python")
    b = run_scenario("fig14-sine", cfg, duration_s=2.0, backend="native")
    for key in ("q3", "theta_m", "tau_shaft", "tau_model"):
        assert np.array_equal(a.columns[key], b.columns[key]), key
    assert np.all(np.isfinite(a.columns["q3"]))


def test_cli_lists_and_runs_a_transmission(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    assert run_fsarm(monkeypatch, "transmissions") == 0
    for n in NAMES:
        assert run_fsarm(monkeypatch, "transmissions", n) == 0
    assert run_fsarm(monkeypatch, "transmissions", "nope") == 2
    code = run_fsarm(
        monkeypatch,
        "run",
        "fig14-sine",
        "--transmission",
        NAMES[-1],
        "--duration",
        "0.5",
        "--out",
        str(tmp_path),
        "--backend",
        "native",
    )
    assert code == 0
    side = json.loads((tmp_path / "fig14-sine.json").read_text())
    assert side["transmission"]["name"] == NAMES[-1]  # the run says what drove joint 3
    block = transmissions.get(NAMES[-1]).block()
    assert list(side["transmission"]["params"].values()) == pytest.approx(
        list(block[: len(side["transmission"]["params"])])
    )
    assert run_fsarm(monkeypatch, "run", "fig14-sine", "--transmission", "nope") == 2
    assert run_fsarm(monkeypatch, "run", "fig14-sine", "--tr-param", "x") == 2


def test_magnetic_spring_output_friction_acts_on_joint_3() -> None:
    """Model F's frame-referenced bearing friction (tanh, 0.05 N*m) acts on the output side:
    i_G2 * tau on q3, opposing its motion, on top of the spring torque."""
    cfg = SimConfig(transmission="magnetic-spring", effects=Effects(control=False))
    m = build_model(cfg, hold_table(0.0, 0.6, 0.4))
    prm = m.numeric(layout.PARAMS_NAME).data
    st = read_structure(m)
    d = mujoco.MjData(m)
    initial_state(m, d, st)
    d.qvel[st.dof[2]] = 0.3  # q3 turning: theta_s' = 3 rad/s, twist rate -3 rad/s
    qfrc = np.zeros(m.nv)
    physics.passive_forces(prm, d.qpos, d.qvel, d.act, qfrc, np.zeros(layout.N_USERDATA))
    tau = physics.shaft_torque(prm, d.qpos, d.qvel, d.act)
    friction = qfrc[st.dof[2]] - st.coef_s * tau
    assert friction == pytest.approx(-st.coef_s * 0.05 * math.tanh(50.0 * 3.0), rel=1e-9)
