"""A dm_control environment for joint-3 tracking through the flexible shaft.

Physics / task / runner are kept apart as in ``dm_control.suite``:

* :class:`FsarmPhysics` - a ``dm_control.mujoco.Physics`` of the configured fsarm model
  (``fsarm_sim.engine.model.build_model``: the exact model ``fsarm run`` steps, with payload, shaft
  parameters, gains and reference table), with named read-outs;
* :class:`Joint3Tracking` - the task (``dm_control.suite.base.Task``): actions, observations,
  reward;
* :func:`load` - builds a ``dm_control.rl.control.Environment``; ``dm_control.viewer.launch(
  environment_loader=load)`` opens it in dm_control's viewer where a display exists.

The shaft physics and the low-level controllers run *inside* ``physics.step()`` through fsarm's
MuJoCo callbacks (``mjcb_passive``/``mjcb_act_dyn``/``mjcb_control``): :class:`FsarmPhysics`
activates them around each ``step``/``forward`` (``fsarm_sim.engine.callbacks.active``).

Action choice: a **joint-3 position-reference offset** (rad), added to the scenario's joint-3
reference from the current control tick on. The whole low-level chain stays active and unchanged
(computed-torque position loop -> eq. 8 torque PID -> motor speed loop, seed 000 Fig. 13), so an
agent learns a residual on top of the paper's controller (e.g. to pre-compensate the shaft's lag
and the bending hysteresis) and cannot bypass its torque and speed limits. A desired-torque action
would need a second entry point into the kernel's tick logic and would switch the position loop
off; the offset needs none. The reward compares joint 3 with the *unmodified* reference.
"""

from __future__ import annotations

import collections
import math
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
from dm_control import mujoco as dm_mujoco
from dm_control.mujoco import wrapper
from dm_control.rl import control
from dm_control.suite import base
from dm_control.utils import rewards
from dm_env import specs

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import ArmStructure, SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout
from fsarm_sim.sim import references, scenarios
from fsarm_sim.sim.simulation import DEFAULT_BACKEND, Backend, initial_state

Array = npt.NDArray[np.float64]
DEG = math.pi / 180.0

DEFAULT_SCENARIO = "fig14-sine"
# Agent period: 10 ticks of the 1 kHz low-level loops (estimate: a typical RL control rate that
# leaves the inner loops ~10 ticks to act on each new reference).
DEFAULT_CONTROL_TIMESTEP_S = 0.01
# Largest reference offset an agent may add (estimate: 20x the ~0.2 deg tracking error of
# fig14-sine with the default gains, small enough to stay far from the joint limits).
MAX_OFFSET_RAD = 5.0 * DEG
# Reward: 1 within +-0.05 deg (estimate: about one count of a 13-bit joint encoder, 0.044 deg),
# falling as a Gaussian to 0.1 at a further 0.5 deg (estimate: the scale of fig14-sine's
# ~0.2 deg tracking error with the default gains, so the reward still tells good from better).
REWARD_TOLERANCE_RAD = 0.05 * DEG
REWARD_MARGIN_RAD = 0.5 * DEG
# Randomised references: the Fig. 14 cosine sweep with a random period and upper angle
# (ranges: estimates around Fig. 14's 4 s / 90 deg that keep the motor below its speed limit).
RANDOM_PERIOD_S = (4.0, 8.0)
RANDOM_HIGH_RAD = (45.0 * DEG, 90.0 * DEG)


class InvalidActionError(InvalidParameterError):
    """An action had the wrong shape or was NaN/infinite."""


class InvalidStateError(InvalidParameterError):
    """A state vector given to ``FsarmPhysics.set_state`` does not belong to the model."""


# What ``FsarmPhysics.get_state`` saves: MuJoCo's whole integration state - time, qpos, qvel, act,
# warm start, controls and ``userdata``, where fsarm's controllers keep their integrators,
# filters, hysteresis states and control clock - followed by the agent's joint-3 reference offset.
STATE_SIG = int(mujoco.mjtState.mjSTATE_INTEGRATION)


class FsarmPhysics(dm_mujoco.Physics):
    """dm_control Physics of an fsarm model, with named read-outs in SI units.

    ``get_state()`` / ``set_state()`` round-trip the *whole* simulator: MuJoCo's integration
    state (``mjSTATE_INTEGRATION``: time, qpos, qvel, act, warm start, ctrl, userdata - the
    controllers' integrators, filters, slip states and control clock live in ``userdata``) plus
    the joint-3 reference offset the agent set, so an MPC or tree search that restores a state
    continues bit-identically. The state vector is valid within the episode it was taken in."""

    _structure: ArmStructure | None = None
    backend: Backend = DEFAULT_BACKEND
    _base: Array | None = None  # this episode's unmodified reference table
    _offset: float = 0.0  # the agent's joint-3 reference offset (rad), applied from its tick on

    def step(self, nstep: int = 1) -> None:
        """``nstep`` physics steps with fsarm's callbacks active (shaft forces, internal states,
        low-level controllers). They are installed only around stepping: mujoco 3.17 cannot
        compile models while Python callbacks are installed (see fsarm_sim.engine.callbacks)."""
        with callbacks.active(self.backend):
            super().step(nstep)

    def forward(self) -> None:
        with callbacks.active(self.backend):
            super().forward()

    @classmethod
    def from_config(
        cls, config: SimConfig, ref_table: Array, backend: Backend = DEFAULT_BACKEND
    ) -> FsarmPhysics:
        """The configured model of ``fsarm run`` (``build_model``) wrapped for dm_control.

        ``Physics.from_xml_string(build_spec(...).to_xml())`` also loads, but the parameters that
        ``build_model`` sets after compiling (shaft inertia as tendon armature, timestep,
        integrator, the parameter vector) would have to be re-applied by hand; wrapping the
        compiled model keeps one code path and gives bit-identical trajectories."""
        if backend not in ("python", "native"):
            raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
        physics: FsarmPhysics = cls.from_model(wrapper.MjModel(build_model(config, ref_table)))
        physics.backend = backend
        physics.set_episode_reference(physics.reference_table().copy())
        return physics

    # --- reference and agent offset --------------------------------------------------------
    def set_episode_reference(self, table: Array) -> None:
        """Write a new episode's (unmodified) reference table and clear the offset."""
        ref = self.reference_table()
        ref[:] = table
        self._base = ref.copy()
        self._offset = 0.0

    def base_reference(self) -> Array:
        """This episode's reference table without the agent's offset (read-only copy)."""
        if self._base is None:
            raise InvalidParameterError("the physics has no reference table yet")
        return self._base

    @property
    def q3_offset(self) -> float:
        """The joint-3 reference offset (rad) in force from the current tick on."""
        return self._offset

    def set_q3_offset(self, offset: float) -> None:
        """Apply a joint-3 reference offset (rad) from the current control tick on."""
        base = self.base_reference()
        self._offset = float(offset)
        k = self.tick()
        self.reference_table()[k:, 2] = base[k:, 2] + self._offset

    def copy(self, share_model: bool = False) -> FsarmPhysics:
        """A copy that keeps the backend, the episode reference and the offset."""
        new: FsarmPhysics = super().copy(share_model=share_model)
        new.backend = self.backend
        new._base = None if self._base is None else self._base.copy()
        new._offset = self._offset
        return new

    # --- whole-simulator state -------------------------------------------------------------
    def get_state(self, sig: int | None = None) -> Array:
        """The simulator's state; ``sig=None`` (default) is the whole state described in the
        class docstring, an explicit ``sig`` is MuJoCo's ``mj_getState`` with that signature."""
        if sig is not None:
            return np.asarray(super().get_state(sig), dtype=np.float64)
        state = np.empty(mujoco.mj_stateSize(self.model.ptr, STATE_SIG) + 1, np.float64)
        mujoco.mj_getState(self.model.ptr, self.data.ptr, state[:-1], STATE_SIG)
        state[-1] = self._offset
        return state

    def set_state(self, physics_state: Any, sig: int | None = None) -> None:
        """Restore a state from :meth:`get_state` (same ``sig``); a vector of the wrong size or
        with non-finite values raises :class:`InvalidStateError`."""
        if sig is not None:
            super().set_state(physics_state, sig)
            return
        state = np.asarray(physics_state, dtype=np.float64)
        n = mujoco.mj_stateSize(self.model.ptr, STATE_SIG) + 1
        if state.shape != (n,):
            raise InvalidStateError(
                f"state must be a vector of {n} values from FsarmPhysics.get_state() of this "
                f"model, got shape {state.shape}"
            )
        if not np.all(np.isfinite(state)):
            raise InvalidStateError("state holds NaN or infinite values")
        mujoco.mj_setState(self.model.ptr, self.data.ptr, state[:-1], STATE_SIG)
        self.set_q3_offset(float(state[-1]))

    @property
    def structure(self) -> ArmStructure:
        if self._structure is None:
            self._structure = read_structure(self.model.ptr)
        return self._structure

    def joint_angles(self) -> Array:
        """q1, q2, q3 (rad)."""
        return np.asarray(self.named.data.qpos[["q1", "q2", "q3"]], dtype=np.float64).copy()

    def joint_velocities(self) -> Array:
        """dq1, dq2, dq3 (rad/s)."""
        return np.asarray(self.named.data.qvel[["q1", "q2", "q3"]], dtype=np.float64).copy()

    def twist(self) -> float:
        """Shaft twist Δθ = θ_m - θ_s (rad): the fixed tendon ``shaft_twist``."""
        st = self.structure
        q = self.data.qpos
        return float(st.coef_m * q[st.qadr[3]] - st.coef_s * q[st.qadr[2]])

    def bend(self) -> float:
        """Shaft bend φ_B (rad) = joint 2's angle."""
        return float(self.named.data.qpos["q2"][0])

    def torque_estimate(self) -> float:
        """The controller's modeled shaft torque τ_m (eq. 8) of the last control tick (N·m)."""
        return float(self.data.userdata[layout.U_LOG + layout.L_TAU_MODEL])

    def reference_table(self) -> Array:
        """The reference table the controllers read (a writable view), one row per tick."""
        table: Array = self.model.ptr.numeric(layout.REF_NAME).data.reshape(-1, layout.REF_COLS)
        return table

    def tick(self) -> int:
        """Index of the control tick at the current time, clamped to the table."""
        dt = float(self.model.ptr.numeric(layout.PARAMS_NAME).data[layout.P_CTRL_DT])
        k = round(float(self.data.time) / dt)
        return min(max(k, 0), self.reference_table().shape[0] - 1)


class Joint3Tracking(base.Task):
    """Track the joint-3 reference; act by offsetting it (see the module docstring)."""

    def __init__(
        self,
        reference: Callable[[Array], Array],
        *,
        ctrl_dt_s: float,
        randomize_reference: bool = False,
        max_offset_rad: float = MAX_OFFSET_RAD,
        random: Any = None,
    ) -> None:
        if not math.isfinite(max_offset_rad) or max_offset_rad <= 0.0:
            raise InvalidParameterError(
                f"max_offset_rad must be a finite angle > 0 rad, got {max_offset_rad!r}"
            )
        self._reference = reference
        self._ctrl_dt = ctrl_dt_s
        self._randomize = randomize_reference
        self._max_offset = max_offset_rad
        super().__init__(random=random)

    # --- episode -------------------------------------------------------------------------
    def episode_reference(self, n_ticks: int) -> Array:
        """The reference table of a new episode (random joint-3 sweep if asked)."""
        t = np.arange(n_ticks, dtype=np.float64) * self._ctrl_dt
        table = np.array(self._reference(t), dtype=np.float64)
        if self._randomize:
            period = float(self.random.uniform(*RANDOM_PERIOD_S))
            high = float(self.random.uniform(*RANDOM_HIGH_RAD))
            pos, vel, acc = references.cosine_sweep(t, 0.0, high, period)
            table[:, 2], table[:, 5], table[:, 8] = pos, vel, acc
        return table

    def initialize_episode(self, physics: FsarmPhysics) -> None:
        physics.set_episode_reference(self.episode_reference(physics.reference_table().shape[0]))
        initial_state(physics.model.ptr, physics.data.ptr, physics.structure)
        super().initialize_episode(physics)

    # --- action --------------------------------------------------------------------------
    def action_spec(self, physics: FsarmPhysics) -> specs.BoundedArray:
        return specs.BoundedArray(
            shape=(1,),
            dtype=np.float64,
            minimum=[-self._max_offset],
            maximum=[self._max_offset],
            name="q3_reference_offset_rad",
        )

    def before_step(self, action: Any, physics: FsarmPhysics) -> None:
        """Validate the action; write base + offset into the joint-3 reference from now on.
        Out-of-range offsets are clipped to the spec (agents' exploration noise); NaN or
        infinite values and wrong shapes raise :class:`InvalidActionError`."""
        a = np.asarray(action, dtype=np.float64)
        if a.size != 1:
            raise InvalidActionError(
                f"action must hold exactly 1 value (joint-3 reference offset, rad), "
                f"got shape {a.shape}"
            )
        value = float(a.reshape(()))
        if not math.isfinite(value):
            raise InvalidActionError(
                f"action (joint-3 reference offset) must be a finite number of radians in "
                f"[{-self._max_offset:.4g}, {self._max_offset:.4g}], got {value!r}"
            )
        physics.set_q3_offset(min(max(value, -self._max_offset), self._max_offset))

    # --- observation / reward ------------------------------------------------------------
    def get_observation(self, physics: FsarmPhysics) -> collections.OrderedDict[str, Array]:
        row = physics.base_reference()[physics.tick()]
        q = physics.joint_angles()
        obs: collections.OrderedDict[str, Array] = collections.OrderedDict()
        obs["joint_angles"] = q
        obs["joint_velocities"] = physics.joint_velocities()
        obs["twist"] = np.array([physics.twist()])
        obs["phi_b"] = np.array([physics.bend()])
        obs["reference"] = np.array([row[2], row[5]])  # q3_ref, qd3_ref (unmodified)
        obs["tracking_error"] = np.array([q[2] - row[2]])
        obs["torque_estimate"] = np.array([physics.torque_estimate()])
        obs["offset"] = np.array([physics.q3_offset])
        return obs

    def get_reward(self, physics: FsarmPhysics) -> float:
        err = float(physics.joint_angles()[2] - physics.base_reference()[physics.tick(), 2])
        return float(
            rewards.tolerance(
                err,
                bounds=(-REWARD_TOLERANCE_RAD, REWARD_TOLERANCE_RAD),
                margin=REWARD_MARGIN_RAD,
                sigmoid="gaussian",
                value_at_margin=0.1,
            )
        )


def load(
    scenario: str = DEFAULT_SCENARIO,
    *,
    config: SimConfig | None = None,
    time_limit: float | None = None,
    control_timestep: float = DEFAULT_CONTROL_TIMESTEP_S,
    randomize_reference: bool = False,
    max_offset_rad: float = MAX_OFFSET_RAD,
    backend: Backend = DEFAULT_BACKEND,
    random: Any = None,
) -> control.Environment:
    """The tracking environment of a registered scenario (reference, payload, duration).

    ``random``: seed or ``np.random.RandomState`` (dm_control convention); it only matters with
    ``randomize_reference``. ``time_limit`` defaults to the scenario's duration."""
    sc = scenarios.get(scenario)
    cfg = (config or SimConfig()).with_(payload_kg=sc.payload_kg)
    limit = sc.duration_s if time_limit is None else time_limit
    if not math.isfinite(limit) or limit <= 0.0:
        raise InvalidParameterError(f"time_limit must be a finite time > 0 s, got {time_limit!r}")
    ctrl_dt = cfg.gains.ctrl_dt_s
    ratio = control_timestep / ctrl_dt
    if not math.isfinite(ratio) or ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
        raise InvalidParameterError(
            f"control_timestep must be a whole multiple of the {ctrl_dt:g} s control period, "
            f"got {control_timestep!r}"
        )
    # one spare agent step of ticks: the last step may read past the time limit
    n_ticks = round((limit + control_timestep) / ctrl_dt) + 1
    task = Joint3Tracking(
        sc.reference,
        ctrl_dt_s=ctrl_dt,
        randomize_reference=randomize_reference,
        max_offset_rad=max_offset_rad,
        random=random,
    )
    # the table's size is fixed here; each episode rewrites its values (initialize_episode)
    table = sc.reference(np.arange(n_ticks, dtype=np.float64) * ctrl_dt)
    physics = FsarmPhysics.from_config(cfg, table, backend)
    # legacy_step=False: physics.step() is plain mj_step, as in fsarm's Simulation
    return control.Environment(
        physics,
        task,
        time_limit=limit,
        control_timestep=control_timestep,
        legacy_step=False,
    )
