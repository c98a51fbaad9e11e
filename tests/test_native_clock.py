"""The native path stops MuJoCo's stage timers (mjcb_time -> 0) while it steps: the same
physics, zero timer durations, the previous clock back afterwards, a user's own clock kept."""

from __future__ import annotations

import ctypes

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import Simulation

INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
STEP = int(mujoco.mjtTimer.mjTIMER_STEP)


@pytest.fixture(autouse=True)
def _restore_clock():
    saved = mujoco.get_mjcb_time()
    yield
    mujoco.set_mjcb_time(saved)


def _native():
    native = callbacks.load_native()
    if native is None:
        pytest.skip("the native callbacks cannot be compiled here")
    return native


def test_the_clock_is_stopped_while_native_steps_and_restored_after() -> None:
    native = _native()
    mujoco.set_mjcb_time(None)
    with callbacks.active("native"):
        assert mujoco.get_mjcb_time() is native.TIME
    assert mujoco.get_mjcb_time() is None
    with callbacks.active("python"):  # the reference path leaves MuJoCo's timers alone
        assert mujoco.get_mjcb_time() is None


def test_a_clock_of_your_own_stays() -> None:
    _native()
    mine = ctypes.CFUNCTYPE(ctypes.c_double)(lambda: 1.0)
    mujoco.set_mjcb_time(mine)
    with callbacks.active("native"):
        assert mujoco.get_mjcb_time() is mine
    assert mujoco.get_mjcb_time() is mine


def test_timers_never_enter_the_dynamics() -> None:
    native = _native()
    table = scenarios.get("fig14-sine").reference(np.arange(601) * 0.001)
    sim = Simulation(SimConfig(), table, "native")
    m, d = sim.model, sim.data
    s0 = np.empty(mujoco.mj_stateSize(m, INTEGRATION))
    mujoco.mj_getState(m, d, s0, INTEGRATION)
    out = []
    with callbacks.active("native"):
        for clock in (native.TIME, None):  # stopped, then MuJoCo's own timers
            mujoco.set_mjcb_time(clock)
            mujoco.mj_setState(m, d, s0, INTEGRATION)
            d.timer[STEP].duration = 0.0
            mujoco.mj_step(m, d, nstep=500)
            s = np.empty_like(s0)
            mujoco.mj_getState(m, d, s, INTEGRATION)
            out.append((s, d.timer[STEP].duration))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    assert out[0][1] == 0.0 < out[1][1]
