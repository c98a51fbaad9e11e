"""The native callbacks as a prebuilt library (fsarm_sim.engine.native_lib)."""

from __future__ import annotations

import os
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import native, native_lib
from fsarm_sim.engine.model import SimConfig, build_model, read_structure
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import initial_state


@pytest.fixture(scope="module")
def lib() -> native_lib.Library:
    found = native_lib.load()
    if found is None:  # setup_env.sh builds it; build it here otherwise
        native_lib.build()
        found = native_lib.load()
    assert found is not None, "the library was built but does not load"
    return found


def _step(m: mujoco.MjModel, install: object, n: int) -> list[np.ndarray]:
    d = mujoco.MjData(m)
    initial_state(m, d, read_structure(m))
    install.install()  # type: ignore[attr-defined]
    try:
        mujoco.mj_step(m, d, nstep=n)
    finally:
        install.uninstall()  # type: ignore[attr-defined]
    return [d.qpos.copy(), d.qvel.copy(), d.act.copy(), d.userdata.copy(), d.qfrc_passive.copy()]


@pytest.mark.parametrize("transmission", ["flexible-shaft", "tendon-sheath"])
def test_the_library_steps_bit_for_bit_as_numba(lib: native_lib.Library, transmission: str) -> None:
    ref = scenarios.get("fig14-sine").reference(np.arange(2002) * 1e-3)
    m = build_model(SimConfig(transmission=transmission), ref, lean=True)
    a = _step(m, lib, 2000)
    b = _step(m, native, 2000)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


def test_a_fresh_process_runs_without_importing_numba(lib: native_lib.Library) -> None:
    code = (
        "import sys; from fsarm_sim.sim.simulation import run_scenario; "
        "r = run_scenario('step-q3', duration_s=0.5); "
        "from fsarm_sim.engine import callbacks; "
        "print(callbacks.native_source(), 'numba' in sys.modules, r.metrics['metric_samples'])"
    )
    env = {**os.environ, "MUJOCO_GL": "disable"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["prebuilt", "library", "False", "500.0"]
    env[native_lib.ENV] = "0"  # switched off: the Numba path
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["numba", "True", "500.0"]


def test_the_library_clock_is_the_stopped_c_clock(lib: native_lib.Library) -> None:
    """mjcb_time from the library is the C function of its stubs file, and it returns 0."""
    import json

    symbols = json.loads((lib.path.parent / "symbols.json").read_text())
    assert symbols["time"] == native_lib.STOPPED_CLOCK
    assert lib.TIME() == 0.0
