"""The two test benches of seed 000 Fig. 5, tested as physics: statics, energy, dissipation, rate.

Every replay goes through ``bench_model.run_prescribed`` / ``run_torque_control``, which raise on any
MuJoCo warning (SimulationWarningError).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine.model import Effects
from fsarm_sim.errors import InvalidParameterError, ShaftRangeError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.effects import bend_friction, series_stiffness
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.plant.transmissions import flexible_shaft
from fsarm_sim.studies import bench


@pytest.fixture(scope="module")
def slip_shaft() -> ShaftParams:
    """Prototype shaft with the catalogue's example Maxwell-slip set switched on."""
    return load_catalogue().shaft(series_hysteresis=True)


def _loop_area(x: np.ndarray, y: np.ndarray) -> float:
    """Closed-loop integral of y dx (trapezoid), positive when the loop dissipates."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


# --- models ----------------------------------------------------------------------------------


def test_bench_models_compile_with_the_paper_ratios_and_run_without_warnings(
    prototype: ShaftParams, slip_shaft: ShaftParams
) -> None:
    s = bench.build_series_bench(slip_shaft, 0.01, math.radians(30))
    assert s.structure.coef_m == pytest.approx(1.0 / 91.0, rel=1e-15)  # 91:1 planetary
    assert s.structure.coef_s == 1.0
    assert s.structure.bend_qadr == -1  # the bend is a parameter, not a joint
    prm = s.params
    assert prm[layout.P_SETUP] == layout.SETUP_SERIES_BENCH
    assert prm[layout.P_EN_CONTROL] == 0.0  # the arm's control kernel never runs on a bench
    assert prm[layout.P_BEND_FIXED] == pytest.approx(math.radians(30))
    slip = prm[layout.P_TR + flexible_shaft.I_SLIP_K : layout.P_TR + flexible_shaft.I_SLIP_F]
    assert slip == pytest.approx(slip_shaft.slip_k)  # the shaft block carries its elements
    assert s.model.body("load_disc").inertia[0] == pytest.approx(0.01)
    blocked = bench.build_series_bench(prototype, "blocked", 0.0)
    assert blocked.structure.load_qadr == -1
    assert blocked.model.nv == 1  # only the rotor moves
    p = bench.build_parallel_bench(prototype, twist_rad=0.2)
    assert p.structure.motor_gear == 51.0  # 51:1 geared joint motor
    assert p.params[layout.P_SETUP] == layout.SETUP_PARALLEL_BENCH
    assert p.params[layout.P_EN_CONDUIT] == 1.0
    # the parallel bench has no slip states: the shaft block's elements are off
    assert not p.params[
        layout.P_TR + flexible_shaft.I_SLIP_K : layout.P_TR + flexible_shaft.I_SLIP_F
    ].any()
    t = np.linspace(0.0, 1.0, 201)
    cols = s.replay(0.2 * np.sin(2 * np.pi * 2.0 * t), t)
    assert tuple(cols) == bench.SERIES_COLUMNS
    assert np.all(np.isfinite(np.column_stack(list(cols.values()))))
    pc = p.replay(0.8 * np.sin(2 * np.pi * 1.0 * t), t)
    assert tuple(pc) == bench.PARALLEL_COLUMNS
    assert np.all(np.isfinite(pc["m_b"]))


# --- series bench ------------------------------------------------------------------------------


@pytest.mark.parametrize("bend_deg", [0.0, 15.0, 45.0, 90.0])
def test_blocked_series_bench_static_stiffness_is_eq8_per_side(
    prototype: ShaftParams, bend_deg: float
) -> None:
    """tau_s / twist = K_sp(phi) for twist > 0 and K_sn(phi) for twist < 0 (seed 000 eq. 8)."""
    bend = math.radians(bend_deg)
    t = np.linspace(0.0, 1.0, 101)
    theta_s0 = 0.05  # the blocked output's constant angle
    theta_m = theta_s0 + np.linspace(-0.4, 0.4, t.size)
    cols = bench.simulate_series_bench(theta_m, t, prototype, "blocked", bend, theta_s0=theta_s0)
    assert np.all(cols["theta_s"] == theta_s0)
    assert np.all(cols["phi_b"] == bend)
    twist = cols["theta_m"] - cols["theta_s"]
    pos, neg = twist > 1e-6, twist < -1e-6
    assert pos.sum() > 40 and neg.sum() > 40
    k_p, k_n = prototype.k_series(bend, 1), prototype.k_series(bend, -1)
    np.testing.assert_allclose(cols["tau_s"][pos] / twist[pos], k_p, rtol=1e-9)
    np.testing.assert_allclose(cols["tau_s"][neg] / twist[neg], k_n, rtol=1e-9)
    assert k_n < k_p


def test_maxwell_slip_loop_dissipates_the_elasto_slip_energy_independent_of_rate(
    slip_shaft: ShaftParams,
) -> None:
    """Per cycle of twist amplitude A each element i dissipates (f_p + f_n)(2A - (f_p + f_n)/k_i):
    its slip torques on the two sides at this bend (f_n = r_n f_p, both grown by the bend
    friction factor) times the twist travel less the element's band."""
    amp = 0.3
    bend = math.radians(45)
    g = bend_friction.factor(bend, slip_shaft.bend_friction_per_rad)
    assert g > 1.0 and slip_shaft.slip_unwinding_ratio < 1.0  # the default shaft's asymmetry
    expected = 0.0
    for k, f0 in zip(slip_shaft.slip_k, slip_shaft.slip_f, strict=True):
        band = f0 * g * (1.0 + slip_shaft.slip_unwinding_ratio)  # f_p + f_n
        expected += band * (2.0 * amp - band / k)
    areas = []
    for freq in (1.0, 4.0):
        t = np.linspace(0.0, 2.0 / freq, 2001)
        cols = bench.simulate_series_bench(
            amp * np.sin(2 * np.pi * freq * t), t, slip_shaft, "blocked", bend
        )
        second = t >= 1.0 / freq - 1e-12  # the second cycle: the first starts from relaxed
        twist = cols["theta_m"] - cols["theta_s"]
        areas.append(_loop_area(twist[second], cols["tau_s"][second]))
    assert areas[0] > 0.0
    assert areas[0] == pytest.approx(expected, rel=1e-3)
    assert areas[1] == pytest.approx(areas[0], rel=1e-3)  # rate-independent


def test_series_bench_conserves_energy_with_dissipation_off_and_motor_held(
    prototype: ShaftParams,
) -> None:
    """Load inertia on the shaft, motor held: kinetic + eq. 8 potential is constant."""
    t = np.linspace(0.0, 2.0, 2001)
    cols = bench.simulate_series_bench(
        np.zeros(t.size),
        t,
        prototype,
        0.01,
        math.radians(30),
        effects=Effects(slip=False),
        theta_s0=-0.2,  # twist +0.2 rad at rest: the load oscillates through both sides
        max_timestep_s=1e-4,
        diagnostics=True,
    )
    assert cols["twist"].min() < -0.1 and cols["twist"].max() > 0.19
    e = cols["energy_j"]
    e0 = e[0]
    assert e0 == pytest.approx(0.5 * prototype.k_series(math.radians(30), 1) * 0.04, rel=1e-12)
    assert np.max(np.abs(e - e0)) / e0 < 5e-3  # semi-implicit Euler: bounded, O(w h)
    period = 2 * np.pi / math.sqrt(prototype.k_series(math.radians(30), 1) / 0.01)
    first, last = t < 2 * period, t > t[-1] - 2 * period
    assert abs(e[last].mean() - e[first].mean()) / e0 < 1e-3  # no drift


def test_load_obeys_newton_and_damping_dissipates_what_it_should(prototype: ShaftParams) -> None:
    """J dw/dt = tau_s at the load; with bearing damping c the energy lost is int c w^2 dt."""
    t = np.linspace(0.0, 1.0, 10001)
    theta_m = 0.3 * np.sin(2 * np.pi * 3.0 * t)
    j = 0.02
    cols = bench.simulate_series_bench(
        theta_m, t, prototype, j, 0.0, max_timestep_s=1e-4, diagnostics=True
    )
    dw = np.diff(cols["omega_s"]) / np.diff(t)
    np.testing.assert_allclose(j * dw, cols["tau_s"][:-1], rtol=0, atol=1e-9)
    c = 0.05
    held = bench.simulate_series_bench(
        np.zeros(t.size),
        t,
        prototype,
        j,
        0.0,
        theta_s0=-0.2,
        load_damping_nms=c,
        max_timestep_s=1e-4,
        diagnostics=True,
    )
    e, w = held["energy_j"], held["omega_s"]
    lost = e[0] - e[-1]
    dissipated = float(np.sum(c * w[1:] ** 2 * np.diff(t)))
    assert lost > 0.5 * e[0]  # the oscillation decays noticeably
    assert lost == pytest.approx(dissipated, rel=2e-2)


def test_torque_loop_follows_a_sine_and_holds_a_step_on_the_blocked_bench(
    prototype: ShaftParams,
) -> None:
    b = bench.build_series_bench(prototype, "blocked", math.radians(45))
    t = np.linspace(0.0, 3.0, 3001)
    tau_d = np.where(t < 2.0, 3.0 * np.sin(2 * np.pi * 0.5 * t), 2.0)
    cols = b.run_torque_control(tau_d, t)
    assert set(bench.SERIES_COLUMNS) <= set(cols)
    err = cols["tau_s"] - cols["tau_d"]
    sine = (cols["t"] > 0.5) & (cols["t"] < 2.0)
    assert np.sqrt(np.mean(err[sine] ** 2)) < 0.02 * 3.0
    assert abs(err[-1]) < 1e-3  # integral action: no steady-state error on the held step


# --- parallel bench ------------------------------------------------------------------------------


def test_parallel_bench_static_moment_is_eq4_with_stiffening(prototype: ShaftParams) -> None:
    """Held at 90 deg the sensor reads K_b (phi + beta phi^3): ~8 N*m for the 9 x 450 prototype."""
    t = np.array([0.0, 0.5, 1.0])
    for phi in (math.pi / 2, -math.pi / 2, math.radians(30)):
        cols = bench.simulate_parallel_bench(np.full(3, phi), t, prototype)
        np.testing.assert_allclose(cols["m_b"], prototype.static_relief_nm(phi), rtol=1e-9)
    at90 = bench.simulate_parallel_bench(np.full(3, math.pi / 2), t, prototype)["m_b"][-1]
    assert at90 == pytest.approx(8.0, rel=1e-3)  # seed 000 Sec. V: about 8 N*m
    twisted = bench.simulate_parallel_bench(np.full(3, math.pi / 2), t, prototype, twist_rad=0.3)
    coupling = -series_stiffness.bend_coupling_torque_nm(
        0.3, math.pi / 2, prototype.s_pos, prototype.s_neg
    )
    assert twisted["m_b"][-1] - at90 == pytest.approx(coupling, rel=1e-9)
    assert 0.0 < abs(coupling) < 0.2  # "torsion does not change the bending moment noticeably"


def test_parallel_bench_loop_area_is_visco_elastic_and_grows_with_rate(
    prototype: ShaftParams,
) -> None:
    """phi = A sin(w t): each branch dissipates pi A^2 k w tau / (1 + (w tau)^2) per cycle."""
    amp = 1.0
    areas = {}
    for freq, cycles in ((0.05, 2), (0.5, 6)):
        w = 2 * np.pi * freq
        t = np.linspace(0.0, cycles / freq, cycles * 2000 + 1)
        cols = bench.simulate_parallel_bench(amp * np.sin(w * t), t, prototype)
        last = t >= (cycles - 1) / freq - 1e-12
        area = _loop_area(cols["phi_b"][last], cols["m_b"][last])
        expected = sum(
            math.pi * amp**2 * k * w * tau / (1.0 + (w * tau) ** 2)
            for k, tau in zip(prototype.conduit_k, prototype.conduit_tau, strict=True)
        )
        assert area == pytest.approx(expected, rel=5e-3)
        areas[freq] = area
    assert 0.0 < areas[0.05] < areas[0.5]
    # without the conduit the loop closes: elastic, stiffening and link inertia store, not dissipate
    t = np.linspace(0.0, 2.0, 4001)
    elastic = bench.simulate_parallel_bench(
        np.sin(2 * np.pi * 0.5 * t), t, prototype, effects=Effects(conduit=False)
    )
    assert abs(_loop_area(elastic["phi_b"], elastic["m_b"])) < 1e-3 * areas[0.5]


# --- determinism and bad inputs ----------------------------------------------------------------------


def test_same_inputs_give_identical_outputs(slip_shaft: ShaftParams) -> None:
    t = np.linspace(0.0, 0.5, 251)
    theta_m = 0.25 * np.sin(2 * np.pi * 3.0 * t)
    s = bench.build_series_bench(slip_shaft, 0.005, math.radians(60))
    a, b = s.replay(theta_m, t), s.replay(theta_m, t)
    c = bench.simulate_series_bench(theta_m, t, slip_shaft, 0.005, math.radians(60))
    for k in a:
        assert np.array_equal(a[k], b[k]) and np.array_equal(a[k], c[k]), k
    p = bench.build_parallel_bench(slip_shaft, twist_rad=0.1)
    pa, pb = p.replay(theta_m * 4, t), p.replay(theta_m * 4, t)
    for k in pa:
        assert np.array_equal(pa[k], pb[k]), k


def test_bad_inputs_raise_named_errors(prototype: ShaftParams) -> None:
    t = np.linspace(0.0, 1.0, 11)
    good = np.zeros(11)
    nan = good.copy()
    nan[4] = np.nan
    with pytest.raises(InvalidParameterError, match="NaN"):
        bench.simulate_series_bench(nan, t, prototype)
    with pytest.raises(InvalidParameterError, match="NaN"):
        bench.simulate_parallel_bench(nan, t, prototype)
    back = t.copy()
    back[6] = back[4]
    with pytest.raises(InvalidParameterError, match="strictly increasing"):
        bench.simulate_series_bench(good, back, prototype)
    with pytest.raises(InvalidParameterError, match="samples"):
        bench.simulate_series_bench(good[:5], t, prototype)
    with pytest.raises(InvalidParameterError, match="unknown load type"):
        bench.build_series_bench(prototype, "spring")
    with pytest.raises(InvalidParameterError, match="> 0"):
        bench.build_series_bench(prototype, -0.01)
    with pytest.raises(InvalidParameterError, match="> 0"):
        bench.build_series_bench(prototype, 0.0)
    with pytest.raises(InvalidParameterError, match="need a load inertia"):
        bench.build_series_bench(prototype, "blocked", load_damping_nms=0.1)
    with pytest.raises(ShaftRangeError, match="validity range"):
        bench.build_series_bench(prototype, "blocked", math.radians(150))
    with pytest.raises(ShaftRangeError, match="validity range"):
        bench.simulate_parallel_bench(np.full(11, math.radians(130)), t, prototype)
    with pytest.raises(InvalidParameterError, match="backend"):
        bench.build_parallel_bench(prototype, backend="gpu")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="unknown sidecar load type"):
        bench.load_from_sidecar({"type": "spring"})
    assert bench.load_from_sidecar({"type": "blocked"}) == "blocked"
    assert bench.load_from_sidecar({"type": "inertia", "inertia_kgm2": 0.01}) == 0.01


def test_bench_models_leave_foreign_callbacks_and_the_arm_alone(prototype: ShaftParams) -> None:
    """A bench replay installs fsarm's callbacks only while stepping."""
    before = (mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn(), mujoco.get_mjcb_control())
    t = np.linspace(0.0, 0.1, 11)
    bench.simulate_series_bench(np.zeros(11), t, prototype)
    after = (mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn(), mujoco.get_mjcb_control())
    assert before == after
