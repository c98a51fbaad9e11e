"""The shaft in the arm, tested as physics: energy, momentum, statics, estimates, dissipation."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import Effects, Gains, SimConfig, build_model, read_structure
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant.effects import bend_friction
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.sim.simulation import initial_state, raise_on_warning

from conftest import hold_table


def _free_arm(dt: float, *, shaft: ShaftParams | None = None, **fx: bool) -> tuple:
    """Uncontrolled arm, joint damping off, joint limits off (their constraint is dissipative)."""
    cfg = SimConfig(
        shaft=shaft or load_catalogue().shaft(series_hysteresis=False),
        effects=Effects(control=False, **fx),
        joint_damping=False,
        integrator="RK4",
        timestep_s=dt,
        gains=Gains(ctrl_dt_s=dt),
    )
    m = build_model(cfg, hold_table(0.0, 0.6, 0.4))
    m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT
    d = mujoco.MjData(m)
    st = read_structure(m)
    initial_state(m, d, st)
    d.qpos[st.qadr[3]] += 0.3 / st.coef_m  # extra twist: the shaft oscillates
    d.qvel[st.dof[0]] = 0.5
    d.qvel[st.dof[1]] = 0.8
    return m, d, st


def _energy_trace(
    m: mujoco.MjModel, d: mujoco.MjData, seconds: float
) -> tuple[np.ndarray, np.ndarray]:
    prm = m.numeric(layout.PARAMS_NAME).data
    st = read_structure(m)
    e, p1 = [], []
    full = np.zeros((m.nv, m.nv))
    with callbacks.active("python"):
        for _ in range(round(seconds / m.opt.timestep)):
            mujoco.mj_forward(m, d)
            e.append(d.energy[0] + d.energy[1] + physics.shaft_potential(prm, d.qpos, d.act))
            mujoco.mj_fullM(m, d, full)
            p1.append((full @ d.qvel)[st.dof[0]])
            mujoco.mj_step(m, d)
    raise_on_warning(d)
    return np.array(e), np.array(p1)


def test_energy_conserved_without_dissipation_and_converges() -> None:
    drifts = []
    for dt in (1e-3, 5e-4):
        m, d, _ = _free_arm(dt, conduit=False)
        e, _ = _energy_trace(m, d, 1.0)
        drifts.append(np.ptp(e))
    # total mechanical energy (kinetic + gravity + shaft springs) of a ~20 J system
    assert drifts[1] < 1e-4
    assert drifts[1] < drifts[0] / 3.0  # converges with the time step


def test_energy_never_rises_with_dissipation() -> None:
    shaft = load_catalogue().shaft(series_hysteresis=True)
    shaft = ShaftParams(**{**shaft.__dict__, "damping_pos": 0.02, "damping_neg": 0.01})
    m, d, _ = _free_arm(5e-4, shaft=shaft, conduit=True, slip=True)
    e, _ = _energy_trace(m, d, 1.0)
    assert e[-1] < e[0] - 0.1  # something was dissipated
    assert np.max(np.diff(e)) < 2e-5  # never rises beyond the integrator's error of the test above


def test_reaction_torques_are_internal() -> None:
    """No torque about joint 1's axis comes from outside: p_q1 = (M qdot)_q1 is conserved."""
    m, d, _ = _free_arm(5e-4, conduit=True, slip=True)
    _, p1 = _energy_trace(m, d, 1.0)
    assert np.ptp(p1) < 1e-9
    assert abs(p1[0]) > 0.1


def _static_hold(q3: float, bend: float, shaft: ShaftParams) -> tuple[float, float, float]:
    m = build_model(
        SimConfig(shaft=shaft, effects=Effects(control=False)), hold_table(0.0, bend, q3)
    )
    d = mujoco.MjData(m)
    st = read_structure(m)
    initial_state(m, d, st)
    with callbacks.active("python"):
        mujoco.mj_forward(m, d)
    twist = st.coef_m * d.qpos[st.qadr[3]] - st.coef_s * d.qpos[st.qadr[2]]
    gravity = d.qfrc_bias[st.dof[2]]
    return twist, gravity, d.qfrc_passive[st.dof[2]]


@pytest.mark.parametrize(("q3", "side"), [(0.9, -1), (-0.9, +1)])
def test_static_twist_is_torque_over_stiffness_on_each_side(
    q3: float, side: int, prototype: ShaftParams
) -> None:
    bend = 0.7
    twist, gravity, passive = _static_hold(q3, bend, prototype)
    assert np.sign(twist) == side
    tau_shaft = gravity / 10.0  # i_G2 = 10
    assert twist == pytest.approx(tau_shaft / prototype.k_series(bend, side), rel=1e-9)
    # and the shaft then holds joint 3 statically: passive torque balances gravity
    assert passive == pytest.approx(gravity, rel=1e-9)


def test_joint2_static_relief_about_8nm_at_90deg(prototype: ShaftParams) -> None:
    """Hold the arm with joint 2 at 90 deg under position control: the joint-2 motor needs about
    8 N*m less with the bent shaft than without (controller not told about the shaft)."""
    from fsarm_sim.sim.simulation import Simulation

    torques = []
    for bending in (True, False):
        cfg = SimConfig(
            shaft=prototype,
            effects=Effects(bending=bending),
            gains=Gains(bend_compensation=False),
        )
        sim = Simulation(cfg, hold_table(0.0, math.pi / 2, 0.0))
        cols, _ = sim.run(3.0)
        torques.append(cols["tau2"][-1])
    relief = abs(torques[1]) - abs(torques[0])  # |without shaft| - |with shaft|
    assert relief == pytest.approx(8.0, abs=0.1)


def test_torque_estimate_matches_truth_and_sees_hysteresis() -> None:
    from fsarm_sim.sim.simulation import run_scenario

    no_hysteresis = SimConfig(shaft=load_catalogue().shaft(series_hysteresis=False))
    exact = run_scenario("fig14-sine", no_hysteresis, duration_s=2.0).metrics
    assert exact["tau_estimate_max_abs_err_nm"] < 1e-12  # same eq. 8, same encoders, same instant
    shaft = load_catalogue().shaft(series_hysteresis=True)
    hyst = run_scenario("fig14-sine", SimConfig(shaft=shaft), duration_s=2.0)
    err = hyst.columns["tau_shaft"] - hyst.columns["tau_model"]
    # the virtual sensor cannot see the slip elements: its error is bounded by their slip torques
    # (straight winding-side values grown by the bend friction at fig14-sine's 45 deg)
    grown = bend_friction.factor(math.radians(45.0), shaft.bend_friction_per_rad)
    assert 0.01 < np.max(np.abs(err)) <= sum(shaft.slip_f) * grown + 1e-9


def test_series_hysteresis_loop_in_the_arm_dissipates() -> None:
    """With the 15 kg payload the twist swings ~0.17 rad: over one full 4 s period the net work
    done on the shaft (the torque-twist loop area) is positive with slip hysteresis, ~0 without."""
    from fsarm_sim.sim.simulation import run_scenario

    works = []
    for hysteresis in (True, False):
        shaft = load_catalogue().shaft(series_hysteresis=hysteresis)
        c = run_scenario(
            "fig14-sine", SimConfig(shaft=shaft), duration_s=8.0, payload_kg=15.0
        ).columns
        cycle = (c["t"] >= 4.0) & (c["t"] <= 8.0)
        tau, twist = c["tau_shaft"][cycle], c["twist"][cycle]
        assert np.ptp(twist) > 0.1
        works.append(float(np.sum(0.5 * (tau[1:] + tau[:-1]) * np.diff(twist))))
    assert works[0] > 0.05  # J per cycle
    assert abs(works[1]) < 0.1 * works[0]


@pytest.mark.parametrize("width", [0.0, 0.02])
def test_the_passive_kernel_bends_joint_2_as_the_torque_from_the_state(width: float) -> None:
    """The passive kernel hands its twist (through the backlash) and bend to the bend coupling;
    the torque on joint 2 it logs is bending_torques' from qpos, bit for bit, in the play and out
    of it."""
    play = (("backlash", (("width_rad", width),)),) if width else ()
    cfg = SimConfig(effects=Effects(control=False, laws=play))
    m = build_model(cfg, hold_table(0.0, 0.6, 0.4))
    prm = m.numeric(layout.PARAMS_NAME).data
    d = mujoco.MjData(m)
    st = read_structure(m)
    initial_state(m, d, st)
    seen = set()
    for twist in (0.004, -0.03, 0.2):  # inside the play (0.02 rad), beyond it, far beyond
        d.qpos[st.qadr[3]] = (twist + st.coef_s * d.qpos[st.qadr[2]]) / st.coef_m
        qfrc = np.zeros(m.nv)
        ud = np.zeros(layout.N_USERDATA)
        physics.passive_forces(prm, d.qpos, d.qvel, d.act, qfrc, ud)
        log = ud[layout.U_LOG :]
        total, conduit = physics.bending_torques(prm, d.qpos, d.qvel, d.act)
        assert log[layout.L_TAU_BEND] == total
        assert log[layout.L_TAU_CONDUIT] == conduit
        coupling = physics.bend_coupling_torque(prm, d.qpos, d.act)
        assert coupling == physics.bend_coupling_torque_at(
            prm, physics.transmitted_twist_angle(prm, d.qpos), d.qpos[st.qadr[1]], d.act
        )
        seen.add(coupling)
    assert len(seen) == 3  # the coupling depends on the twist these steps set
