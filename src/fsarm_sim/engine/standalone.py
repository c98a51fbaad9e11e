"""A standalone MJCF of the arm for the stock MuJoCo viewer and other MuJoCo tools.

The packaged model (``models/fsarm``) leaves the shaft to fsarm's callbacks: in plain MuJoCo its
``shaft_twist`` tendon has no stiffness, so the elbow motor drives nothing. :func:`standalone_xml`
writes a self-contained scene in which the shaft is its **linearised** stiffness - an
approximation, stated in the file:

* ``shaft_twist`` gets the tendon stiffness of joint 3's transmission at the chosen bend, the mean
  of its winding and unwinding sides at zero twist (eq. 3 for the flexible shaft; no asymmetry,
  no hysteresis, no slip, no bend dependence while the arm moves);
* joint 2 gets the shaft's parallel bending stiffness K_b as a joint spring about upright (eq. 2
  linearised: the cubic β term and the conduit's viscoelastic branches are dropped);
* the actuators are position servos the viewer's sliders drive: q1, q2 at the joints, and the
  elbow's motor on the motor-side angle θ_m scaled to elbow radians (``gear`` 1/i_G2), so the
  elbow follows its slider *through the shaft spring*; the internal-state carriers, parameter
  and reference storage of the simulator are removed.

Servo gains are estimates chosen to hold the arm with the 15 kg payload within about a degree
and to stay well damped at the 1 ms Euler step (see the constants).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig, build_spec, model_path, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout

# Position servos (estimates): q2 must hold ~25 N·m of gravity without payload and ~145 N·m with
# 15 kg (Table III geometry), so 2000 N·m/rad leaves < 5° of sag at full payload; damping near
# critical for its ~2.6 kg·m² (armature 2.5). q1 carries no gravity.
Q1_KP, Q1_KV = 500.0, 50.0
Q2_KP, Q2_KV = 2000.0, 150.0
# The elbow servo acts on θ_m / i_G2 (elbow radians): 5000 N·m/rad there is 50 N·m/rad on θ_m
# (gear² = 1/100), beside the shaft's ~15 N·m/rad, against the rotor's ~0.008 kg·m² seen at θ_m
# (3e-5 · 16²): ~80 rad/s, damping ratio ~0.4 with kv = 50 (0.5 N·m·s/rad on θ_m).
J3_KP, J3_KV = 5000.0, 50.0
TWIST_PROBE_RAD = 1e-3  # the twist at which each side's stiffness is read (a small-signal slope)


def linear_shaft_stiffness(config: SimConfig, bend_rad: float) -> float:
    """Mean of joint 3's transmission stiffness on its two sides at zero twist and ``bend_rad``
    (N·m/rad, shaft side), from the controller's block (eq. 3 alone for the flexible shaft)."""
    tr = config.transmission_model()
    block = config.transmission_blocks()[1]
    k = 0.5 * (
        tr.stiffness(block, TWIST_PROBE_RAD, bend_rad)
        + tr.stiffness(block, -TWIST_PROBE_RAD, bend_rad)
    )
    return float(k)


def bending_stiffness(config: SimConfig) -> float:
    """The parallel bending stiffness K_b at joint 2 (N·m/rad); 0 for a transmission not routed
    over joint 2."""
    return float(config.shaft.kb) if config.transmission == "flexible-shaft" else 0.0


def standalone_spec(
    config: SimConfig | None = None, bend_rad: float = math.pi / 4
) -> mujoco.MjSpec:
    """The standalone scene (see the module docstring) as an MjSpec."""
    cfg = config or SimConfig()
    if isinstance(bend_rad, bool) or not math.isfinite(bend_rad):
        raise InvalidParameterError(f"bend must be a finite angle in rad, got {bend_rad!r}")
    cfg.validate()
    if cfg.transmission == "flexible-shaft":
        cfg.shaft.check_bend(bend_rad)
    spec = build_spec(
        cfg, np.zeros((1, layout.REF_COLS)), model_path("fsarm").with_name("scene.xml")
    )
    with callbacks.suspended():
        st = read_structure(mujoco.MjSpec.from_file(str(model_path())).compile())
    for act in list(spec.actuators):
        spec.delete(act)
    for num in list(spec.numerics):
        if num.name in (layout.PARAMS_NAME, layout.REF_NAME):
            spec.delete(num)
    spec.nuserdata = 0
    spec.tendon("shaft_twist").stiffness = [linear_shaft_stiffness(cfg, bend_rad), 0.0, 0.0]
    spec.joint("q2").stiffness = [bending_stiffness(cfg), 0.0, 0.0]
    spec.joint("q2").springref = 0.0
    for name, target, kind, gear, kp, kv, ctrl in (
        ("q1_servo", "q1", mujoco.mjtTrn.mjTRN_JOINT, 1.0, Q1_KP, Q1_KV, 2.967),
        ("q2_servo", "q2", mujoco.mjtTrn.mjTRN_JOINT, 1.0, Q2_KP, Q2_KV, 2.094),
        ("q3_servo", "theta_m", mujoco.mjtTrn.mjTRN_TENDON, 1.0 / st.coef_s, J3_KP, J3_KV, 2.618),
    ):
        act = spec.add_actuator(name=name, target=target, trntype=kind)
        act.gear[0] = gear
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.gainprm[0] = kp
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[:3] = [0.0, -kp, -kv]
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.ctrlrange = [-ctrl, ctrl]
    spec.key("home").ctrl = np.zeros(3)
    q2 = spec.key("home")
    q2.qpos = np.zeros(4)
    return spec


def standalone_xml(config: SimConfig | None = None, bend_rad: float = math.pi / 4) -> str:
    """The standalone scene as MJCF text, headed by a comment saying what is approximated."""
    cfg = config or SimConfig()
    spec = standalone_spec(cfg, bend_rad)
    k = linear_shaft_stiffness(cfg, bend_rad)
    note = (
        "<!-- fsarm-sim standalone export: a self-contained scene for the stock MuJoCo viewer.\n"
        f"  APPROXIMATION: joint 3's {cfg.transmission} is the linear spring shaft_twist "
        f"(stiffness {k:.4g} N*m/rad,\n"
        f"  its two sides' mean at {math.degrees(bend_rad):.4g} deg of bend) and joint 2 has its "
        f"bending stiffness K_b = {bending_stiffness(cfg):.4g} N*m/rad;\n"
        "  no asymmetry, hysteresis, slip, bend dependence or fsarm controllers (those need\n"
        "  fsarm_sim's callbacks: `fsarm run`). Actuators are position servos in joint radians;\n"
        "  q3_servo drives the joint-3 motor, so the elbow follows it through the shaft spring. -->\n"
    )
    return note + spec.to_xml()
