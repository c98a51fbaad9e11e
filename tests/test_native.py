"""Native (Numba C) callbacks: same trajectories as the Python reference, foreign models left
alone, per-model parameters in rollout threads, verified struct offsets, cached compilation.

No timing asserts here: speed is measured by ``scripts/bench_step.py`` / ``fsarm bench-speed``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine import callbacks, native, native_abi
from fsarm_sim.engine.model import Effects, Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError, SimulationWarningError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.sim import batch, scenarios
from fsarm_sim.sim.simulation import Simulation
from fsarm_sim.studies import bench

FULLPHYSICS = mujoco.mjtState.mjSTATE_FULLPHYSICS
INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION


def _table(name: str, duration_s: float) -> np.ndarray:
    n = round(duration_s / 0.001) + 1
    return scenarios.get(name).reference(np.arange(n) * 0.001)


def _full(shaft_d: float = 9.0, shaft_l: float = 450.0, **changes: object) -> SimConfig:
    """Every effect on, series (Maxwell-slip) hysteresis included."""
    shaft = load_catalogue().shaft(shaft_d, shaft_l, series_hysteresis=True)
    return SimConfig(shaft=shaft).with_(**changes)


@pytest.fixture(autouse=True)
def _restore_callbacks():
    saved = (mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn(), mujoco.get_mjcb_control())
    yield
    mujoco.set_mjcb_passive(saved[0])
    mujoco.set_mjcb_act_dyn(saved[1])
    mujoco.set_mjcb_control(saved[2])


def _run_both(cfg: SimConfig, scenario: str, duration_s: float) -> dict[str, dict]:
    table = _table(scenario, duration_s)
    out = {}
    for backend in ("python", "native"):
        sim = Simulation(cfg, table, backend)
        cols, _ = sim.run(duration_s)
        state = np.empty(mujoco.mj_stateSize(sim.model, INTEGRATION))
        mujoco.mj_getState(sim.model, sim.data, state, INTEGRATION)
        a = sim.structure.act_slip
        out[backend] = {"cols": cols, "state": state, "slip": sim.data.act[a : a + 3].copy()}
    return out


def _max_diff(a: dict, b: dict) -> tuple[float, str]:
    worst, where = 0.0, ""
    for k in a["cols"]:
        d = float(np.max(np.abs(a["cols"][k] - b["cols"][k])))
        if d > worst:
            worst, where = d, k
    d = float(np.max(np.abs(a["state"] - b["state"])))
    if d > worst:
        worst, where = d, "final mjSTATE_INTEGRATION"
    return worst, where


def test_fig14_full_model_native_matches_python_bit_for_bit() -> None:
    """1.5 s of fig14-sine with every effect (series + slip + bending + conduit + loops)."""
    out = _run_both(_full(), "fig14-sine", 1.5)
    py, nat = out["python"], out["native"]
    assert set(py["cols"]) == set(nat["cols"])
    assert len(py["cols"]["t"]) >= 1500  # one row per control tick
    # the run exercises what it claims to: the shaft carries torque, the slip states move
    assert np.max(np.abs(py["cols"]["tau_shaft"])) > 0.1
    assert np.max(np.abs(py["cols"]["tau_conduit"])) > 0.0
    assert np.all(np.abs(py["slip"]) > 1e-6)
    worst, where = _max_diff(py, nat)
    assert worst <= 1e-12, f"native and python paths differ by {worst:.3g} in {where}"
    # Bitwise: both paths run the same source and Numba calls the same pow() (see
    # effects/bending.py); a difference of a few ulp here means a kernel now computes something
    # differently when compiled (e.g. x**3 with an int exponent, which Numba expands to x*x*x).
    assert worst == 0.0, f"not bit-identical: {worst:.3g} in {where}"


@pytest.mark.parametrize("scenario", sorted(scenarios.REGISTRY))
def test_every_scenario_agrees_briefly(scenario: str) -> None:
    cfg = _full(payload_kg=scenarios.get(scenario).payload_kg)
    worst, where = _max_diff(*_run_both(cfg, scenario, 0.3).values())
    assert worst <= 1e-12, f"{scenario}: paths differ by {worst:.3g} in {where}"


@pytest.mark.parametrize("controller", ["hysteresis-comp", "dob", "paper-pid"])
def test_joint3_controllers_agree_bit_for_bit(controller: str) -> None:
    """Each joint-3 controller option: the native kernels step exactly as the Python ones."""
    cfg = _full(gains=Gains(controller=controller), payload_kg=5.0)
    out = _run_both(cfg, "fig14-sine", 0.5)
    worst, where = _max_diff(out["python"], out["native"])
    assert worst == 0.0, f"{controller}: paths differ by {worst:.3g} in {where}"


@pytest.mark.parametrize("integrator", ["RK4", "implicitfast"])
def test_paths_agree_under_other_integrators(integrator: str) -> None:
    """RK4 calls the callbacks 4 times per step; the tick logic must behave identically."""
    worst, where = _max_diff(*_run_both(_full(integrator=integrator), "step-q3", 0.6).values())
    assert worst <= 1e-12, f"{integrator}: paths differ by {worst:.3g} in {where}"


def test_effects_switched_off_agree() -> None:
    cfg = _full(effects=Effects(slip=False, conduit=False, coupling=False))
    worst, where = _max_diff(*_run_both(cfg, "step-q2", 0.4).values())
    assert worst <= 1e-12, f"paths differ by {worst:.3g} in {where}"


def test_bench_models_with_absent_joints_agree() -> None:
    """Series and parallel benches have absent joints (index -1) and no controller."""
    sh = load_catalogue().shaft(series_hysteresis=True)
    t = np.linspace(0.0, 1.0, 101)
    series = {
        b: bench.simulate_series_bench(
            0.3 * np.sin(2 * np.pi * t), t, sh, load=0.01, bend_rad=0.5, backend=b
        )
        for b in ("python", "native")
    }
    assert np.max(np.abs(series["python"]["tau_s"])) > 0.1
    for k in series["python"]:
        np.testing.assert_array_equal(series["python"][k], series["native"][k], err_msg=k)
    par = {
        b: bench.simulate_parallel_bench(0.8 * np.sin(np.pi * t), t, sh, twist_rad=0.2, backend=b)
        for b in ("python", "native")
    }
    assert np.max(np.abs(par["python"]["m_b"])) > 0.1
    for k in par["python"]:
        np.testing.assert_array_equal(par["python"][k], par["native"][k], err_msg=k)


FOREIGN_XML = """
<mujoco>
  <worldbody><body><joint name="a" axis="0 1 0" damping="0.1"/>
    <geom type="capsule" size=".05" fromto="0 0 0 0 0 .4" mass="1"/></body></worldbody>
  <actuator><motor joint="a"/><general joint="a" dyntype="user" gainprm="1"/></actuator>
  <custom>{numeric}</custom>
  <size nuserdata="40"/>
</mujoco>
"""


@pytest.mark.parametrize(
    "numeric",
    [
        "",  # no custom fields at all
        '<numeric name="fsarm_params" data="1 2 3"/><numeric name="fsarm_ref" data="0"/>',
        # right size and names but no magic number
        f'<numeric name="fsarm_params" size="{layout.N_PARAMS}"/><numeric name="fsarm_ref" data="0"/>',
        # size and magic number right, name wrong (the lookup tests the name after them)
        f'<numeric name="fsarm_ref" data="0"/>'
        f'<numeric name="fsarm_param" size="{layout.N_PARAMS}" data="{layout.MAGIC}"/>',
    ],
)
def test_foreign_models_are_left_alone(numeric: str) -> None:
    m = mujoco.MjModel.from_xml_string(FOREIGN_XML.format(numeric=numeric))
    runs = {}
    for mode in ("off", "native"):
        d = mujoco.MjData(m)
        d.qpos[0] = 0.7
        d.ctrl[:] = (0.3, 0.0)
        d.act[0] = 0.25
        d.userdata[:] = 1.5
        if mode == "native":
            native.install()
        else:
            mujoco.set_mjcb_passive(None)
            mujoco.set_mjcb_act_dyn(None)
            mujoco.set_mjcb_control(None)
        mujoco.mj_step(m, d, nstep=50)
        native.uninstall()
        runs[mode] = d
    off, nat = runs["off"], runs["native"]
    np.testing.assert_array_equal(nat.qpos, off.qpos)
    np.testing.assert_array_equal(nat.qvel, off.qvel)
    np.testing.assert_array_equal(nat.act, [0.25])  # act_dyn returned 0
    np.testing.assert_array_equal(nat.ctrl, [0.3, 0.0])
    np.testing.assert_array_equal(nat.userdata, np.full(40, 1.5))


def test_install_and_uninstall() -> None:
    native.install()
    assert native.installed()
    assert mujoco.get_mjcb_passive() is native.PASSIVE
    native.uninstall()
    assert not native.installed()
    assert mujoco.get_mjcb_passive() is None
    src = callbacks.load_native()  # the prebuilt library where built, else this module
    with callbacks.active("native"):
        assert src.installed()
    assert not src.installed()


def _alone(cfg: SimConfig, table: np.ndarray, n: int) -> np.ndarray:
    sim = Simulation(cfg, table, "native")
    out = np.empty((n, mujoco.mj_stateSize(sim.model, FULLPHYSICS)))
    with callbacks.active("native"):
        for i in range(n):
            mujoco.mj_step(sim.model, sim.data)
            mujoco.mj_getState(sim.model, sim.data, out[i], FULLPHYSICS)
    return out


def test_rollout_threads_keep_each_models_parameters() -> None:
    """Two differently configured models stepped at the same time in two rollout threads give
    each model's own single-thread trajectory, bit for bit."""
    table = _table("fig14-sine", 1.0)
    cfgs = [_full(6.0, 435.0), _full(12.0, 535.0)]
    n = 800
    alone = [_alone(c, table, n) for c in cfgs]
    assert np.max(np.abs(alone[0] - alone[1])) > 1e-3  # the two configurations really differ
    sims = [Simulation(c, table, "native") for c in cfgs]
    result = batch.run_batch(sims, n, workers=2, record=True)
    assert result.states is not None and result.workers == 2
    for got, want in zip(result.states, alone, strict=True):
        np.testing.assert_array_equal(got, want)
    # the batch leaves each simulation at its final state, ready to continue
    final = np.empty(alone[0].shape[1])
    mujoco.mj_getState(sims[1].model, sims[1].data, final, FULLPHYSICS)
    np.testing.assert_array_equal(final, alone[1][-1])


def test_batch_continues_like_simulation_run() -> None:
    """A batch of 300 steps after 200 stepped by Simulation.run == 500 steps of Simulation.run,
    user inputs (an applied force on joint 1) included."""
    table = _table("step-q3", 0.6)
    ref = Simulation(_full(), table, "native")
    ref.data.qfrc_applied[ref.structure.dof[0]] = 2.0
    ref.run(0.5, log_every_ticks=0)
    sim = Simulation(_full(), table, "native")
    sim.data.qfrc_applied[sim.structure.dof[0]] = 2.0
    sim.run(0.2, log_every_ticks=0)
    batch.run_batch([sim], 300, workers=1)
    assert abs(sim.data.qpos[sim.structure.qadr[0]]) > 1e-4  # the applied force acted
    for attr in ("qpos", "qvel", "act", "userdata", "time"):
        np.testing.assert_array_equal(getattr(sim.data, attr), getattr(ref.data, attr))


def test_batch_rejects_bad_arguments_and_reports_warnings() -> None:
    table = _table("step-q3", 0.2)
    sims = [Simulation(_full(), table, "native"), Simulation(_full(), table, "python")]
    with pytest.raises(InvalidParameterError, match="one callback backend"):
        batch.run_batch(sims, 10)
    with pytest.raises(InvalidParameterError, match="at least one"):
        batch.run_batch([], 10)
    with pytest.raises(InvalidParameterError, match="n_steps"):
        batch.run_batch(sims[:1], 0)
    with pytest.raises(InvalidParameterError, match="workers"):
        batch.run_batch(sims[:1], 10, workers=0)
    with pytest.raises(InvalidParameterError, match="twice"):
        batch.run_batch([sims[0], sims[0]], 10)
    bad = sims[0]
    bad.data.qvel[:] = 1e12  # MuJoCo flags the blown-up state (mjWARN_BADQVEL / BADQACC)
    with pytest.raises(SimulationWarningError):
        batch.run_batch([bad], 10)


def test_offsets_are_verified_against_the_bindings() -> None:
    native_abi._verify_offsets(native.OFFSETS)  # the table in use passes
    if mujoco.__version__ in native_abi._RECORDED:  # the no-compiler fallback also passes
        assert native_abi._RECORDED[mujoco.__version__] == native.OFFSETS
    broken = json.loads(json.dumps(native.OFFSETS))
    broken["data"]["qvel"][0] += 8  # qvel's slot now points at act
    with pytest.raises(native_abi.NativeBackendError, match=r"mjData\.qvel"):
        native_abi._verify_offsets(broken)
    broken = json.loads(json.dumps(native.OFFSETS))
    broken["model"]["nnumeric"][0] += 8
    with pytest.raises(native_abi.NativeBackendError, match=r"mjModel\.nnumeric"):
        native_abi._verify_offsets(broken)


@pytest.mark.skipif(native_abi.compiler() is None, reason="no C compiler to run the offsetof probe")
def test_offsetof_probe_matches_table_in_use() -> None:
    assert native_abi._offsets_from_compiler(native_abi.compiler() or "cc") == native.OFFSETS


def test_compiled_callbacks_are_cached() -> None:
    """A fresh process loads all the callbacks (the clock too) from the cache this process
    filled."""
    code = "from fsarm_sim.engine import native; print(native.COMPILE_INFO.cache_hits)"
    env = dict(os.environ)
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert out.stdout.strip().splitlines()[-1] == str(len(native.CFUNCS)), out.stderr[-2000:]


def test_speed_benchmark_runs_and_reports() -> None:
    """Smoke test of the benchmark's plumbing (tiny sizes; the numbers are not checked)."""
    from fsarm_sim.studies.speed import format_report, measure_speed

    r = measure_speed(
        reps=1,
        block_steps=20,
        rtf_reps=1,
        rtf_duration_s=0.05,
        batch_reps=1,
        batch_runs=2,
        batch_duration_s=0.05,
        max_workers=2,
    )
    for v in (r.raw_us, r.python_us, r.native_us, r.rtf_native, *r.batch_steps_per_s.values()):
        assert np.isfinite(v) and v > 0
    assert set(r.batch_scaling) == {1, 2} and r.batch_scaling[1] == 1.0
    text = format_report(r)
    assert "native/raw" in text and "real-time factor" in text and "2 workers" in text
    assert "per point (inline)" in text
