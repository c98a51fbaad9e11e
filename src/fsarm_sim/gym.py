"""The joint-3 tracking task as a Gymnasium environment, registered as ``fsarm_sim/Joint3Tracking-v0``.

::

    import gymnasium as gym
    import fsarm_sim.gym  # registers the id

    env = gym.make("fsarm_sim/Joint3Tracking-v0", scenario="p2p-payload")

(or in one line ``gym.make("fsarm_sim.gym:fsarm_sim/Joint3Tracking-v0")``, Gymnasium's
``module:id`` form). It wraps :func:`fsarm_sim.studies.dmc_env.load` - the same physics, task and
reward as the dm_control environment - with what RL libraries such as stable-baselines3 expect:

* the action is the joint-3 reference offset **normalised** to ``[-1, 1]`` (float32), scaled to
  ``±max_offset_rad`` (default 5°) before it reaches the simulator;
* the observation is the dm_control observation dict flattened in its key order
  (:data:`OBSERVATION_KEYS` says which slice is which) as float32;
* an episode ends by *truncation* at the scenario's duration (``time_limit``); tracking has no
  terminal state;
* ``reset(seed=...)`` seeds the randomised reference (``randomize_reference=True``).
"""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium
import numpy as np
import numpy.typing as npt
from gymnasium import spaces

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.studies import dmc_env

ENV_ID = "fsarm_sim/Joint3Tracking-v0"
RENDER_MODES = ("rgb_array",)


class Joint3TrackingEnv(gymnasium.Env[npt.NDArray[np.float32], npt.NDArray[np.float32]]):
    """Gymnasium view of :func:`fsarm_sim.studies.dmc_env.load` (see the module docstring)."""

    metadata = {"render_modes": list(RENDER_MODES), "render_fps": 100}  # noqa: RUF012 (Gymnasium's own attribute)

    def __init__(
        self,
        scenario: str = dmc_env.DEFAULT_SCENARIO,
        *,
        config: SimConfig | None = None,
        time_limit: float | None = None,
        control_timestep: float = dmc_env.DEFAULT_CONTROL_TIMESTEP_S,
        randomize_reference: bool = False,
        max_offset_rad: float = dmc_env.MAX_OFFSET_RAD,
        render_mode: str | None = None,
    ) -> None:
        if render_mode is not None and render_mode not in RENDER_MODES:
            raise InvalidParameterError(
                f"render_mode must be None or one of {', '.join(RENDER_MODES)}, got {render_mode!r}"
            )
        self._env = dmc_env.load(
            scenario,
            config=config,
            time_limit=time_limit,
            control_timestep=control_timestep,
            randomize_reference=randomize_reference,
            max_offset_rad=max_offset_rad,
        )
        self.render_mode = render_mode
        self._scale = float(max_offset_rad)
        ospec = self._env.observation_spec()
        self.observation_keys: tuple[str, ...] = tuple(ospec)
        size = sum(int(np.prod(s.shape)) for s in ospec.values())
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)

    @property
    def dm_env(self) -> Any:
        """The wrapped dm_control environment (its ``physics`` has ``get_state``/``set_state``)."""
        return self._env

    def _flat(self, observation: Any) -> npt.NDArray[np.float32]:
        return np.concatenate([np.ravel(observation[k]) for k in self.observation_keys]).astype(
            np.float32
        )

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            self._env.task._random = np.random.RandomState(seed)  # dm_control's task RNG
        ts = self._env.reset()
        return self._flat(ts.observation), {}

    def step(
        self, action: Any
    ) -> tuple[npt.NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        ts = self._env.step(np.clip(a, -1.0, 1.0) * self._scale)
        truncated = bool(ts.last())
        return self._flat(ts.observation), float(ts.reward), False, truncated, {}

    def render(self) -> npt.NDArray[np.uint8] | None:
        if self.render_mode is None:
            return None
        image: npt.NDArray[np.uint8] = self._env.physics.render(height=240, width=320)
        return image


def register() -> None:
    """Register :data:`ENV_ID` with Gymnasium (done on import; repeated calls are no-ops)."""
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(
            id=ENV_ID, entry_point="fsarm_sim.gym:Joint3TrackingEnv", disable_env_checker=False
        )


register()
