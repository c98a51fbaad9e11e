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

PARAMS_NAME = "fsarm_params"
REF_NAME = "fsarm_ref"
MAGIC = 7013.0  # first parameter; marks an fsarm model so callbacks ignore foreign models
REF_COLS = 9

# --- structure (read from the compiled MJCF, never typed twice) ---
# A qpos/dof index of -1 means "absent" (bench models): its angle and rate read as 0 (for the
# bend joint: P_BEND_FIXED) and no force is applied to it.
P_MAGIC = 0
P_QADR_Q1 = 1
P_QADR_Q2 = 2
P_QADR_Q3 = 3
P_QADR_ROT = 4
P_DOF_Q1 = 5
P_DOF_Q2 = 6
P_DOF_Q3 = 7
P_DOF_ROT = 8
P_COEF_M = 9  # theta_m = COEF_M * rotor angle   (1 / i_G1)
P_COEF_S = 10  # theta_s = COEF_S * q3           (i_G2)
P_ACT_BR1 = 11
P_ACT_BR2 = 12
P_ACT_SLIP1 = 13  # three consecutive slip elements (other transmissions: their state slots)
P_CTRL_J1 = 14
P_CTRL_J2 = 15
P_CTRL_J3 = 16
P_MADR_Q1 = 17  # index of the diagonal of the joint-space inertia in data.M (CSR)
P_MADR_Q2 = 18
P_MADR_Q3 = 19
# --- the shaft's parallel (bending) side; its series side is the transmission block P_TR ---
# (slots 20-25, 32-34, 38 and 58-61 held the flexible shaft's own copy before 0.3.0: free)
P_KB = 26
P_BETA = 27
P_BR_K1 = 28
P_BR_TAU1 = 29
P_BR_K2 = 30
P_BR_TAU2 = 31
# --- effect switches (1.0 on, 0.0 off) ---
P_EN_SERIES = 35
P_EN_BEND = 36
P_EN_CONDUIT = 37
P_EN_COUPLING = 39
P_EN_CONTROL = 40
# --- control ---
P_CTRL_DT = 41
P_N_TICKS = 42
P_WN1 = 43
P_ZETA1 = 44
P_WN2 = 45
P_ZETA2 = 46
P_WN3 = 47
P_ZETA3 = 48
P_TAU_BW = 49  # torque PID: loop bandwidth w_t, rad/s (gains scheduled on eq. 8 stiffness)
P_TAU_WI = 50  # integral corner w_i, rad/s
P_TAU_KDN = 51  # normalized derivative gain (dimensionless)
P_SPD_KP = 52  # EPOS-like speed loop, motor side: N*m per rad/s
P_SPD_KI = 53
P_OMEGA_MAX = 54  # motor speed limit, rad/s (motor side)
P_TAU_MOT_MAX = 55  # motor torque (current) limit, N*m (motor side)
P_TAU1_MAX = 56
P_TAU2_MAX = 57
P_CM_KB = 62  # the controller's model of the bending moment (eq. 4); its shaft model is P_TRC
P_CM_BETA = 63
P_CM_BEND_COMP = 64  # 1: joint-2 controller adds the modeled elastic bending moment
P_SPEED_FF = 65  # 1: torque PID adds the measured shaft-output speed as feedforward
P_BEND_FIXED = 66  # bend angle used when there is no bend joint (P_QADR_Q2 < 0), rad
P_SETUP = 67  # 0: arm, 1: series bench, 2: parallel bench
P_RK4 = 68  # 1 when the model integrates with RK4 (see physics.control)
# --- joint-3 transmission (fsarm_sim.transmissions): which one, the plant's parameter block and
# the controller's copy (virtual torque sensor, gain scheduling); the flexible shaft (kind 0)
# included, like every other.
P_TRANS = 69
P_TR = 70  # N_TR consecutive parameters (transmissions.base.N_TR)
P_TRC = 94  # N_TR consecutive parameters: the controller's model of the transmission
P_TR_K0 = 118  # controller's stiffness at zero twist, straight (floor of the gain scheduler)
# --- arm effects the discrepancy workflow can switch on (0: off) ---
P_PAY_DM = 119  # payload mass error, kg: the plant carries it, the controllers do not know it
P_PAY_L2 = 120  # joint 2 -> joint 3 distance, m (from the compiled MJCF)
P_PAY_L3 = 121  # joint 3 -> payload centre of mass, m (from the compiled MJCF)
P_GRAVITY = 122  # |g|, m/s^2 (from the compiled MJCF)
P_BL_WIDTH = 123  # backlash (dead band) on the transmission twist, total width, rad
P_BL_CENTER = 124  # middle of the dead band, rad
P_GAIN_SCHED = 125  # 1: torque-PID gains scheduled on the model stiffness; 0: fixed at P_TR_K0
# --- the control clock (physics.control): ticks come from a step count, never from data.time
# alone, which drifts by rounding (1e-4 s after an hour at 10 us); see physics.control ---
P_TIMESTEP = 126  # physics timestep h the model was built with, s
P_STEPS_PER_TICK = 127  # control period / timestep (a whole number >= 1)
N_PARAMS = 128
N_TR = 24

TR_FLEXIBLE_SHAFT = 0.0
TR_RTCA = 1.0
TR_QA_JOINT = 2.0
TR_MAGNETIC_SPRING = 3.0
TR_TENDON_SHEATH = 4.0
STIFFNESS_FLOOR = 0.1  # gain scheduler: stiffness floored at this fraction of P_TR_K0

SETUP_ARM = 0.0
SETUP_SERIES_BENCH = 1.0
SETUP_PARALLEL_BENCH = 2.0

# --- data.userdata ---
U_TICK = 0  # index+1 of the last control tick processed (0: none yet)
U_MEM = 1  # controller memory: torque-PID integral, previous error, speed-loop integral, init
U_PRE = 5  # the same memory as it was before the current tick (a tick is re-done from here)
N_MEM = 4
U_OUT = 9  # held motor commands: joint 1, joint 2 (joint torque), joint-3 motor (rotor torque)
U_LOG = 12  # logs of the last control tick
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
N_USERDATA = U_ACC_PRE + N_ACC
N_USERDATA_LOGGED = U_LOG + N_LOG  # what a run records per row (memory, outputs, logs)
