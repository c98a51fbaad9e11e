"""The Gymnasium environment: registered id, Gymnasium's own checker, float32 normalised action
space, truncation at the time limit, and the same physics as the dm_control environment."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import fsarm_sim.gym as fgym
from fsarm_sim.errors import FsarmError
from fsarm_sim.studies import dmc_env


def test_registered_id_makes_the_environment() -> None:
    env = gymnasium.make(fgym.ENV_ID, time_limit=0.05)
    assert isinstance(env.unwrapped, fgym.Joint3TrackingEnv)
    assert env.action_space.dtype == np.float32
    np.testing.assert_array_equal(env.action_space.low, [-1.0])
    np.testing.assert_array_equal(env.action_space.high, [1.0])
    env.close()


@pytest.mark.filterwarnings("ignore:.*Box observation space (minimum|maximum) value is")
def test_gymnasium_check_env_passes() -> None:
    """Gymnasium's checker; its only remarks are the unbounded observation ranges (angles,
    rates and torques have no declared bound)."""
    check_env(fgym.Joint3TrackingEnv(time_limit=0.1), skip_render_check=True)


def test_episode_is_truncated_at_the_time_limit() -> None:
    env = fgym.Joint3TrackingEnv(time_limit=0.05)
    obs, _ = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape and obs.dtype == np.float32
    steps, truncated, terminated = 0, False, False
    while not (truncated or terminated):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert 0.0 <= float(reward) <= 1.0
        steps += 1
    assert truncated and not terminated and steps == 5


def test_normalised_action_is_the_dm_env_offset() -> None:
    """Action a in [-1, 1] is the dm_control action a * max_offset: same observations."""
    gym_env = fgym.Joint3TrackingEnv(time_limit=0.1)
    dm = dmc_env.load(time_limit=0.1)
    gym_env.reset()
    dm.reset()
    for a in (0.5, -0.25, 1.0):
        obs, *_ = gym_env.step(np.array([a], dtype=np.float32))
        ts = dm.step(np.array([float(np.float32(a)) * dmc_env.MAX_OFFSET_RAD]))
        flat = np.concatenate([np.ravel(v) for v in ts.observation.values()]).astype(np.float32)
        np.testing.assert_array_equal(obs, flat)


def test_same_seed_same_random_reference() -> None:
    def first_obs(seed: int) -> np.ndarray:
        env = fgym.Joint3TrackingEnv(time_limit=0.05, randomize_reference=True)
        env.reset(seed=seed)
        obs, *_ = env.step(np.zeros(1, dtype=np.float32))
        for _ in range(3):
            obs, *_ = env.step(np.zeros(1, dtype=np.float32))
        return obs

    np.testing.assert_array_equal(first_obs(4), first_obs(4))
    assert not np.array_equal(first_obs(4), first_obs(5))


@pytest.mark.parametrize("bad", [{"render_mode": "human"}, {"time_limit": -1.0}])
def test_bad_arguments_are_named_errors(bad: dict[str, object]) -> None:
    with pytest.raises(FsarmError):
        fgym.Joint3TrackingEnv(**bad)  # type: ignore[arg-type]
