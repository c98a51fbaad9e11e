"""dm_control environment: specs, finite values, determinism, a full episode, named errors, and
agreement with fsarm's own runner (the same physics inside physics.step())."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from dm_env import StepType

from fsarm_sim.engine.model import SimConfig, build_model
from fsarm_sim.errors import FsarmError
from fsarm_sim.sim.simulation import run_scenario
from fsarm_sim.studies import dmc_env

from conftest import hold_table


def _rollout(env: object, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ts = env.reset()  # type: ignore[attr-defined]
    obs, rew = [], []
    for a in actions:
        ts = env.step(a)  # type: ignore[attr-defined]
        obs.append(np.concatenate([np.ravel(v) for v in ts.observation.values()]))
        rew.append(ts.reward)
    return np.array(obs), np.array(rew)


def test_specs_match_observations() -> None:
    env = dmc_env.load(time_limit=0.05)
    spec = env.action_spec()
    assert spec.shape == (1,)
    np.testing.assert_allclose(spec.minimum, [-dmc_env.MAX_OFFSET_RAD])
    np.testing.assert_allclose(spec.maximum, [dmc_env.MAX_OFFSET_RAD])
    ts = env.reset()
    assert ts.step_type == StepType.FIRST
    ospec = env.observation_spec()
    assert list(ospec) == list(ts.observation)
    assert set(ospec) >= {"joint_angles", "joint_velocities", "twist", "phi_b", "reference"}
    for k, s in ospec.items():
        assert ts.observation[k].shape == s.shape, k


def test_values_are_finite_and_reward_bounded() -> None:
    env = dmc_env.load("p2p-payload", time_limit=0.3)
    rng = np.random.default_rng(0)
    spec = env.action_spec()
    obs, rew = _rollout(env, rng.uniform(spec.minimum, spec.maximum, size=(30, 1)))
    assert np.all(np.isfinite(obs)) and np.all(np.isfinite(rew))
    assert np.all((rew >= 0.0) & (rew <= 1.0))


def test_same_seed_same_trajectory() -> None:
    actions = np.random.default_rng(1).uniform(-0.02, 0.02, size=(25, 1))

    def run(seed: int) -> tuple[np.ndarray, np.ndarray]:
        env = dmc_env.load(time_limit=0.25, randomize_reference=True, random=seed)
        return _rollout(env, actions)

    a, b, c = run(7), run(7), run(8)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert not np.array_equal(a[0], c[0])  # the seed draws the reference


def test_full_episode_ends_at_the_time_limit() -> None:
    env = dmc_env.load(time_limit=0.2, control_timestep=0.01)
    ts = env.reset()
    steps = 0
    while not ts.last():
        ts = env.step(np.zeros(1))
        steps += 1
    assert steps == 20
    assert ts.step_type == StepType.LAST and ts.discount == 1.0
    assert env.physics.data.time == pytest.approx(0.2)
    assert env.step(np.zeros(1)).first()  # the next step starts a new episode


@pytest.mark.parametrize("bad", [[np.nan], [np.inf], [0.0, 0.0]])
def test_bad_action_raises_named_error(bad: list[float]) -> None:
    env = dmc_env.load(time_limit=0.05)
    env.reset()
    with pytest.raises(dmc_env.InvalidActionError, match="action"):
        env.step(np.array(bad))
    assert issubclass(dmc_env.InvalidActionError, FsarmError)


def test_zero_action_reproduces_fsarm_run_exactly() -> None:
    """The environment steps the very model ``fsarm run`` steps: with a zero offset its joint-3
    trajectory equals run_scenario's bit for bit (callbacks run inside physics.step())."""
    env = dmc_env.load("fig14-sine", time_limit=0.5)
    env.reset()
    q3, t = [], []
    for _ in range(50):
        ts = env.step(np.zeros(1))
        q3.append(ts.observation["joint_angles"][2])
        t.append(env.physics.data.time)
    cols = run_scenario("fig14-sine", duration_s=0.5).columns
    k = np.rint(np.array(t[:-1]) / 0.001).astype(int)  # the run logs up to (not past) 0.5 s
    np.testing.assert_array_equal(np.array(q3[:-1]), cols["q3"][k])
    # and the shaft really acts: a twist carries joint 3's gravity load
    assert abs(ts.observation["twist"][0]) > 1e-3


def test_offset_action_moves_joint3_through_the_shaft() -> None:
    """A constant +2 deg reference offset on a held pose: joint 3 settles ~2 deg above the
    (unmodified) reference, i.e. the action reaches the plant through the torque/speed loops."""
    env = dmc_env.load("step-q3", time_limit=0.45)  # step-q3 holds 30 deg until 0.5 s
    offset = np.radians(2.0)
    obs, _ = _rollout(env, np.full((45, 1), offset))
    err = env.task.get_observation(env.physics)["tracking_error"][0]
    assert err == pytest.approx(offset, abs=0.2 * offset)
    assert obs.shape[0] == 45


def test_callbacks_are_not_left_installed() -> None:
    """Stepping the environment must not leave Python callbacks behind (mujoco 3.17 cannot
    compile a model while they are installed)."""
    env = dmc_env.load(time_limit=0.02)
    env.reset()
    env.step(np.zeros(1))
    assert mujoco.get_mjcb_passive() is None and mujoco.get_mjcb_control() is None
    build_model(SimConfig(), hold_table(0.0, 0.5, 0.5))  # compiles fine afterwards


def test_specs_before_reset() -> None:
    """RL wrappers (shimmy, Acme) read the specs before the first reset."""
    env = dmc_env.load(time_limit=0.05)
    ospec = env.observation_spec()
    ts = env.reset()
    assert list(ospec) == list(ts.observation)
    for k, s in ospec.items():
        assert ts.observation[k].shape == s.shape, k


def _step_obs(env: object, actions: np.ndarray) -> np.ndarray:
    out = []
    for a in actions:
        ts = env.step(a)  # type: ignore[attr-defined]
        out.append(np.concatenate([np.ravel(v) for v in ts.observation.values()]))
    return np.array(out)


@pytest.mark.parametrize("backend", ["native", "python"])
def test_state_round_trip_restores_controllers_exactly(backend: str) -> None:
    """get_state/set_state carries the controllers' states (userdata), the time and the agent's
    offset: a restored physics continues bit-identically (MPC / tree search)."""
    env = dmc_env.load(time_limit=0.4, backend=backend)  # type: ignore[arg-type]
    env.reset()
    rng = np.random.default_rng(3)
    _step_obs(env, rng.uniform(-0.05, 0.05, size=(10, 1)))
    saved = env.physics.get_state()
    future = rng.uniform(-0.05, 0.05, size=(15, 1))
    first = _step_obs(env, future)
    env.physics.set_state(saved)
    again = _step_obs(env, future)
    np.testing.assert_array_equal(first, again)
    # a different continuation really differs (the check above can fail)
    env.physics.set_state(saved)
    other = _step_obs(env, -future)
    assert np.max(np.abs(other - first)) > 1e-6


def test_bad_state_is_a_named_error() -> None:
    env = dmc_env.load(time_limit=0.05)
    env.reset()
    state = env.physics.get_state()
    with pytest.raises(dmc_env.InvalidStateError, match="vector of"):
        env.physics.set_state(state[:-2])
    state[0] = np.nan
    with pytest.raises(dmc_env.InvalidStateError, match="NaN"):
        env.physics.set_state(state)


def test_dm_env_conformance() -> None:
    """dm_env's own conformance mixin, run through unittest."""
    import unittest

    from dm_env import test_utils

    class Conformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
        def make_object_under_test(self) -> object:
            return dmc_env.load(time_limit=0.1)

    result = unittest.TextTestRunner(verbosity=0).run(
        unittest.defaultTestLoader.loadTestsFromTestCase(Conformance)
    )
    assert result.testsRun > 0
    assert result.wasSuccessful(), result.failures + result.errors
