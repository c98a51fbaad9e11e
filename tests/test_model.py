"""The MJCF models and the run configuration built on them."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine.model import Gains, SimConfig, build_model, model_path, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.shaft import load_catalogue

from conftest import hold_table

MODELS = Path(str(model_path())).parent


def test_model_and_scene_compile_without_warnings() -> None:
    for name in ("fsarm.xml", "scene.xml"):
        m = mujoco.MjModel.from_xml_path(str(MODELS / name))
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
        for _ in range(50):
            mujoco.mj_step(m, d)
        assert all(w.number == 0 for w in d.warning)


def test_structure_as_seed000() -> None:
    m = mujoco.MjModel.from_xml_path(str(MODELS / "fsarm.xml"))
    st = read_structure(m)
    assert st.i_g1 == pytest.approx(16.0)  # seed 000 Sec. IV-A2
    assert st.i_g2 == pytest.approx(10.0)
    # whole robot under one root body (Pinocchio's MJCF parser reads only the first)
    roots = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
    assert len(roots) == 1
    # Table III geometry: L1 = 200, L2 = 420, L3 = 400 mm
    assert m.body("link2").pos[2] == pytest.approx(0.200)
    assert m.body("link3").pos[2] == pytest.approx(0.420)
    assert m.body("payload").pos[2] == pytest.approx(0.400)
    # the joint-3 rotor sits on link 1, its axis parallel to joint 1's
    rotor = m.joint("j3_rotor")
    assert m.body_parentid[rotor.bodyid[0]] == m.body("link1").id
    assert np.allclose(rotor.axis, m.joint("q1").axis)
    # rotor inertia reflected for the 50:1 and 100:1 harmonic drives (armature)
    assert m.joint("q1").armature[0] > 0 and m.joint("q2").armature[0] > 0


def test_payload_is_applied_and_limited() -> None:
    m0 = build_model(SimConfig(), hold_table(0, 0, 0))
    m15 = build_model(SimConfig(payload_kg=15.0), hold_table(0, 0, 0))
    assert m15.body("payload").mass[0] == pytest.approx(15.0)
    assert m0.body("payload").mass[0] == pytest.approx(0.0)
    for bad in (-1.0, 15.5, math.nan):
        with pytest.raises(InvalidParameterError, match="payload"):
            build_model(SimConfig(payload_kg=bad), hold_table(0, 0, 0))


def test_parameters_reach_the_model() -> None:
    cfg = SimConfig(gains=Gains(torque_bandwidth_rad_s=70.0))
    m = build_model(cfg, hold_table(0.1, 0.2, 0.3, n=5))
    p = m.numeric(layout.PARAMS_NAME).data
    assert p[layout.P_MAGIC] == layout.MAGIC
    assert p[layout.P_TAU_BW] == 70.0
    assert p[layout.P_TR] == pytest.approx(cfg.shaft.k_pos)  # the shaft block: k_pos first
    assert p[layout.P_N_TICKS] == 5
    # the kernels' userdata, then the run recorder's buffer (spec_sizes: the compiled sizes)
    assert m.nuserdata == layout.N_USERDATA + layout.REC_ROWS_DEFAULT * layout.rec_width(
        m.nq, m.nv, m.na
    )


@pytest.mark.parametrize(
    ("cfg", "match"),
    [
        (SimConfig(gains=Gains(ctrl_dt_s=0.0015)), "whole multiple"),
        (SimConfig(gains=Gains(torque_bandwidth_rad_s=math.nan)), "torque_bandwidth"),
        (SimConfig(gains=Gains(ctrl_dt_s=0.0)), "ctrl_dt_s"),
        (SimConfig(timestep_s=-1.0), "timestep"),
        (SimConfig(integrator="Verlet"), "integrator"),
    ],
)
def test_bad_configuration(cfg: SimConfig, match: str) -> None:
    with pytest.raises(InvalidParameterError, match=match):
        build_model(cfg, hold_table(0, 0, 0))


def test_bad_reference_table() -> None:
    with pytest.raises(InvalidParameterError, match="shape"):
        build_model(SimConfig(), np.zeros((3, 4)))
    bad = hold_table(0, 0, 0)
    bad[0, 0] = np.nan
    with pytest.raises(InvalidParameterError, match="NaN"):
        build_model(SimConfig(), bad)


def test_broken_mjcf_gives_structure_error(tmp_path: Path) -> None:
    text = (MODELS / "fsarm.xml").read_text().replace('coef="-10"', 'coef="-9"')
    f = tmp_path / "fsarm.xml"
    f.write_text(text)
    with pytest.raises(ModelStructureError, match="shaft_twist"):
        build_model(SimConfig(), hold_table(0, 0, 0), path=f)


def _mjb(model: mujoco.MjModel) -> bytes:
    """Every field of a compiled model, as MuJoCo saves it (MJB)."""
    buf = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return buf.tobytes()


def _cached_configs() -> list[SimConfig]:
    from dataclasses import replace

    from fsarm_sim.engine.model import Effects
    from fsarm_sim.plant.shaft import load_catalogue

    cat = load_catalogue()
    return [
        SimConfig(shaft=cat.shaft(6, 335)),
        SimConfig(shaft=cat.shaft(12, 535)),  # other slip limits: the same structure
        SimConfig(shaft=cat.shaft(8, 435, series_hysteresis=True), payload_kg=5.0),
        SimConfig(shaft=replace(cat.shaft(10, 435), inertia_kgm2=2e-5)),
        SimConfig(
            effects=Effects(
                laws=(
                    ("coulomb_friction", (("f_c_nm", 0.5),)),
                    ("viscous_damping", (("b_nms", 0.2),)),
                )
            ),
            joint_damping=False,
            timestep_s=0.0005,
            integrator="RK4",
        ),
        SimConfig(transmission="rtca"),
        SimConfig(transmission="tendon-sheath"),
        SimConfig(shaft=cat.shaft(6, 335), gains=Gains(wn_rad_s=(10.0, 12.0, 14.0))),
    ]


@pytest.mark.parametrize("lean", [True, False])
def test_cached_build_is_the_fresh_build(lean: bool) -> None:
    """build_model copies a compiled model kept per structure: every field of what it returns is
    the same as compiling afresh, whichever runs were built before (issue 15)."""
    from fsarm_sim.engine import model as model_mod

    table = hold_table(0.0, 0.5, 0.3, n=50)
    configs = _cached_configs()
    fresh = []
    for cfg in configs:
        model_mod.clear_model_cache()
        fresh.append(_mjb(build_model(cfg, table, lean=lean)))
    model_mod.clear_model_cache()
    for _ in range(2):  # in order, then again with every structure kept
        for cfg, want in zip(configs, fresh, strict=True):
            assert _mjb(build_model(cfg, table, lean=lean)) == want
    for cfg, want in zip(reversed(configs), reversed(fresh), strict=True):
        assert _mjb(build_model(cfg, table, lean=lean)) == want
    # the cached path was the one tested: configs 0, 1 and 7 differ only in numbers, so they
    # share one kept structure
    model_mod.clear_model_cache()
    for i in (0, 1, 7):
        build_model(configs[i], table, lean=lean)
    assert len(model_mod._cache) == 1


def test_built_models_share_nothing() -> None:
    """Each build_model is its own model: writing one changes neither the next nor another."""
    table = hold_table(0.0, 0.5, 0.3, n=5)
    a = build_model(SimConfig(), table, lean=True)
    want = _mjb(a)
    b = build_model(SimConfig(), table, lean=True)
    b.dof_damping[:] = 123.0
    b.numeric(layout.PARAMS_NAME).data[:] = -1.0
    b.numeric(layout.REF_NAME).data[:] = 7.0
    b.actuator_actrange[:] = 0.25
    assert _mjb(a) == want
    assert _mjb(build_model(SimConfig(), table, lean=True)) == want


def test_long_tables_are_not_kept() -> None:
    """A reference table over the cache's size limit is compiled afresh and not kept."""
    from fsarm_sim.engine import model as model_mod

    model_mod.clear_model_cache()
    n = model_mod.MODEL_CACHE_MAX_REF_NUMBERS // layout.REF_COLS + 1
    build_model(SimConfig(), hold_table(0.0, 0.5, 0.3, n=n), lean=True)
    assert not model_mod._cache


def test_transmission_blocks_are_kept_per_config_and_handed_out_as_copies() -> None:
    cfg = SimConfig()
    plant, ctrl = cfg.transmission_blocks()
    plant[:] = np.nan  # a caller writing into its copy
    ctrl[:] = np.nan
    again = cfg.transmission_blocks()
    assert np.all(np.isfinite(again[0])) and np.all(np.isfinite(again[1]))
    # a changed config builds its own blocks
    other = cfg.with_(shaft=load_catalogue().shaft(cfg.shaft.diameter_mm, 335.0))
    assert not np.array_equal(other.transmission_blocks()[0], again[0])
    assert other == other.with_() and cfg != other  # the kept blocks are not a field


SCENES = sorted(MODELS.parent.glob("*/scene*.xml"))


@pytest.mark.parametrize("path", SCENES, ids=[f"{p.parent.name}/{p.name}" for p in SCENES])
def test_scenes_survive_noisy_controls_without_warnings(path: Path) -> None:
    """Menagerie's model test: 3000 steps of random controls within the control ranges, plain
    MuJoCo (no fsarm callbacks), no warning and a finite state."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    lo = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 0], -1.0)
    hi = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 1], 1.0)
    for _ in range(3000):
        d.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(m, d)
    assert all(w.number == 0 for w in d.warning)
    assert np.all(np.isfinite(d.qpos))


@pytest.mark.parametrize("folder", ["fsarm", "bench"])
def test_model_folders_are_complete(folder: str) -> None:
    """Each model folder stands alone as in Menagerie: a licence, a changelog, a README with the
    sources, and at least one scene."""
    here = MODELS.parent / folder
    for name in ("LICENSE", "CHANGELOG.md", "README.md"):
        assert (here / name).is_file(), name
    assert list(here.glob("scene*.xml"))
