"""The MJCF models and the run configuration built on them."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fsarm_sim.engine.model import Gains, SimConfig, build_model, model_path, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout as L

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
    p = m.numeric(L.PARAMS_NAME).data
    assert p[L.P_MAGIC] == L.MAGIC
    assert p[L.P_TAU_BW] == 70.0
    assert p[L.P_TR] == pytest.approx(cfg.shaft.k_pos)  # the shaft block: k_pos first
    assert p[L.P_N_TICKS] == 5
    # the kernels' userdata, then the run recorder's buffer (spec_sizes: the compiled sizes)
    assert m.nuserdata == L.N_USERDATA + L.REC_ROWS_DEFAULT * L.rec_width(m.nq, m.nv, m.na)


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
