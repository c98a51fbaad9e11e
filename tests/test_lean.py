"""The lean twin (fsarm_sim.engine.lean): the same dynamics as the full model, fewer elements."""

from __future__ import annotations

import numpy as np
import pytest

from fsarm_sim.engine.model import SimConfig, build_model
from fsarm_sim.errors import FsarmError
from fsarm_sim.kernels import layout
from fsarm_sim.plant import transmissions
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import run_scenario

STATE = ("q1", "q2", "q3", "qd1", "qd2", "qd3", "theta_m", "omega_m", "tau_shaft", "tau_motor")


def test_the_twin_drops_visual_geoms_and_sensors_only() -> None:
    ref = np.zeros((2, layout.REF_COLS))
    full = build_model(SimConfig(payload_kg=5.0), ref)
    lean = build_model(SimConfig(payload_kg=5.0), ref, lean=True)
    assert lean.nsensor == 0 < full.nsensor
    assert lean.ngeom < full.ngeom
    for name in ("nbody", "njnt", "nq", "nv", "na", "nu", "nsite", "ntendon", "nuserdata"):
        assert getattr(lean, name) == getattr(full, name), name
    np.testing.assert_array_equal(lean.body_mass, full.body_mass)
    np.testing.assert_array_equal(lean.body_inertia, full.body_inertia)
    np.testing.assert_array_equal(
        lean.numeric(layout.PARAMS_NAME).data, full.numeric(layout.PARAMS_NAME).data
    )


@pytest.mark.parametrize("transmission", transmissions.names())
def test_every_scenario_runs_the_same_on_the_twin(transmission: str) -> None:
    """10 s of every scenario (with its disturbance and outer loop): states within 1e-9."""
    for sc in scenarios.REGISTRY.values():
        cfg = SimConfig(transmission=transmission)
        out = []
        for lean in (False, True):
            try:
                r = run_scenario(sc.name, cfg, duration_s=10.0, lean=lean)
                out.append(r.columns)
            except FsarmError as exc:  # e.g. a spring that cannot hold the payload, a failed run
                out.append({"failed": str(exc)})
        if "failed" in out[0] or "failed" in out[1]:
            assert out[0] == out[1], (sc.name, transmission)
            continue
        for key in STATE:
            err = float(np.max(np.abs(out[0][key] - out[1][key])))
            assert err <= 1e-9, (sc.name, transmission, key, err)


def test_the_twin_switches_off_only_a_spring_stage_that_adds_nothing() -> None:
    """idle_off disables MuJoCo's spring stage in the twin (no joint or tendon of the arm has a
    spring), never in the full model, and keeps it where any element has a spring."""
    import mujoco

    from fsarm_sim.engine import lean as lean_mod

    spring = int(mujoco.mjtDisableBit.mjDSBL_SPRING)
    ref = np.zeros((2, layout.REF_COLS))
    full = build_model(SimConfig(), ref)
    twin = build_model(SimConfig(), ref, lean=True)
    assert twin.opt.disableflags & spring
    assert not full.opt.disableflags & spring
    assert not lean_mod.has_springs(twin)
    for field in ("jnt_stiffness", "jnt_stiffnesspoly", "tendon_stiffness", "tendon_stiffnesspoly"):
        m = build_model(SimConfig(), ref)
        getattr(m, field).flat[0] = 1.0
        assert lean_mod.has_springs(m), field
        assert not lean_mod.idle_off(m) and not m.opt.disableflags & spring, field


@pytest.mark.parametrize("transmission", transmissions.names())
def test_the_spring_stage_off_changes_no_bit(
    transmission: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """10 s of every scenario on the twin with and without idle_off: every column bit for bit."""
    from fsarm_sim.engine import model as model_mod

    for sc in scenarios.REGISTRY.values():
        cfg = SimConfig(transmission=transmission)
        out = []
        for off in (True, False):
            if not off:
                monkeypatch.setattr(model_mod, "idle_off", lambda m: False)
            try:
                out.append(run_scenario(sc.name, cfg, duration_s=10.0, lean=True).columns)
            except FsarmError as exc:
                out.append({"failed": np.array([str(exc)])})
        assert out[0].keys() == out[1].keys(), (sc.name, transmission)
        for key in out[0]:
            np.testing.assert_array_equal(out[0][key], out[1][key], err_msg=f"{sc.name} {key}")
        monkeypatch.undo()


@pytest.mark.parametrize("field", ["jnt_stiffness", "tendon_stiffness"])
def test_a_spring_written_into_the_twin_later_is_refused_not_ignored(field: str) -> None:
    """A stiffness written into the lean twin after it was built would be inert (its spring
    stage is off): run() and step() refuse it with a named error instead of ignoring it."""
    from fsarm_sim.errors import ModelStructureError
    from fsarm_sim.sim.simulation import Simulation

    ref = np.zeros((20, layout.REF_COLS))
    sim = Simulation(SimConfig(), ref, lean=True)
    sim.run(0.005)  # fine before the write
    getattr(sim.model, field).flat[0] = 50.0
    with pytest.raises(ModelStructureError, match="lean=False"):
        sim.run(0.005)
    with pytest.raises(ModelStructureError, match="lean=False"):
        sim.step()
    full = Simulation(SimConfig(), ref, lean=False)  # the full model keeps its spring stage
    getattr(full.model, field).flat[0] = 50.0
    full.run(0.005)
