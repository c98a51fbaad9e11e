"""The standalone MJCF export: plain MuJoCo (no fsarm callbacks) drives the elbow through the
linearised shaft spring, with no warnings; the numbers in it are the transmission's."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from typer.testing import CliRunner

from fsarm_sim.cli import app
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig, model_path
from fsarm_sim.engine.standalone import (
    bending_stiffness,
    linear_shaft_stiffness,
    standalone_xml,
)
from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.shaft import load_catalogue


def _settle(m: mujoco.MjModel, ctrl: list[float], steps: int = 3000) -> mujoco.MjData:
    d = mujoco.MjData(m)
    d.ctrl[:] = ctrl
    for _ in range(steps):
        mujoco.mj_step(m, d)
    assert not np.any(d.warning.number), d.warning
    return d


@pytest.mark.parametrize("payload_kg", [0.0, 15.0])
def test_elbow_follows_its_servo_through_the_shaft_spring(payload_kg: float) -> None:
    with callbacks.suspended():
        m = mujoco.MjModel.from_xml_string(standalone_xml(SimConfig(payload_kg=payload_kg)))
        d = _settle(m, [0.0, math.pi / 4, 0.5])
    q = d.qpos
    assert abs(q[1] - math.pi / 4) < math.radians(5.0)
    # the shaft carries the elbow's gravity load: the spring's torque times the hypoid ratio is
    # the gravity torque at q3, and the elbow sags behind the motor by the twist
    twist = q[3] / 16.0 - 10.0 * q[2]
    k = m.tendon_stiffness[m.tendon("shaft_twist").id]
    gravity_q3 = d.qfrc_bias[2]  # at rest: gravity only
    assert 10.0 * k * twist == pytest.approx(gravity_q3, rel=0.02)
    sag = 0.5 - q[2]
    assert sag == pytest.approx(twist / 10.0, abs=math.radians(1.0))
    if payload_kg == 0.0:
        assert abs(sag) < math.radians(1.0)


def test_packaged_model_alone_leaves_the_elbow_limp() -> None:
    """The contrast the export exists for: without fsarm's callbacks the packaged model's shaft
    transmits nothing, so turning the motor does not move the elbow."""
    with callbacks.suspended():
        m = mujoco.MjModel.from_xml_path(str(model_path()))
        m.opt.gravity[:] = 0.0
        d = mujoco.MjData(m)
        d.ctrl[m.actuator("j3_motor").id] = 0.5
        for _ in range(500):
            mujoco.mj_step(m, d)
    assert abs(d.qpos[2]) < 1e-9 and abs(d.qpos[3]) > 1.0


def test_spring_constants_are_the_transmissions() -> None:
    cfg = SimConfig(shaft=load_catalogue().shaft(diameter_mm=6.5, length_mm=335.0))
    bend = math.radians(60.0)
    m = mujoco.MjModel.from_xml_string(standalone_xml(cfg, bend))
    k = linear_shaft_stiffness(cfg, bend)
    sh = cfg.shaft
    assert min(sh.k_series(bend, 1), sh.k_series(bend, -1)) <= k
    assert k <= max(sh.k_series(bend, 1), sh.k_series(bend, -1))
    assert m.tendon_stiffness[m.tendon("shaft_twist").id] == pytest.approx(k)
    assert m.jnt_stiffness[m.joint("q2").id] == pytest.approx(bending_stiffness(cfg))
    assert m.nuserdata == 0 and m.nu == 3


def test_noisy_controls_give_no_warning() -> None:
    """A Menagerie-style check: 3000 steps of random controls."""
    m = mujoco.MjModel.from_xml_string(standalone_xml())
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    for _ in range(3000):
        d.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(m, d)
    assert not np.any(d.warning.number)
    assert np.all(np.isfinite(d.qpos))


def test_bad_bend_is_a_named_error() -> None:
    with pytest.raises(FsarmError):
        standalone_xml(bend_rad=math.radians(500.0))


def test_cli_writes_the_scene_and_the_template(tmp_path: object) -> None:
    from pathlib import Path

    out = Path(str(tmp_path))
    r = CliRunner().invoke(app, ["export-mjcf", str(out / "arm.xml"), "--bend-deg", "30"])
    assert r.exit_code == 0, r.output
    mujoco.MjModel.from_xml_path(str(out / "arm.xml"))
    r = CliRunner().invoke(app, ["shafts", "--export", str(out / "mine.toml")])
    assert r.exit_code == 0, r.output
    assert load_catalogue(out / "mine.toml").shaft() == load_catalogue().shaft()
    assert "ESTIMATES" in (out / "mine.toml").read_text()
