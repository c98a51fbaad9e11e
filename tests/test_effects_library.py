"""The effect library of the discrepancy workflow: one module per effect, tested as physics
(energy, dissipation, limits) and against the registry that wires them into the setups."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from fsarm_sim.plant.effects import (
    backlash,
    conduit_viscoelastic,
    coulomb_friction,
    delay,
    nonlinear_stiffness,
    payload_error,
    registry,
    sensor_offset,
    viscous_damping,
)

SPEC_NAMES = {
    "coulomb_friction",
    "viscous_damping",
    "backlash",
    "hysteresis",
    "nonlinear_stiffness",
    "delay",
    "sensor_offset",
}


def _work(x: np.ndarray, tau: np.ndarray) -> float:
    """Work done on an element over a path: integral of tau dx (trapezoid)."""
    return float(np.sum(0.5 * (tau[1:] + tau[:-1]) * np.diff(x)))


# ------------------------------------------------------------------ Coulomb friction


def test_coulomb_sliding_torque_opposes_motion_and_dissipates() -> None:
    for v in (-3.0, -1e-6, 1e-6, 2.0):
        tau = coulomb_friction.sliding_torque_nm(v, 0.4)
        assert tau * v < 0.0
        assert abs(tau) == 0.4
        assert coulomb_friction.dissipation_w(v, 0.4) == pytest.approx(-tau * v)
    assert coulomb_friction.sliding_torque_nm(0.0, 0.4) == 0.0


def test_coulomb_stick_slip_stops_a_sliding_body_in_v0_j_over_f() -> None:
    """A body with friction only decelerates at F/J and then stays at rest (exact stick)."""
    j, f, h, v = 0.02, 0.5, 1e-4, 3.0
    t_stop = None
    for k in range(20000):
        v_new = coulomb_friction.stick_slip_velocity(v, h * f / j)
        assert abs(v_new) <= abs(v)  # friction never speeds a body up
        if v_new == 0.0 and t_stop is None:
            t_stop = (k + 1) * h
        v = v_new
    assert v == 0.0
    assert t_stop == pytest.approx(3.0 * j / f, abs=2 * h)
    # a push below the friction limit does not move a body at rest
    assert coulomb_friction.stick_slip_velocity(0.9 * h * f / j, h * f / j) == 0.0


def test_coulomb_presliding_loop_dissipates_4_f_a_per_cycle() -> None:
    """Rectangular friction loop: work per cycle 4 F A (A >> delta), positive, rate-independent."""
    f, delta, amp = 0.3, 1e-4, 0.2
    for periods in (1.0, 7.0):
        t = np.linspace(0.0, periods, 20001)
        x = amp * np.sin(2 * np.pi * t / periods)
        z = 0.0
        tau = np.empty_like(x)
        for i in range(x.size):
            dx = x[i] - x[i - 1] if i else 0.0
            z = coulomb_friction.presliding_state(z, dx, delta)
            tau[i] = coulomb_friction.presliding_torque_nm(z, delta, f)
        assert np.max(np.abs(tau)) == pytest.approx(f)
        assert _work(x, tau) == pytest.approx(4 * f * amp, rel=2e-3)


# ------------------------------------------------------------------ viscous damping


def test_viscous_loop_area_is_pi_b_omega_a2() -> None:
    b, amp, w = 0.05, 0.3, 2 * np.pi * 1.5
    t = np.linspace(0, 2 * np.pi / w, 20001)
    x = amp * np.sin(w * t)
    tau = np.array([viscous_damping.damper_torque_nm(v, b) for v in amp * w * np.cos(w * t)])
    assert _work(x, tau) == pytest.approx(np.pi * b * w * amp**2, rel=1e-4)
    assert all(viscous_damping.dissipation_w(v, b) >= 0 for v in (-2.0, 0.0, 3.0))


# ------------------------------------------------------------------ backlash


@pytest.mark.parametrize("center", [0.0, 0.01, -0.02])
def test_backlash_dead_zone_limits(center: float) -> None:
    w = 0.06
    xs = np.linspace(-0.3, 0.3, 6001)
    y = np.array([backlash.transmitted_deflection_rad(x, w, center) for x in xs])
    inside = np.abs(xs - center) <= w / 2
    assert np.all(y[inside] == 0.0)  # no torque across the gap
    assert np.allclose(np.diff(y[~inside][xs[~inside] > center]), np.diff(xs)[0])  # slope 1
    assert np.all(np.abs(y) <= np.abs(xs - center) + 1e-15)
    assert np.max(np.abs(np.diff(y))) <= np.diff(xs)[0] + 1e-12  # continuous
    assert backlash.transmitted_rate(center, 5.0, w, center) == 0.0
    assert backlash.transmitted_rate(center + w, 5.0, w, center) == 5.0
    assert not backlash.in_contact(center, w, center)
    # zero play: the identity
    assert backlash.transmitted_deflection_rad(0.123, 0.0, 0.0) == pytest.approx(0.123)


# ------------------------------------------------------------------ nonlinear stiffness


@pytest.mark.parametrize("c2,c3", [(0.5, 1.0), (-0.3, 0.2), (0.0, -0.5)])
def test_polynomial_spring_is_an_energy_gradient(c2: float, c3: float) -> None:
    k, xr, h = 14.0, 0.4, 1e-6
    for x in (-0.35, -0.05, 0.02, 0.3):
        dv = (
            nonlinear_stiffness.polynomial_potential_j(x + h, k, c2, c3, xr)
            - nonlinear_stiffness.polynomial_potential_j(x - h, k, c2, c3, xr)
        ) / (2 * h)
        assert nonlinear_stiffness.polynomial_torque_nm(x, k, c2, c3, xr) == pytest.approx(
            dv, rel=1e-6
        )
        ds = (
            nonlinear_stiffness.polynomial_torque_nm(x + h, k, c2, c3, xr)
            - nonlinear_stiffness.polynomial_torque_nm(x - h, k, c2, c3, xr)
        ) / (2 * h)
        assert nonlinear_stiffness.polynomial_stiffness(x, k, c2, c3, xr) == pytest.approx(
            ds, rel=1e-5
        )
    # the linear limit is eq. 8; a closed loop through a conservative spring does no work
    assert nonlinear_stiffness.polynomial_torque_nm(0.2, k, 0.0, 0.0, xr) == pytest.approx(k * 0.2)
    x = 0.3 * np.sin(np.linspace(0, 2 * np.pi, 4001))
    tau = np.array([nonlinear_stiffness.polynomial_torque_nm(v, k, c2, c3, xr) for v in x])
    assert abs(_work(x, tau)) < 1e-6


def test_masterflex08_curve_is_seed001_table1() -> None:
    """Seed 001 Table 1 evaluated directly (degrees) inside the fitted range (|T| <= 5 N*m),
    through the origin, stiffening; beyond it the one continuation the RTCA transmission uses."""
    from fsarm_sim.plant.transmissions import rtca

    d = 30.0
    pos = 4.202 - 4.201 * math.cos(0.03322 * d) + 0.1622 * math.sin(0.03322 * d)
    pos0 = 4.202 - 4.201
    assert nonlinear_stiffness.masterflex08_torque_nm(math.radians(d), 1.0) == pytest.approx(
        pos - pos0
    )
    w = 0.04357
    neg = -3.107 + sum(
        a * math.cos(n * w * -d) + b * math.sin(n * w * -d)
        for n, a, b in ((1, 2.335, -1.487), (2, 0.7484, 0.3618), (3, 0.02559, 0.1976))
    )
    neg0 = -3.107 + 2.335 + 0.7484 + 0.02559
    assert nonlinear_stiffness.masterflex08_torque_nm(math.radians(-d), 1.0) == pytest.approx(
        neg - neg0
    )
    assert nonlinear_stiffness.masterflex08_torque_nm(0.0, 1.0) == 0.0
    sec = [
        nonlinear_stiffness.masterflex08_torque_nm(math.radians(a), 1.0) / math.radians(a)
        for a in (10, 45)
    ]
    assert sec[0] < sec[1]  # soft near zero
    # twist scale: a shaft half as long needs half the twist for the same torque
    assert nonlinear_stiffness.masterflex08_torque_nm(0.3, 2.0) == pytest.approx(
        nonlinear_stiffness.masterflex08_torque_nm(0.6, 1.0)
    )
    # one curve in the project: the RTCA transmission's, continued linearly past the fit's end
    block = nonlinear_stiffness.MF08_BLOCK  # the RTCA block, the printed curve without dead zone
    assert [block[i] for i in range(24) if i != rtca.I_XDEAD_NEG] == [
        rtca.default_block()[i] for i in range(24) if i != rtca.I_XDEAD_NEG
    ]
    for deg in (-90.0, -40.0, 20.0, 70.0, 90.0):
        x = math.radians(deg)
        assert nonlinear_stiffness.masterflex08_torque_nm(x, 1.0) == rtca.straight_elastic_nm(
            block, x
        )
    end = block[rtca.I_XFIT_POS]
    assert rtca.straight_elastic_nm(block, end) == pytest.approx(5.0, rel=1e-6)
    a, b = end - 1e-7, end + 1e-7  # continuous there (the slope is ~8 N*m/rad)
    assert nonlinear_stiffness.masterflex08_torque_nm(a, 1.0) == pytest.approx(
        nonlinear_stiffness.masterflex08_torque_nm(b, 1.0), abs=5e-6
    )
    # switchable: extend_linear = 0 keeps the printed series (8.38 N*m at +90 deg)
    series = rtca.default_block({"extend_linear": 0.0})
    assert rtca.straight_elastic_nm(series, math.radians(90.0)) == pytest.approx(8.38, abs=0.02)


def test_delay_shifts_a_signal_by_fractional_samples() -> None:
    h = 1e-3
    t = np.arange(4000) * h
    y = np.sin(2 * np.pi * 2.0 * t)
    for d_samples in (0.0, 3.0, 7.4, -5.6):
        out = delay.delayed_signal(y, d_samples)
        ref = np.sin(2 * np.pi * 2.0 * (t - d_samples * h))
        core = slice(20, -20)
        assert np.max(np.abs(out[core] - ref[core])) < 1e-4
    assert np.array_equal(delay.delayed_signal(y, 0.0), y)
    assert delay.delayed_sample(y, 0, 5.0) == y[0]  # before the record: first value held


def test_sensor_offset_roundtrip() -> None:
    for v, b in ((1.5, 0.2), (-3.0, -0.7)):
        r = sensor_offset.reading(v, b)
        assert r - v == pytest.approx(b)
        assert sensor_offset.true_value(r, b) == pytest.approx(v)


# ------------------------------------------------------------------ visco-elastic (existing kernel)


def test_viscoelastic_exact_update_matches_fine_euler_of_branch_rate() -> None:
    """The replay's exact branch update integrates conduit_viscoelastic.branch_rate."""
    from fsarm_sim.discrepancy.replay import branch_columns

    tau_b, h = 0.15, 1e-3
    t = np.arange(3000) * h
    x = 0.5 * np.sin(2 * np.pi * 0.8 * t) + 0.2 * np.sin(2 * np.pi * 3.1 * t)
    w_exact = branch_columns(x, np.array([tau_b]), h)[:, 0]
    sub = 200
    z = x[0]
    w_euler = np.zeros_like(x)
    for i in range(1, x.size):
        for k in range(1, sub + 1):
            xk = x[i - 1] + (x[i] - x[i - 1]) * k / sub
            z += h / sub * conduit_viscoelastic.branch_rate(xk, z, tau_b)
        w_euler[i] = x[i] - z
    assert np.max(np.abs(w_exact - w_euler)) < 2e-4 * np.max(np.abs(x))


# ------------------------------------------------------------------ payload error (arm)


def test_payload_error_matches_mujoco_gravity() -> None:
    """Extra payload mass: the module's gravity torques equal MuJoCo's bias-force change."""
    import mujoco

    from fsarm_sim.engine import callbacks
    from fsarm_sim.engine.model import SimConfig, build_spec

    def model_with(mass: float) -> mujoco.MjModel:
        with callbacks.suspended():
            return build_spec(SimConfig(payload_kg=mass), np.zeros((1, 9))).compile()

    m0, m1 = model_with(2.0), model_with(5.0)
    d0, d1 = mujoco.MjData(m0), mujoco.MjData(m1)
    q2a, q3a = m0.joint("q2").qposadr[0], m0.joint("q3").qposadr[0]
    dof2, dof3 = m0.joint("q2").dofadr[0], m0.joint("q3").dofadr[0]
    mujoco.mj_forward(m1, d1)
    l2 = float(np.linalg.norm(d1.xanchor[m1.joint("q3").id] - d1.xanchor[m1.joint("q2").id]))
    l3 = float(np.linalg.norm(d1.xipos[m1.body("payload").id] - d1.xanchor[m1.joint("q3").id]))
    g = float(-m0.opt.gravity[2])
    for q2, q3 in ((0.0, 0.0), (0.7, -0.3), (-1.1, 1.6), (1.5, 0.9)):
        for m, d in ((m0, d0), (m1, d1)):
            d.qpos[:] = 0.0
            d.qvel[:] = 0.0
            d.qpos[q2a], d.qpos[q3a] = q2, q3
            mujoco.mj_forward(m, d)
        tau2, tau3 = payload_error.gravity_torques_nm(3.0, q2, q3, l2, l3, g)
        # qfrc_bias holds minus the generalized gravity force
        assert -(d1.qfrc_bias[dof2] - d0.qfrc_bias[dof2]) == pytest.approx(tau2, abs=1e-9)
        assert -(d1.qfrc_bias[dof3] - d0.qfrc_bias[dof3]) == pytest.approx(tau3, abs=1e-9)
    assert payload_error.shaft_twist_error_rad(10.0, 10.0, 15.0) == pytest.approx(10.0 / 150.0)


# ------------------------------------------------------------------ registry


def test_registry_covers_the_spec_vocabulary_and_is_consistent() -> None:
    names = set(registry.names())
    assert names >= SPEC_NAMES
    assert "payload_error" in names
    for eff in registry.EFFECTS:
        for mod in eff.module.split(" / "):
            importlib.import_module(f"fsarm_sim.plant.effects.{mod.strip()}")
        assert eff.variants
        for v in eff.variants:
            assert v.setups and v.enters
            for p in v.params:
                assert p.lower < p.upper and p.unit and p.meaning
    with pytest.raises(KeyError, match="known effects"):
        registry.get("gremlins")
    # hysteresis has both kinds; every bench has every spec effect available
    assert set(registry.get("hysteresis").variant_keys()) >= {"maxwell_slip", "viscoelastic"}
    for setup, inertia in (
        ("series_bench", False),
        ("series_bench", True),
        ("parallel_bench", False),
    ):
        avail = {e for e, _ in registry.applicable(setup, inertia)}
        assert avail == SPEC_NAMES
    assert ("coulomb_friction", "load") in registry.applicable("series_bench", True)
    assert ("coulomb_friction", "load") not in registry.applicable("series_bench", False)


@pytest.mark.parametrize(
    "setup,inertia", [("series_bench", False), ("series_bench", True), ("parallel_bench", False)]
)
def test_every_applicable_effect_changes_the_replay(setup: str, inertia: bool) -> None:
    """Generic over the registry: each (effect, variant) at mid-size parameters enters the replay."""
    from fsarm_sim.discrepancy import replay, replay_inputs
    from fsarm_sim.discrepancy.benchmodel import EffectInstance, nominal_from_shaft
    from fsarm_sim.plant.shaft import load_catalogue

    sh = load_catalogue().shaft()
    base = nominal_from_shaft(setup, sh, 0.01 if inertia else None, j_link=0.01)
    h = 1e-3
    t = np.arange(3000) * h
    u = 0.3 * np.sin(2 * np.pi * 1.3 * t) * np.minimum(t / 0.3, 1.0)
    z = np.zeros_like(u)
    inp = replay_inputs.ReplayInputs(
        setup,
        t,
        h,
        u,
        replay_inputs.derivative(u, h),
        replay_inputs.derivative(u, h, 2),
        z,
        z,
        u if setup == "parallel_bench" else z,
        z,
        np.zeros_like(u) if inertia else None,
        inertia,
        np.zeros_like(u) if inertia else None,
    )
    y0 = replay.replay(base, inp)["y"]
    for name, variant in registry.applicable(setup, inertia):
        var = registry.get(name).variant(variant)
        params = {}
        for p in var.params:
            mid = p.lower + 0.05 * (p.upper - p.lower) if p.lower >= 0 else 0.05 * p.upper
            params[p.name] = [mid] if name == "hysteresis" else mid
        if name == "nonlinear_stiffness":
            params["x_ref_rad"] = 0.3
        if name == "hysteresis" and variant == "maxwell_slip":
            params["delta_rad"] = [0.02]
        if name == "hysteresis" and variant == "viscoelastic":
            params["tau_s"] = [0.2]
        y = replay.replay(base.with_effect(EffectInstance(name, variant, params)), inp)["y"]
        assert np.all(np.isfinite(y))
        assert np.max(np.abs(y - y0)) > 1e-4, f"{name}[{variant}] did not change the replay"
