"""Where per-model parameters and per-run states live, so process-global callbacks find them.

MuJoCo callbacks are process-global (toolchain.md). Everything a callback needs therefore travels
*inside* the model and data it receives:

* ``model.numeric("fsarm_params")`` - parameter vector (layout ``P_*`` below), written at build;
* ``model.numeric("fsarm_ref")``    - reference table, one row per control tick:
  ``q_ref[3], qd_ref[3], qdd_ref[3]``;
* ``data.userdata``                 - discrete controller memory, held outputs and logs (``U_*``);
* ``data.act``                      - continuous internal states (conduit branches, slip elements),
  integrated by MuJoCo.

The indices are plain module-level ints so that Numba-compiled kernels can use them as constants.
"""

from __future__ import annotations

from typing import NamedTuple

from fsarm_sim.paramblocks import Decl, Layout
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import bending, conduit_viscoelastic, registry
from fsarm_sim.plant.transmissions.base import N_TR

PARAMS_NAME = "fsarm_params"
REF_NAME = "fsarm_ref"
MAGIC = 7013.0  # first parameter; marks an fsarm model so callbacks ignore foreign models
REF_COLS = 9

# Joint-3 transmissions: the kernels dispatch on the integer id, the module's place in the
# registry (fsarm_sim.plant.transmissions.MODULES); tests/test_layout.py checks that every id reaches
# its own module's kernels. N_TR is the interface's block size.
TRANSMISSION_MODULES = tuple(transmissions.MODULES)
TR_TENDON_SHEATH = transmissions.KIND["tendon_sheath"]

# --- the parameter vector, block by block (offsets computed here, in this order) ---
LAYOUT = Layout()
_ = LAYOUT
P_MAGIC = _.one("magic", "magic", "-", "marks an fsarm model (MAGIC)", MAGIC)

# structure, read from the compiled MJCF (never typed twice). A qpos/dof index of -1 means
# "absent" (bench models): its angle and rate read as 0 (for the bend joint: P_BEND_FIXED) and no
# force is applied to it.
_s = _.block(
    "structure",
    (
        Decl("qadr_q1", "index", 0.0, "qpos address of q1"),
        Decl("qadr_q2", "index", 0.0, "qpos address of q2 (the bend joint)"),
        Decl("qadr_q3", "index", 0.0, "qpos address of q3"),
        Decl("qadr_rot", "index", 0.0, "qpos address of joint 3's motor rotor"),
        Decl("dof_q1", "index", 0.0, "dof address of q1"),
        Decl("dof_q2", "index", 0.0, "dof address of q2"),
        Decl("dof_q3", "index", 0.0, "dof address of q3"),
        Decl("dof_rot", "index", 0.0, "dof address of the rotor"),
        Decl("coef_m", "-", 0.0, "theta_m = coef_m * rotor angle (1 / i_G1, shaft_twist tendon)"),
        Decl("coef_s", "-", 0.0, "theta_s = coef_s * q3 (i_G2, shaft_twist tendon)"),
        Decl("act_br1", "index", 0.0, "act address of conduit branch 1"),
        Decl("act_br2", "index", 0.0, "act address of conduit branch 2"),
        Decl("act_slip1", "index", 0.0, "act address of the transmission's first state slot"),
        Decl("ctrl_j1", "index", 0.0, "ctrl address of joint 1's motor"),
        Decl("ctrl_j2", "index", 0.0, "ctrl address of joint 2's motor"),
        Decl("ctrl_j3", "index", 0.0, "ctrl address of joint 3's motor (rotor torque)"),
        Decl("madr_q1", "index", 0.0, "data.M address of q1's inertia diagonal (CSR)"),
        Decl("madr_q2", "index", 0.0, "data.M address of q2's inertia diagonal"),
        Decl("madr_q3", "index", 0.0, "data.M address of q3's inertia diagonal"),
    ),
)
P_QADR_Q1, P_QADR_Q2, P_QADR_Q3, P_QADR_ROT = (
    _s[k] for k in ("qadr_q1", "qadr_q2", "qadr_q3", "qadr_rot")
)
P_DOF_Q1, P_DOF_Q2, P_DOF_Q3, P_DOF_ROT = (_s[k] for k in ("dof_q1", "dof_q2", "dof_q3", "dof_rot"))
P_COEF_M, P_COEF_S = _s["coef_m"], _s["coef_s"]
P_ACT_BR1, P_ACT_BR2, P_ACT_SLIP1 = _s["act_br1"], _s["act_br2"], _s["act_slip1"]
P_CTRL_J1, P_CTRL_J2, P_CTRL_J3 = _s["ctrl_j1"], _s["ctrl_j2"], _s["ctrl_j3"]
P_MADR_Q1, P_MADR_Q2, P_MADR_Q3 = _s["madr_q1"], _s["madr_q2"], _s["madr_q3"]

# the shaft's parallel (bending) side: each law declares its own block
_b = _.block("bending", bending.KERNEL_PARAMS)
P_KB, P_BETA = _b["kb"], _b["beta"]
_c = _.block("conduit", conduit_viscoelastic.KERNEL_PARAMS)
P_BR_K1, P_BR_TAU1, P_BR_K2, P_BR_TAU2 = _c["k1"], _c["tau1"], _c["k2"], _c["tau2"]

# plant switches (1.0 on, 0.0 off)
_e = _.block(
    "switches",
    (
        Decl("series", "on/off", 1.0, "joint 3's transmission carries torque (Effects.series)"),
        Decl("bend", "on/off", 1.0, "eq. 2/4 bending moment on joint 2 (Effects.bending)"),
        Decl("conduit", "on/off", 1.0, "conduit visco-elastic branches (Effects.conduit)"),
        Decl(
            "coupling",
            "on/off",
            1.0,
            "-dV/dphi_B of the transmission on joint 2 (Effects.coupling)",
        ),
        Decl("control", "on/off", 1.0, "the controllers and their clock run (Effects.control)"),
    ),
)
P_EN_SERIES, P_EN_BEND, P_EN_CONDUIT = _e["series"], _e["bend"], _e["conduit"]
P_EN_COUPLING, P_EN_CONTROL = _e["coupling"], _e["control"]

# controllers (model.Gains, controllers/): clock, position loops, joint-3 cascade, limits
_g = _.block(
    "control",
    (
        Decl("ctrl_dt", "s", 0.001, "control period (Gains.ctrl_dt_s)"),
        Decl("n_ticks", "-", 1.0, "rows of the reference table fsarm_ref"),
        Decl("wn1", "rad/s", 20.0, "joint 1 position loop natural frequency"),
        Decl("zeta1", "-", 1.0, "joint 1 position loop damping ratio"),
        Decl("wn2", "rad/s", 20.0, "joint 2 position loop natural frequency"),
        Decl("zeta2", "-", 1.0, "joint 2 position loop damping ratio"),
        Decl("wn3", "rad/s", 25.0, "joint 3 outer position loop natural frequency"),
        Decl("zeta3", "-", 1.0, "joint 3 outer position loop damping ratio"),
        Decl("tau_bw", "rad/s", 60.0, "torque PID loop bandwidth w_t (gains scheduled on K)"),
        Decl("tau_wi", "rad/s", 10.0, "torque PID integral corner w_i"),
        Decl("tau_kdn", "-", 0.0, "torque PID normalized derivative gain"),
        Decl("spd_kp", "N*m*s/rad", 0.009, "EPOS-like speed loop proportional gain, motor side"),
        Decl("spd_ki", "N*m/rad", 0.3, "speed loop integral gain, motor side"),
        Decl("omega_max", "rad/s", 0.0, "motor speed limit, motor side (MJCF)"),
        Decl("tau_mot_max", "N*m", 0.0, "motor torque (current) limit, motor side (MJCF)"),
        Decl("tau1_max", "N*m", 0.0, "joint 1 torque limit (MJCF)"),
        Decl("tau2_max", "N*m", 0.0, "joint 2 torque limit (MJCF)"),
        Decl("cm_kb", "N*m/rad", 0.0, "the controller's model of K_b (eq. 4)"),
        Decl("cm_beta", "1/rad^2", 0.0, "the controller's model of beta (eq. 2)"),
        Decl("cm_bend_comp", "on/off", 1.0, "joint 2 loop adds the modeled bending moment"),
        Decl("speed_ff", "on/off", 1.0, "torque PID adds the measured output speed as feedforward"),
        Decl(
            "gain_sched", "on/off", 1.0, "torque-PID gains follow the model stiffness (else fixed)"
        ),
        Decl("tr_k0", "N*m/rad", 0.0, "controller's stiffness at its operating point, straight"),
        Decl("timestep", "s", 0.001, "physics timestep h the model was built with (the clock)"),
        Decl("steps_per_tick", "-", 1.0, "control period / timestep, a whole number >= 1"),
        Decl("rk4", "on/off", 0.0, "1 when the model integrates with RK4 (physics.control)"),
    ),
)
P_CTRL_DT, P_N_TICKS = _g["ctrl_dt"], _g["n_ticks"]
P_WN1, P_ZETA1, P_WN2, P_ZETA2, P_WN3, P_ZETA3 = (
    _g[k] for k in ("wn1", "zeta1", "wn2", "zeta2", "wn3", "zeta3")
)
P_TAU_BW, P_TAU_WI, P_TAU_KDN = _g["tau_bw"], _g["tau_wi"], _g["tau_kdn"]
P_SPD_KP, P_SPD_KI, P_OMEGA_MAX = _g["spd_kp"], _g["spd_ki"], _g["omega_max"]
P_TAU_MOT_MAX, P_TAU1_MAX, P_TAU2_MAX = _g["tau_mot_max"], _g["tau1_max"], _g["tau2_max"]
P_CM_KB, P_CM_BETA, P_CM_BEND_COMP = _g["cm_kb"], _g["cm_beta"], _g["cm_bend_comp"]
P_SPEED_FF, P_GAIN_SCHED, P_TR_K0 = _g["speed_ff"], _g["gain_sched"], _g["tr_k0"]
# the control clock (physics.control): ticks come from a step count, never from data.time alone,
# which drifts by rounding (1e-4 s after an hour at 10 us)
P_TIMESTEP, P_STEPS_PER_TICK, P_RK4 = _g["timestep"], _g["steps_per_tick"], _g["rk4"]

# setups: the arm or a bench, and the bend a bench imposes without a joint
_u = _.block(
    "setup",
    (
        Decl("setup", "id", 0.0, "0: arm, 1: series bench, 2: parallel bench (SETUP_*)"),
        Decl("bend_fixed", "rad", 0.0, "bend angle used when there is no bend joint"),
    ),
)
P_SETUP, P_BEND_FIXED = _u["setup"], _u["bend_fixed"]

# joint-3 transmission (fsarm_sim.plant.transmissions): which one, the plant's block and the
# controller's copy (virtual torque sensor, gain scheduling); the flexible shaft included
P_TRANS = _.one("transmission", "kind", "id", "transmission id (TRANSMISSION_MODULES index)")
P_TR = _.array("plant_transmission", N_TR, "per PARAMS", "the plant's transmission block")
P_TRC = _.array(
    "controller_transmission", N_TR, "per PARAMS", "the controller's model of the transmission"
)

# joint 3's controller structure (model.Gains.controller) and the parameters of its options:
# the disturbance observer's Q filter (controllers/joint3_dob.py) and the controller's own
# Maxwell-slip model of the shaft (controllers/joint3_hysteresis.py), identified from bench records
CTRL_DEFAULT = 0.0  # eq. 8 virtual sensor, speed feedforward, scheduled torque PID
CTRL_HYSTERESIS = 1.0  # the same with the hysteresis-aware torque estimate
CTRL_DOB = 2.0  # the default plus a disturbance observer on joint 3
CTRL_PAPER_PID = 3.0  # seed 000 Fig. 13 as printed: eq. 8 and the PID, no speed feedforward
_j = _.block(
    "joint3_controller",
    (
        Decl("kind", "id", 0.0, "joint-3 controller structure (CTRL_*; Gains.controller)"),
        Decl("dob_wq", "rad/s", 20.0, "disturbance observer Q-filter cut-off w_q"),
        Decl("hm_k_pos", "N*m/rad", 0.0, "hysteresis model: spring, winding side, straight"),
        Decl("hm_s_pos", "N*m/rad^2", 0.0, "hysteresis model: spring slope in |phi_B|, winding"),
        Decl("hm_k_neg", "N*m/rad", 0.0, "hysteresis model: spring, unwinding side, straight"),
        Decl("hm_s_neg", "N*m/rad^2", 0.0, "hysteresis model: spring slope, unwinding side"),
        Decl("hm_k1", "N*m/rad", 0.0, "hysteresis model: element 1 stiffness"),
        Decl("hm_k2", "N*m/rad", 0.0, "hysteresis model: element 2 stiffness"),
        Decl("hm_k3", "N*m/rad", 0.0, "hysteresis model: element 3 stiffness"),
        Decl("hm_f1", "N*m", 0.0, "hysteresis model: element 1 slip torque, straight, winding"),
        Decl("hm_f2", "N*m", 0.0, "hysteresis model: element 2 slip torque, straight, winding"),
        Decl("hm_f3", "N*m", 0.0, "hysteresis model: element 3 slip torque, straight, winding"),
        Decl("hm_rn", "-", 1.0, "hysteresis model: unwinding / winding slip torque"),
        Decl("hm_mu", "1/rad", 0.0, "hysteresis model: growth of slip torque with |phi_B|"),
    ),
)
P_CTRL_KIND, P_DOB_WQ = _j["kind"], _j["dob_wq"]
P_HM = _j["hm_k_pos"]  # first of the 12 hysteresis-model slots, in Gains.hysteresis_model order
N_HM = 12


class LawBlock(NamedTuple):
    """Where a registry arm law's numbers live: its on/off slot, the slot holding the ``data.act``
    address of its first own state (-1 while it is off or has none), its parameters' slots
    [start, end) and how many own states it has."""

    name: str
    on: int
    act: int
    start: int
    end: int
    n_states: int


def _law_block(effect: registry.Effect) -> LawBlock:
    assert effect.law is not None
    on = Decl("on", "on/off", 0.0, f"{effect.name} acts on the plant (Effects.laws)")
    act = Decl("act", "index", -1.0, f"act address of {effect.name}'s first own state")
    idx = LAYOUT.block(f"law:{effect.name}", (on, act, *effect.law.KERNEL_PARAMS))
    start, end = LAYOUT.bounds(f"law:{effect.name}")
    return LawBlock(effect.name, idx["on"], idx["act"], start + 2, end, len(effect.law.STATES))


# the registry's arm effect laws (Effect.law): one block each, an on/off slot, a state-address
# slot and then the law's KERNEL_PARAMS, in registry order; kernels.dispatch calls each law whose
# slot is on through its hooks (plant.effects.base: torques of the named state with its own
# states appended, the transmitted twist), engine.model applies its model writes
ARM_LAW_BLOCKS: tuple[LawBlock, ...] = tuple(_law_block(e) for e in registry.arm_laws())
LAW_BLOCK = {b.name: b for b in ARM_LAW_BLOCKS}

N_PARAMS = LAYOUT.size
del _, _s, _b, _c, _e, _g, _u, _j

STIFFNESS_FLOOR = 0.1  # gain scheduler: stiffness floored at this fraction of P_TR_K0

SETUP_ARM = 0.0
SETUP_SERIES_BENCH = 1.0
SETUP_PARALLEL_BENCH = 2.0

# --- data.userdata ---
U_TICK = 0  # index+1 of the last control tick processed (0: none yet)
U_MEM = 1  # controller memory (M_* below)
N_MEM = 9
U_PRE = U_MEM + N_MEM  # the same memory as it was before the current tick (a tick is re-done)
U_OUT = U_PRE + N_MEM  # held motor commands: joint 1, joint 2 (joint torque), joint-3 rotor torque
U_LOG = U_OUT + 3  # logs of the last control tick
# controller memory, ``U_MEM + M_*``
M_PID_I = 0  # torque-PID integral
M_PID_E = 1  # torque-PID previous error
M_SPD_I = 2  # speed-loop integral
M_INIT = 3  # 1 once a tick has run (the previous error and twist are valid)
M_SLIP = 4  # 3 slots: the hysteresis model's element deflections z_i, rad
M_TWIST = 7  # the twist at the previous tick (the hysteresis model's increment), rad
M_DOB = 8  # the disturbance observer's Q-filter state, N*m
L_TAU_D_JOINT = 0  # joint-3 desired joint torque, N*m
L_TAU_D_SHAFT = 1  # desired shaft torque, N*m
L_TAU_MODEL = 2  # modeled shaft torque tau_m (virtual torque sensor), N*m
L_OMEGA_D = 3  # desired shaft-input speed omega_d, rad/s
L_PID_P = 4
L_PID_I = 5
L_PID_D = 6
L_TAU_SHAFT = 7  # true shaft torque (written by the passive callback), N*m
L_TAU_BEND = 8  # total bending torque on joint 2 (elastic + conduit + coupling), N*m
L_TAU_CONDUIT = 9  # conduit (visco-elastic) part of it, N*m
N_LOG = 10
U_STEP = U_LOG + N_LOG  # index+1 of the last physics step the control clock saw (0: none yet)
U_STEP_T = U_STEP + 1  # data.time at that step's first call (anchor of the drift-free clock)
U_TICK_STEP = U_STEP + 2  # step index at which the current control tick started
U_ACC = U_STEP + 3  # run metrics, accumulated once per physics step (A_* below)
# run metrics (``U_ACC + A_*``): tracking error against the reference the controllers track,
# sampled at the start of every physics step, whatever the logging options
A_COUNT = 0  # physics steps accumulated
A_SQ_ERR = 1  # 3 slots: sum of squared tracking error of joints 1-3, rad^2
A_MAX_ERR = 4  # 3 slots: largest |tracking error| of joints 1-3, rad
A_SQ_TAU_EST = 7  # sum of squared joint-3 torque-estimate error (tau_model - tau_shaft), (N*m)^2
A_MAX_TAU_EST = 8  # its largest magnitude, N*m
A_PEAK_MOTOR_TORQUE = 9  # largest |joint-3 motor (rotor) torque command|, N*m
A_PEAK_ROTOR_SPEED = 10  # largest |rotor speed|, rad/s
A_PEAK_SHAFT_TORQUE = 11  # largest |true shaft torque|, N*m
A_PEAK_TWIST = 12  # largest |twist theta_m - theta_s|, rad
A_PEAK_TAU2 = 13  # largest |joint-2 torque command|, N*m
A_MOTOR_WORK = 14  # positive mechanical work of joint 3's motor, J (sum of max(P, 0) * h)
N_ACC = 15
U_ACC_PRE = U_ACC + N_ACC  # the accumulators as they were before the current step (re-done)
N_USERDATA_LOGGED = U_LOG + N_LOG  # what a run records per row (memory, outputs, logs)
# the run recorder (physics.record_row): the control kernel writes a row every U_REC_STRIDE
# physics steps into a buffer at the end of userdata - the time, qpos, qvel, act and the first
# N_USERDATA_LOGGED userdata values, at the step's true state - and Simulation drains it between
# chunks of steps, so no Python runs per recorded row
U_REC_STRIDE = U_ACC_PRE + N_ACC  # physics steps between rows; 0: recording off
U_REC_NEXT = U_REC_STRIDE + 1  # step index of the next row to record
U_REC_LAST = U_REC_STRIDE + 2  # step index of the last row written (-1: none since the drain)
U_REC_ROWS = U_REC_STRIDE + 3  # rows in the buffer since the last drain
U_REC_CAP = U_REC_STRIDE + 4  # rows the buffer holds
U_REC_LOST = U_REC_STRIDE + 5  # rows that found the buffer full (Simulation raises if > 0)
U_REC_BUF = U_REC_STRIDE + 6  # the buffer: U_REC_CAP rows of rec_width(nq, nv, na) values
N_USERDATA = U_REC_BUF  # userdata of a model without a recording buffer (the kernels' minimum)
REC_ROWS_DEFAULT = 2048  # buffer rows of a model built by engine.model (about 1 MB on the arm)


def rec_width(nq: int, nv: int, na: int) -> int:
    """Values per recorded row: time, qpos, qvel, act, the logged userdata."""
    return 1 + nq + nv + na + N_USERDATA_LOGGED
