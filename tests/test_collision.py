"""Sensorless collision detection and hand guiding at joint 3 (seed 004 Algorithms 1-2).

Physics checks: the momentum observer reproduces the external torque through its first-order
lag; with shaft hysteresis the identified error band is the slip torque the encoders cannot see;
the admittance moves the joint by impulse / D_a. Then the detection figures: delay after a
scripted hit, no false alarm on collision-free runs (the threshold is identified on other runs).
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from fsarm_sim.engine.model import SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import bend_friction
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import RunResult, run_scenario
from fsarm_sim.studies import collision

HIT = scenarios.get("collision-hit")
HAND = scenarios.get("hand-guide")
HYSTERESIS = SimConfig(shaft=load_catalogue().shaft(series_hysteresis=True))
# the shaft's eq. 8 law alone: the observer's own accuracy, without the slip torque it cannot see
ELASTIC = SimConfig(shaft=load_catalogue().shaft(series_hysteresis=False))


@pytest.fixture(scope="module")
def default_runs() -> dict[str, RunResult]:
    return {
        "hit": run_scenario(HIT, ELASTIC),
        "twin": run_scenario(collision.without_disturbance(HIT), ELASTIC),
        "fig14-sine": run_scenario("fig14-sine", ELASTIC),
        "p2p-payload": run_scenario("p2p-payload", ELASTIC),
        "hand": run_scenario(HAND, ELASTIC),
    }


def _lowpass(x: np.ndarray, gain: float, dt: float) -> np.ndarray:
    """The observer's ideal response: dr/dt = K (tau_ext - r), same discretization."""
    out = np.zeros_like(x)
    for k in range(1, len(x)):
        out[k] = out[k - 1] + gain * dt * (x[k - 1] - out[k - 1])
    return out


def test_observer_reproduces_the_external_torque_through_its_lag(
    default_runs: dict[str, RunResult],
) -> None:
    res = default_runs["hit"]
    assert HIT.disturbance is not None
    tau = collision.external_torque(res, HIT.disturbance)
    # the hit is F x lever: 100 N at the flange, perpendicular to link 3
    m = build_model(ELASTIC, np.zeros((1, 9)))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    q3 = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "q3")
    flange = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "flange")
    lever = float(np.linalg.norm(d.site_xpos[flange] - d.xanchor[q3]))
    assert np.max(np.abs(tau)) == pytest.approx(scenarios.HIT_PEAK_N * lever, rel=1e-9)
    r = collision.residual(res)
    ideal = _lowpass(tau, collision.GAIN_RAD_S, res.config.gains.ctrl_dt_s)
    assert np.max(np.abs(r - ideal)) < 0.005 * np.max(np.abs(tau))


def test_hit_is_detected_within_5_ms_and_the_arm_stops(
    default_runs: dict[str, RunResult],
) -> None:
    cal = collision.calibrate(ELASTIC)
    res = default_runs["hit"]
    rep = collision.evaluate_detection("hit", res, cal.threshold_nm, HIT.disturbance)
    assert rep.delay_s is not None and 0.0 < rep.delay_s <= 0.005
    assert rep.false_alarms == 0
    # Algorithm 1 line 8: joint 3 holds the angle it had when the alarm came
    c = res.columns
    k = int(np.searchsorted(c["t"], rep.detected_s))
    np.testing.assert_array_equal(c["q3_ref"][k:], c["q3"][k])
    assert np.all(c["qd3_ref"][k:] == 0.0)
    assert abs(c["q3"][-1] - c["q3"][k]) < 0.01
    assert abs(c["qd3"][-1]) < 0.05
    # limits: the hit saturates the motor at most, and the twist stays in the law's valid range
    assert np.max(np.abs(c["tau_motor"])) <= 1.0
    assert np.max(np.abs(c["twist"])) < res.config.transmission_model().twist_range_rad
    assert np.max(np.abs(c["q3"] - c["q3_ref"])) < math.radians(10.0)


@pytest.mark.parametrize("run", ["twin", "fig14-sine", "p2p-payload"])
def test_no_false_alarm_on_collision_free_runs(
    default_runs: dict[str, RunResult], run: str
) -> None:
    """The threshold comes from the identification runs, not from these."""
    cal = collision.calibrate(ELASTIC)
    rep = collision.evaluate_detection(run, default_runs[run], cal.threshold_nm)
    assert rep.false_alarms == 0 and rep.detected_s is None
    assert rep.peak_estimate_nm < cal.threshold_nm


def test_hook_loop_is_the_plain_loop_when_nothing_happens(
    default_runs: dict[str, RunResult],
) -> None:
    """Tick-by-tick stepping with an (idle) outer loop gives fig14-sine bit for bit."""
    twin = default_runs["twin"].columns
    plain = default_runs["fig14-sine"].columns
    n = len(twin["t"])
    for key in twin:
        np.testing.assert_array_equal(twin[key], plain[key][:n], err_msg=key)


def test_hysteresis_band_is_the_slip_torque_the_encoders_cannot_see() -> None:
    """With Maxwell-slip hysteresis the sensor misses up to the elements' slip torques on the
    shaft - on the winding side, grown by the bend friction at the identification runs' bends
    (joint 2 swings 15-60 deg); on joint 3 that is i_G2 times it, and the identification finds a
    band inside those bounds."""
    cal = collision.calibrate(HYSTERESIS)
    m = build_model(HYSTERESIS, np.zeros((1, 9)))
    straight = read_structure(m).coef_s * sum(HYSTERESIS.shaft.slip_f)
    mu = HYSTERESIS.shaft.bend_friction_per_rad
    lo = straight * bend_friction.factor(math.radians(15.0), mu)
    hi = straight * bend_friction.factor(math.radians(60.0), mu)
    assert 0.98 * lo <= cal.max_abs_residual_nm <= 1.02 * hi
    hit = collision.evaluate_detection(
        "hit", run_scenario(HIT, HYSTERESIS), cal.threshold_nm, HIT.disturbance
    )
    assert hit.delay_s is not None and hit.delay_s <= 0.03
    assert hit.false_alarms == 0
    free = collision.evaluate_detection(
        "p2p", run_scenario("p2p-payload", HYSTERESIS), cal.threshold_nm
    )
    assert free.false_alarms == 0 and free.detected_s is None


def test_hand_guiding_moves_by_impulse_over_damping_then_holds(
    default_runs: dict[str, RunResult],
) -> None:
    res = default_runs["hand"]
    assert HAND.disturbance is not None
    pushes = [(a, b) for a, b, _ in scenarios.HAND_PUSHES]
    rep = collision.evaluate_guiding(res, HAND.disturbance, pushes)
    tau = collision.external_torque(res, HAND.disturbance)
    t, dt = res.columns["t"], res.config.gains.ctrl_dt_s
    for (a, b, force), p in zip(scenarios.HAND_PUSHES, rep.pushes, strict=True):
        inside = (t >= a) & (t <= b + 0.5)
        impulse = float(np.sum(tau[inside]) * dt)
        assert math.copysign(1.0, p["travel_rad"]) == math.copysign(1.0, force)
        # first-order admittance: total displacement = impulse / D_a
        assert p["travel_rad"] == pytest.approx(
            impulse / collision.ADMITTANCE_DAMPING_NMS, rel=0.02
        )
        assert abs(p["drift_after_release_rad"]) < 1e-3
        assert p["speed_after_release_rad_s"] < 0.01
    assert rep.human_work_j > 0.0  # the joint yields: the hand does positive work
    assert rep.final_speed_rad_s < 1e-3
    c = res.columns
    assert np.max(np.abs(c["tau_motor"])) < 1.0  # below the motor's current limit
    lo, hi = rep.q3_range_rad
    assert lo > -2.618 and hi < 2.618


def test_hand_guiding_mode_without_a_hand_holds_still() -> None:
    res = run_scenario(collision.without_disturbance(HAND), duration_s=1.0)
    q3 = res.columns["q3"]
    assert np.max(np.abs(q3 - q3[0])) < 1e-6


def test_on_another_transmission_rtca() -> None:
    cfg = SimConfig(transmission="rtca")
    cal = collision.calibrate(cfg)
    hit = collision.evaluate_detection(
        "hit", run_scenario(HIT, cfg), cal.threshold_nm, HIT.disturbance
    )
    assert hit.delay_s is not None and hit.delay_s <= 0.02
    assert hit.false_alarms == 0
    twin = collision.evaluate_detection(
        "twin", run_scenario(collision.without_disturbance(HIT), cfg), cal.threshold_nm
    )
    assert twin.false_alarms == 0 and twin.detected_s is None
    assert HAND.disturbance is not None
    hand = collision.evaluate_guiding(
        run_scenario(replace(HAND, duration_s=2.5), cfg),
        HAND.disturbance,
        [scenarios.HAND_PUSHES[0][:2]],
    )
    assert hand.pushes[0]["travel_rad"] > 0.1
    assert abs(hand.pushes[0]["drift_after_release_rad"]) < 1e-3


def test_alarm_intervals_and_bad_inputs() -> None:
    t = np.arange(8) * 0.001
    r = np.array([0.0, 2.0, 3.0, 0.5, -4.0, -1.0, 0.0, 2.5])
    found = collision.alarms(t, r, 1.5)
    assert [(a.start_s, a.end_s, a.peak_nm) for a in found] == [
        (0.001, 0.002, 3.0),
        (0.004, 0.004, -4.0),
        (0.007, 0.007, 2.5),
    ]
    with pytest.raises(collision.CollisionError, match="threshold"):
        collision.alarms(t, r, 0.0)
    with pytest.raises(collision.CollisionError, match="length"):
        collision.alarms(t, r[:-1], 1.0)
    m = build_model(ELASTIC, np.zeros((1, 9)))
    with pytest.raises(collision.CollisionError, match="too high"):
        collision.JointThreeObserver(m, ELASTIC, gain_rad_s=2000.0)
    bad = replace(HIT, disturbance=scenarios.Disturbance("elbow", lambda t: (0, 0, 0), (0, 1)))
    with pytest.raises(InvalidParameterError, match="elbow"):
        run_scenario(bad, duration_s=0.01)


def test_cli_table_and_json(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    from fsarm_sim.cli import collision as cli_collision

    cal = collision.Calibration(0.2, 0.1, 2.0, ("id @ 0 kg",))
    det = (
        collision.DetectionReport("collision-hit", 0.2, (1.2, 1.25), 1.202, 0.002, 0, 40.0, 32.0),
        collision.DetectionReport(
            "p2p-payload", 0.2, None, None, None, None, 0.0, 0.0, "cannot hold"
        ),
    )
    guide = collision.GuidingReport(
        ({"start_s": 0.5, "end_s": 1.5, "mean_push_nm": 9.0, "travel_rad": 0.2,
          "drift_after_release_rad": 0.0, "speed_after_release_rad_s": 0.0,
          "motor_share": 0.75},),
        6.0, 0.0, (0.5, 0.8),
    )  # fmt: skip
    monkeypatch.setattr(
        collision,
        "run_battery",
        lambda cfg, backend: collision.Battery("x", cal, 100.0, det, guide),
    )
    app = typer.Typer()
    app.callback()(lambda: None)
    cli_collision.register(app)
    out = tmp_path / "c.json"
    res = CliRunner().invoke(app, ["collision", "--json", str(out)], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "collision-hit" in res.output and "skipped" in res.output
    data = json.loads(out.read_text())
    assert data["detection"][0]["delay_s"] == 0.002
    assert data["detection"][1]["skipped"] == "cannot hold"
    assert data["hand_guiding"]["pushes"][0]["travel_rad"] == 0.2
    assert "motor's share" in res.output and "0.75" in res.output
    bad = CliRunner().invoke(app, ["collision", "--backend", "gpu"])
    assert bad.exit_code != 0


# ------------------------------------------------------------------ seed 004's Algorithms 1-2

# seed 004 Table 2, bend pi/2: (P, Q, M) per direction
RC = (-0.208, 0.916, 0.301)
RA = (-0.030, 0.913, -0.063)


def _columns(th2: np.ndarray, noise: float = 0.0) -> dict[str, np.ndarray]:
    w = np.gradient(th2)
    th1 = np.where(w > 0, np.polyval(RC, th2), np.polyval(RA, th2))
    rng = np.random.default_rng(0)
    th1 = th1 + noise * rng.standard_normal(len(th2))
    return {"t": np.arange(len(th2)) * 1e-3, "theta_m": th1, "q3": th2, "qd3": w / 1e-3}


def test_identification_recovers_the_branches_and_sets_delta_a() -> None:
    th2 = 0.8 * np.sin(np.linspace(0.0, 4.0 * math.pi, 4001))
    model = collision.identify_position_model([_columns(th2, noise=1e-3)], ["synthetic"])
    np.testing.assert_allclose(model.up, RC, atol=5e-3)
    np.testing.assert_allclose(model.down, RA, atol=5e-3)
    assert 0.0 < model.max_error_rad < 0.01
    assert model.threshold_rad == pytest.approx(collision.MARGIN * model.max_error_rad)
    # a joint that never moves one way cannot be identified (eq. 19 needs both fits)
    with pytest.raises(collision.CollisionError, match="both ways"):
        collision.identify_position_model([_columns(np.linspace(0.0, 1.0, 500))], ["one way"])


def test_algorithm1_delta_sees_a_displacement_error() -> None:
    th2 = 0.8 * np.sin(np.linspace(0.0, 4.0 * math.pi, 4001))
    cols = _columns(th2)
    clean = collision.algorithm1_delta(cols, RC, RA)
    assert np.max(np.abs(clean)) < 1e-12
    hit = dict(cols)
    hit["theta_m"] = cols["theta_m"].copy()
    hit["theta_m"][2000:2050] -= 0.1  # the joint pushed back: motor ahead of both branches
    d = collision.algorithm1_delta(hit, RC, RA)
    assert np.max(np.abs(d[2000:2050])) > 0.05
    found = collision.alarms(cols["t"], d, 0.05)
    assert len(found) == 1 and found[0].start_s == pytest.approx(2.0)


def test_algorithm2_hand_guiding_follows_the_push_and_holds() -> None:
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim import scenarios
    from fsarm_sim.sim.simulation import run_scenario

    sc = collision.algorithm2_scenario()
    assert sc.disturbance is not None
    res = run_scenario(sc, SimConfig(transmission="tendon-sheath"))
    g = collision.evaluate_guiding(
        res, sc.disturbance, [(a, b) for a, b, _ in scenarios.HAND_PUSHES]
    )
    assert len(g.pushes) == 6 and g.cycles() == 3  # seed 004: three up-and-down cycles
    for p in g.pushes:
        assert math.copysign(1.0, p["travel_rad"]) == math.copysign(1.0, p["mean_push_nm"])
        assert abs(p["travel_rad"]) > math.radians(1.0)  # the joint yields to a 9 N*m push
        assert abs(p["drift_after_release_rad"]) < math.radians(0.5)  # and stays where left
        assert abs(p["speed_after_release_rad_s"]) < 0.05
        assert p["motor_share"] > 0.9  # the motor carries the joint's move, not the stretch
    assert g.motor_follows()


def test_guiding_report_says_whether_the_joint_followed_and_held() -> None:
    """The hand-guiding claim's criterion (seed 004 Sec. V-B), as GuidingReport reads it."""

    def push(
        travel: float, speed: float, drift: float, sign: float = 1.0, motor: float = 1.0
    ) -> dict[str, float]:
        return {
            "start_s": 0.5,
            "end_s": 1.5,
            "mean_push_nm": 9.0 * sign,
            "travel_rad": travel * sign,
            "speed_after_release_rad_s": speed,
            "drift_after_release_rad": drift,
            "motor_share": motor,
        }

    def report(*pushes: dict[str, float]) -> collision.GuidingReport:
        return collision.GuidingReport(pushes, 1.0, 0.0, (0.0, 1.0))

    good = report(push(0.5, 0.001, 0.001), push(0.5, 0.002, -0.001, -1.0))
    assert good.follows() and good.holds() and good.stays()
    creeping = report(push(0.5, collision.HOLD_SPEED_RAD_S * 1.5, 0.2), push(0.5, 0.0, 0.0, -1.0))
    assert creeping.follows() and not creeping.holds() and not creeping.stays()
    wrong_way = report(push(-0.5, 0.0, 0.0))
    assert not wrong_way.follows()
    # the motor held while the transmission stretched: the joint moved, the motor did not follow
    stretched = report(push(0.5, 0.0, 0.0), push(0.5, 0.0, 0.0, -1.0, motor=0.1))
    assert stretched.follows() and not stretched.motor_follows()
    assert good.motor_follows()
    # cycles: an up push answered by a down push; two ups in a row are no cycle
    assert good.cycles() == 1
    assert report(*(push(0.5, 0.0, 0.0, s) for s in (1.0, -1.0) * 3)).cycles() == 3
    assert report(push(0.5, 0.0, 0.0), push(0.5, 0.0, 0.0)).cycles() == 0
