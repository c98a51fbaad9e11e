"""Array kernels the callbacks run: shaft forces, state rates, and the control tick.

Each kernel takes the parameter vector (``layout.P_*``), MuJoCo's state arrays and output arrays;
no MuJoCo objects, no Python objects. The Python callbacks (:mod:`fsarm_sim.engine.callbacks`) call them
as they are; the native path compiles the very same functions with Numba.

Where the shaft's reaction torques land: the twist is the fixed tendon
``theta_m - theta_s = rotor / i_G1 - i_G2 q3``; its torque enters as generalized forces on the
rotor joint (``-tau / i_G1``; a capstan law's own motor-end torque there, ``tr_motor_torque``) and
on q3 (``+i_G2 tau``) and nowhere else. Joint-space forces are
internal between a joint's parent and child bodies, so the reaction of the motor/gearbox acts on
link 1 (the rotor's parent) and the reaction of the hypoid acts on link 2 (q3's parent): the
world sees no torque from the shaft, which ``tests/test_physics.py`` checks through conservation
of angular momentum about joint 1's axis.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from fsarm_sim.controllers.joint3_dob import disturbance, observer_input, observer_step
from fsarm_sim.controllers.joint3_hysteresis import bend_factor, element_step, spring_torque
from fsarm_sim.controllers.joint3_torque import scheduled_gains, speed_loop, torque_pid
from fsarm_sim.controllers.joint_position import clamp, computed_torque
from fsarm_sim.controllers.tendon_sheath_compliance import (
    MOTOR_POSITION_GAIN_RAD_S,
    motor_speed_command,
    position_command,
)
from fsarm_sim.kernels.dispatch import (
    arm_law_owns,
    arm_law_state_rate,
    arm_law_torques,
    arm_law_twist,
    arm_laws_on,
    tr_bend_torque,
    tr_has_motor_torque,
    tr_motor_torque,
    tr_output_torque,
    tr_potential,
    tr_sensor_torque,
    tr_state_rate,
    tr_stiffness,
    tr_torque,
)
from fsarm_sim.kernels.layout import (
    A_COUNT,
    A_MAX_ERR,
    A_MAX_TAU_EST,
    A_MOTOR_WORK,
    A_PEAK_MOTOR_TORQUE,
    A_PEAK_ROTOR_SPEED,
    A_PEAK_SHAFT_TORQUE,
    A_PEAK_TAU2,
    A_PEAK_TWIST,
    A_SQ_ERR,
    A_SQ_TAU_EST,
    CTRL_DOB,
    CTRL_HYSTERESIS,
    L_OMEGA_D,
    L_PID_D,
    L_PID_I,
    L_PID_P,
    L_TAU_BEND,
    L_TAU_CONDUIT,
    L_TAU_D_JOINT,
    L_TAU_D_SHAFT,
    L_TAU_MODEL,
    L_TAU_SHAFT,
    M_DOB,
    M_INIT,
    M_PID_E,
    M_PID_I,
    M_SLIP,
    M_SPD_I,
    M_TWIST,
    N_ACC,
    N_MEM,
    N_TR,
    N_USERDATA_LOGGED,
    P_ACT_BR1,
    P_ACT_BR2,
    P_ACT_SLIP1,
    P_BEND_FIXED,
    P_BETA,
    P_BR_K1,
    P_BR_K2,
    P_BR_TAU1,
    P_BR_TAU2,
    P_CM_BEND_COMP,
    P_CM_BETA,
    P_CM_KB,
    P_COEF_M,
    P_COEF_S,
    P_CTRL_DT,
    P_CTRL_J1,
    P_CTRL_J2,
    P_CTRL_J3,
    P_CTRL_KIND,
    P_DOB_WQ,
    P_DOF_Q1,
    P_DOF_Q2,
    P_DOF_Q3,
    P_DOF_ROT,
    P_EN_BEND,
    P_EN_CONDUIT,
    P_EN_CONTROL,
    P_EN_COUPLING,
    P_EN_SERIES,
    P_GAIN_SCHED,
    P_HM,
    P_KB,
    P_MADR_Q1,
    P_MADR_Q2,
    P_MADR_Q3,
    P_N_TICKS,
    P_OMEGA_MAX,
    P_QADR_Q1,
    P_QADR_Q2,
    P_QADR_Q3,
    P_QADR_ROT,
    P_RK4,
    P_SPD_KI,
    P_SPD_KP,
    P_SPEED_FF,
    P_STEPS_PER_TICK,
    P_TAU1_MAX,
    P_TAU2_MAX,
    P_TAU_BW,
    P_TAU_KDN,
    P_TAU_MOT_MAX,
    P_TAU_WI,
    P_TIMESTEP,
    P_TR,
    P_TR_K0,
    P_TRANS,
    P_TRC,
    P_WN1,
    P_WN2,
    P_WN3,
    P_ZETA1,
    P_ZETA2,
    P_ZETA3,
    REF_COLS,
    STIFFNESS_FLOOR,
    TR_TENDON_SHEATH,
    U_ACC,
    U_ACC_PRE,
    U_LOG,
    U_MEM,
    U_OUT,
    U_PRE,
    U_REC_BUF,
    U_REC_CAP,
    U_REC_LAST,
    U_REC_LOST,
    U_REC_NEXT,
    U_REC_ROWS,
    U_REC_STRIDE,
    U_STEP,
    U_STEP_T,
    U_TICK,
    U_TICK_STEP,
    rec_width,
)
from fsarm_sim.plant.effects import (
    bending,
    conduit_viscoelastic,
)
from fsarm_sim.plant.effects.base import State

FloatArray = npt.NDArray[np.float64]
# A call is "at" a physics step when its time is within this fraction of a timestep of the step's
# time: RK4's half-step stages (h/2 away) are never steps, while rounding of data.time (about
# 1e-16 * t per step) stays far below it.
STEP_TOLERANCE = 0.25


def coord(x: FloatArray, index: float) -> float:
    """x[index], or 0 for an absent joint (index -1)."""
    i = int(index)
    return x[i] if i >= 0 else 0.0


def bend_angle(prm: FloatArray, qpos: FloatArray) -> float:
    """phi_B: the joint-2 angle on the arm, the held bend angle on a series bench."""
    i = int(prm[P_QADR_Q2])
    return qpos[i] if i >= 0 else prm[P_BEND_FIXED]


def add_force(qfrc: FloatArray, index: float, value: float) -> None:
    """qfrc[index] += value, unless the joint is absent."""
    i = int(index)
    if i >= 0:
        qfrc[i] += value


def twist_angle(prm: FloatArray, qpos: FloatArray) -> float:
    """Shaft twist theta_m - theta_s (rad), from the tendon coefficients."""
    return prm[P_COEF_M] * coord(qpos, prm[P_QADR_ROT]) - prm[P_COEF_S] * coord(
        qpos, prm[P_QADR_Q3]
    )


def twist_and_rate(prm: FloatArray, qpos: FloatArray, qvel: FloatArray) -> tuple[float, float]:
    """Shaft twist (rad) and its rate (rad/s)."""
    rate = prm[P_COEF_M] * coord(qvel, prm[P_DOF_ROT]) - prm[P_COEF_S] * coord(qvel, prm[P_DOF_Q3])
    return twist_angle(prm, qpos), rate


def transmission_input(
    prm: FloatArray, twist: float, rate: float
) -> tuple[float, float, FloatArray, int]:
    """(twist, rate) reaching the transmission's law (through the registry's twist laws that are
    on, e.g. a backlash: ``arm_law_twist``), its block and its first state slot."""
    x, xd = arm_law_twist(prm, twist, rate)
    return x, xd, prm[P_TR : P_TR + N_TR], int(prm[P_ACT_SLIP1])


def shaft_torque(prm: FloatArray, qpos: FloatArray, qvel: FloatArray, act: FloatArray) -> float:
    """True torque carried by joint 3's transmission (N*m), at the joint end.

    Flexible shaft (default): eq. 8 + eq. 1 damping + Maxwell-slip elements. Any other
    transmission: its own law (:mod:`fsarm_sim.plant.transmissions`).
    """
    if prm[P_EN_SERIES] < 0.5:
        return 0.0
    twist, rate = twist_and_rate(prm, qpos, qvel)
    x, xd, tr, a0 = transmission_input(prm, twist, rate)
    return tr_torque(prm[P_TRANS], tr, x, xd, bend_angle(prm, qpos), act, a0)


def bend_coupling_torque_at(prm: FloatArray, x: float, bend: float, act: FloatArray) -> float:
    """-dV/dphi_B on joint 2, V the transmission's stored energy (its ``potential_j``).

    ``x``: the twist reaching the transmission's law (through the registry's twist laws that are
    on: :func:`transmission_input`); ``bend``: :func:`bend_angle`. They are passed in because the
    passive kernel has computed both already; :func:`bend_coupling_torque` computes them from
    ``qpos``. A transmission routed over joint 2 whose law depends on the bend stores energy that
    changes when joint 2 moves at constant twist; this torque is its reaction, so the arm conserves
    energy (tests/test_energy_check.py, ``fsarm check-dynamics``). Every transmission states it
    through the interface (``bend_torque_nm``; tests check it against the derivative of
    ``potential_j``).
    """
    return tr_bend_torque(
        prm[P_TRANS],
        prm[P_TR : P_TR + N_TR],
        x,
        bend,
        act,
        int(prm[P_ACT_SLIP1]),
    )


def transmitted_twist_angle(prm: FloatArray, qpos: FloatArray) -> float:
    """Twist reaching the transmission's law (rad): :func:`twist_angle` through the registry's
    twist laws that are on (the angle half of :func:`transmission_input`)."""
    x, _ = arm_law_twist(prm, twist_angle(prm, qpos), 0.0)
    return x


def bend_coupling_torque(prm: FloatArray, qpos: FloatArray, act: FloatArray) -> float:
    """:func:`bend_coupling_torque_at` from the state: computes the transmitted twist and the bend
    from ``qpos`` (for callers outside the passive kernel, e.g. energy bookkeeping)."""
    return bend_coupling_torque_at(
        prm, transmitted_twist_angle(prm, qpos), bend_angle(prm, qpos), act
    )


def bending_torques_at(
    prm: FloatArray, x: float, bend: float, act: FloatArray
) -> tuple[float, float]:
    """(total, conduit part) of the torque the bent shaft puts on joint 2 (N*m).

    ``x``: the transmitted twist (read only when the series transmission and its bend coupling
    are on); ``bend``: :func:`bend_angle`. The passive kernel passes the values it has already
    computed; :func:`bending_torques` computes them from the state.
    """
    total = 0.0
    conduit = 0.0
    if prm[P_EN_BEND] > 0.5:
        total -= bending.elastic_moment_nm(bend, prm[P_KB], prm[P_BETA])
    if prm[P_EN_CONDUIT] > 0.5:
        conduit -= conduit_viscoelastic.branch_moment_nm(
            bend, act[int(prm[P_ACT_BR1])], prm[P_BR_K1]
        )
        conduit -= conduit_viscoelastic.branch_moment_nm(
            bend, act[int(prm[P_ACT_BR2])], prm[P_BR_K2]
        )
        total += conduit
    if prm[P_EN_SERIES] > 0.5 and prm[P_EN_COUPLING] > 0.5:
        total += bend_coupling_torque_at(prm, x, bend, act)
    return total, conduit


def bending_torques(
    prm: FloatArray, qpos: FloatArray, qvel: FloatArray, act: FloatArray
) -> tuple[float, float]:
    """(total, conduit part) of the torque the bent shaft puts on joint 2 (N*m), from the state
    (:func:`bending_torques_at`; ``qvel`` is unused and kept for callers' signature)."""
    return bending_torques_at(prm, transmitted_twist_angle(prm, qpos), bend_angle(prm, qpos), act)


def law_state(
    prm: FloatArray,
    qpos: FloatArray,
    qvel: FloatArray,
    ud: FloatArray,
    twist: float,
    rate: float,
    bend: float,
) -> State:
    """The named state the registry's arm laws read (``plant.effects.base.STATE``, in order);
    ``twist``, ``rate`` and ``bend`` as the caller computed them (:func:`twist_and_rate`,
    :func:`bend_angle`)."""
    cm = prm[P_COEF_M]
    return (
        coord(qpos, prm[P_QADR_Q2]),
        coord(qpos, prm[P_QADR_Q3]),
        coord(qvel, prm[P_DOF_Q2]),
        coord(qvel, prm[P_DOF_Q3]),
        cm * coord(qpos, prm[P_QADR_ROT]),
        cm * coord(qvel, prm[P_DOF_ROT]),
        twist,
        rate,
        bend,
        ud[U_OUT + 2],
        cm,
        prm[P_TIMESTEP],
    )


def passive_forces(
    prm: FloatArray,
    qpos: FloatArray,
    qvel: FloatArray,
    act: FloatArray,
    qfrc: FloatArray,
    ud: FloatArray,
) -> None:
    """mjcb_passive body: *add* the shaft's generalized forces to ``qfrc`` (qfrc_passive).

    ``ud``: the data's userdata (the laws read the held motor command there; the shaft's torques
    are logged at ``U_LOG``)."""
    # twist, rate and bend once per call: the transmission and the arm laws read them
    twist, rate = twist_and_rate(prm, qpos, qvel)
    bend = bend_angle(prm, qpos)
    tau = 0.0  # joint end
    tau_m = 0.0  # motor end: the same unless the law gives its ends their own torques
    x = twist  # the transmitted twist once the series transmission is on (read only then)
    if prm[P_EN_SERIES] > 0.5:
        kind = prm[P_TRANS]
        x, xd, tr, a0 = transmission_input(prm, twist, rate)
        tau = tr_torque(kind, tr, x, xd, bend, act, a0)
        tau_m = (
            tr_motor_torque(kind, tr, x, xd, bend, act, a0) if tr_has_motor_torque(kind) else tau
        )
    add_force(qfrc, prm[P_DOF_ROT], -prm[P_COEF_M] * tau_m)
    add_force(qfrc, prm[P_DOF_Q3], prm[P_COEF_S] * tau)
    cs = prm[P_COEF_S]
    q3 = coord(qpos, prm[P_QADR_Q3])
    qd3 = coord(qvel, prm[P_DOF_Q3])
    # the transmission's own torque against the frame on its output side (0 for most)
    add_force(
        qfrc,
        prm[P_DOF_Q3],
        cs * tr_output_torque(prm[P_TRANS], prm[P_TR : P_TR + N_TR], cs * q3, cs * qd3),
    )
    total, conduit = bending_torques_at(prm, x, bend, act)
    add_force(qfrc, prm[P_DOF_Q2], total)
    # the registry's arm effect laws that are switched on (kernels.dispatch, generated), called
    # with the named state, which is built only then
    t2, t3, tm = 0.0, 0.0, 0.0
    if arm_laws_on(prm):
        t2, t3, tm = arm_law_torques(prm, act, law_state(prm, qpos, qvel, ud, twist, rate, bend))
    add_force(qfrc, prm[P_DOF_Q2], t2)
    add_force(qfrc, prm[P_DOF_Q3], t3)
    add_force(qfrc, prm[P_DOF_ROT], prm[P_COEF_M] * tm)
    ud[U_LOG + L_TAU_SHAFT] = tau
    ud[U_LOG + L_TAU_BEND] = total
    ud[U_LOG + L_TAU_CONDUIT] = conduit


def state_rate(
    prm: FloatArray,
    qpos: FloatArray,
    qvel: FloatArray,
    act: FloatArray,
    act_adr: int,
    ud: FloatArray,
) -> float:
    """mjcb_act_dyn body: d(act[act_adr])/dt for the internal states (``ud``: the userdata)."""
    bend = bend_angle(prm, qpos)
    if act_adr == int(prm[P_ACT_BR1]):
        return conduit_viscoelastic.branch_rate(bend, act[act_adr], prm[P_BR_TAU1])
    if act_adr == int(prm[P_ACT_BR2]):
        return conduit_viscoelastic.branch_rate(bend, act[act_adr], prm[P_BR_TAU2])
    twist, rate = twist_and_rate(prm, qpos, qvel)
    if arm_law_owns(prm, act_adr):  # a registry law's own state
        s = law_state(prm, qpos, qvel, ud, twist, rate, bend)
        return arm_law_state_rate(prm, act, s, act_adr)
    twist, rate = arm_law_twist(prm, twist, rate)
    a0 = int(prm[P_ACT_SLIP1])
    vm = prm[P_COEF_M] * coord(qvel, prm[P_DOF_ROT])  # motor-side speed: a tendon's sliding
    return tr_state_rate(
        prm[P_TRANS], prm[P_TR : P_TR + N_TR], twist, rate, bend, act, a0, act_adr - a0, vm
    )


def shaft_potential(prm: FloatArray, qpos: FloatArray, act: FloatArray) -> float:
    """Energy stored in the enabled shaft elements (J), for energy bookkeeping."""
    twist = transmitted_twist_angle(prm, qpos)
    bend = bend_angle(prm, qpos)
    v = 0.0
    if prm[P_EN_SERIES] > 0.5:
        v += tr_potential(
            prm[P_TRANS], prm[P_TR : P_TR + N_TR], twist, bend, act, int(prm[P_ACT_SLIP1])
        )
    if prm[P_EN_BEND] > 0.5:
        v += bending.potential_j(bend, prm[P_KB], prm[P_BETA])
    if prm[P_EN_CONDUIT] > 0.5:
        v += conduit_viscoelastic.branch_potential_j(bend, act[int(prm[P_ACT_BR1])], prm[P_BR_K1])
        v += conduit_viscoelastic.branch_potential_j(bend, act[int(prm[P_ACT_BR2])], prm[P_BR_K2])
    return v


def arm_joint_commands(
    prm: FloatArray,
    ref: FloatArray,
    row: int,
    qpos: FloatArray,
    qvel: FloatArray,
    bias: FloatArray,
    mass: FloatArray,
    out: FloatArray,
) -> None:
    """Joints 1 and 2: computed-torque position loops (joint 2 with the bending moment's
    compensation when on) into ``out[0]``, ``out[1]``."""
    q2 = qpos[int(prm[P_QADR_Q2])]
    dof1 = int(prm[P_DOF_Q1])
    dof2 = int(prm[P_DOF_Q2])
    tau1 = computed_torque(
        qpos[int(prm[P_QADR_Q1])],
        qvel[dof1],
        ref[row],
        ref[row + 3],
        ref[row + 6],
        mass[int(prm[P_MADR_Q1])],
        bias[dof1],
        prm[P_WN1],
        prm[P_ZETA1],
    )
    tau2 = computed_torque(
        q2,
        qvel[dof2],
        ref[row + 1],
        ref[row + 4],
        ref[row + 7],
        mass[int(prm[P_MADR_Q2])],
        bias[dof2],
        prm[P_WN2],
        prm[P_ZETA2],
    )
    if prm[P_CM_BEND_COMP] > 0.5:
        tau2 += bending.elastic_moment_nm(q2, prm[P_CM_KB], prm[P_CM_BETA])
    out[0] = clamp(tau1, prm[P_TAU1_MAX])
    out[1] = clamp(tau2, prm[P_TAU2_MAX])


def observer_torque(
    prm: FloatArray,
    bias: FloatArray,
    mass: FloatArray,
    qd3: float,
    tau_m: float,
    mem_in: FloatArray,
    mem_out: FloatArray,
) -> float:
    """The disturbance observer (controllers/joint3_dob.py): the lumped disturbance that joins
    the desired joint torque (none on the first tick), its filter advanced into ``mem_out``."""
    dof3 = int(prm[P_DOF_Q3])
    cs = prm[P_COEF_S]
    m33 = mass[int(prm[P_MADR_Q3])]
    wq = prm[P_DOB_WQ]
    y = mem_in[M_DOB]
    d = disturbance(y, m33, qd3, wq) if mem_in[M_INIT] > 0.5 else 0.0
    u = observer_input(cs * tau_m, bias[dof3], m33, qd3, wq)
    if mem_in[M_INIT] < 0.5:  # first tick: start the filter at its input (no disturbance)
        y = u
    mem_out[M_DOB] = observer_step(y, u, wq, prm[P_CTRL_DT])
    return d


def shaft_speed_command(
    prm: FloatArray,
    ref: FloatArray,
    row: int,
    qd3: float,
    theta_m: float,
    theta_s: float,
    q2: float,
    tau_d: float,
    tau_m: float,
    mem_in: FloatArray,
) -> tuple[float, float, float, float, float, float]:
    """Joint 3's shaft-speed command from the desired shaft torque: (omega_d, PID integral,
    error, P, I, D terms) of the torque PID with gains scheduled on the model's stiffness, or
    of seed 004's dual-encoder position loop with the tendon-sheath transmission."""
    dt = prm[P_CTRL_DT]
    cm = prm[P_COEF_M]
    cs = prm[P_COEF_S]
    trc = prm[P_TRC : P_TRC + N_TR]
    k_model = max(
        tr_stiffness(prm[P_TRANS], trc, theta_m - theta_s, q2), STIFFNESS_FLOOR * prm[P_TR_K0]
    )
    omega_ff = cs * qd3 if prm[P_SPEED_FF] > 0.5 else 0.0
    omega_max_shaft = prm[P_OMEGA_MAX] * cm
    if prm[P_GAIN_SCHED] < 0.5:  # fixed gains, tuned at zero twist, straight (seed 001's PID)
        k_model = prm[P_TR_K0]
    kp, ki, kd = scheduled_gains(prm[P_TAU_BW], prm[P_TAU_WI], prm[P_TAU_KDN], k_model)
    if prm[P_TRANS] == TR_TENDON_SHEATH:
        # seed 004's dual-encoder position control (controllers/tendon_sheath_compliance.py)
        theta_c = position_command(cs * ref[row + 2], tau_d, k_model)
        omega_d = motor_speed_command(
            theta_c, theta_m, cs * ref[row + 5], MOTOR_POSITION_GAIN_RAD_S, omega_max_shaft
        )
        integ, err, p_term, i_term, d_term = 0.0, theta_c - theta_m, 0.0, 0.0, 0.0
    else:
        omega_d, integ, err, p_term, i_term, d_term = torque_pid(
            tau_d,
            tau_m,
            mem_in[M_PID_I],
            mem_in[M_PID_E],
            mem_in[M_INIT],
            dt,
            kp,
            ki,
            kd,
            omega_ff,
            omega_max_shaft,
        )
    return omega_d, integ, err, p_term, i_term, d_term


def torque_estimate(
    prm: FloatArray, x: float, bend: float, mem_in: FloatArray, mem_out: FloatArray
) -> float:
    """Joint 3's virtual torque sensor at twist ``x`` and bend ``bend``: the controller's copy of
    the transmission's law (eq. 8 for the shaft) or the hysteresis model
    (:func:`hysteresis_estimate`), as ``P_CTRL_KIND`` says."""
    if prm[P_CTRL_KIND] == CTRL_HYSTERESIS:
        return hysteresis_estimate(prm, x, bend, mem_in, mem_out)
    return tr_sensor_torque(prm[P_TRANS], prm[P_TRC : P_TRC + N_TR], x, bend)


def control_tick(
    prm: FloatArray,
    ref: FloatArray,
    k: int,
    qpos: FloatArray,
    qvel: FloatArray,
    bias: FloatArray,
    mass: FloatArray,
    mem_in: FloatArray,
    mem_out: FloatArray,
    out: FloatArray,
    log: FloatArray,
) -> None:
    """One control tick: joints 1-2 position loops, joint-3 cascade of Fig. 13 (with the
    tendon-sheath transmission: seed 004's dual-encoder position loop in place of the torque PID).

    Joint 3's controller structure is ``P_CTRL_KIND`` (``model.Gains.controller``): the torque
    estimate is eq. 8 or the hysteresis model (:func:`hysteresis_estimate`), and the disturbance
    observer, when on, adds its estimate to the desired joint torque.

    Reads memory ``mem_in`` (``layout.M_*``: torque-PID integral and previous error, speed-loop
    integral, init flag, the hysteresis model's elements and last twist, the observer's filter),
    writes ``mem_out``, motor commands ``out`` (joint-1 torque, joint-2 torque, joint-3 rotor torque)
    and ``log``.
    """
    row = min(k, int(prm[P_N_TICKS]) - 1) * REF_COLS
    dt = prm[P_CTRL_DT]
    cm = prm[P_COEF_M]
    cs = prm[P_COEF_S]
    q2 = qpos[int(prm[P_QADR_Q2])]
    q3 = qpos[int(prm[P_QADR_Q3])]
    dof3 = int(prm[P_DOF_Q3])
    arm_joint_commands(prm, ref, row, qpos, qvel, bias, mass, out)
    # joint 3, outer loop: desired joint torque -> desired shaft torque
    tau_d_joint = computed_torque(
        q3,
        qvel[dof3],
        ref[row + 2],
        ref[row + 5],
        ref[row + 8],
        mass[int(prm[P_MADR_Q3])],
        bias[dof3],
        prm[P_WN3],
        prm[P_ZETA3],
    )
    # virtual torque sensor: eq. 8 on the two encoders and the joint-2 encoder
    theta_m = cm * qpos[int(prm[P_QADR_ROT])]
    theta_s = cs * q3
    tau_m = torque_estimate(prm, theta_m - theta_s, q2, mem_in, mem_out)
    if prm[P_CTRL_KIND] == CTRL_DOB:
        tau_d_joint += observer_torque(prm, bias, mass, qvel[dof3], tau_m, mem_in, mem_out)
    tau_d = tau_d_joint / cs
    omega_d, integ, err, p_term, i_term, d_term = shaft_speed_command(
        prm, ref, row, qvel[dof3], theta_m, theta_s, q2, tau_d, tau_m, mem_in
    )
    omega_motor = qvel[int(prm[P_DOF_ROT])]
    tau_mot, s_integ = speed_loop(
        omega_d / cm,
        omega_motor,
        mem_in[M_SPD_I],
        dt,
        prm[P_SPD_KP],
        prm[P_SPD_KI],
        prm[P_TAU_MOT_MAX],
    )
    out[2] = tau_mot
    mem_out[M_PID_I] = integ
    mem_out[M_PID_E] = err
    mem_out[M_SPD_I] = s_integ
    mem_out[M_INIT] = 1.0
    log[L_TAU_D_JOINT] = tau_d_joint
    log[L_TAU_D_SHAFT] = tau_d
    log[L_TAU_MODEL] = tau_m
    log[L_OMEGA_D] = omega_d
    log[L_PID_P] = p_term
    log[L_PID_I] = i_term
    log[L_PID_D] = d_term


def hysteresis_estimate(
    prm: FloatArray, x: float, bend: float, mem_in: FloatArray, mem_out: FloatArray
) -> float:
    """The hysteresis-aware virtual torque sensor (controllers/joint3_hysteresis.py) at twist
    ``x`` and bend ``bend``: advances the model's elements from ``mem_in`` into ``mem_out`` by the
    twist increment since the last tick (none on the first) and returns the model's torque."""
    h = P_HM
    dx = x - mem_in[M_TWIST] if mem_in[M_INIT] > 0.5 else 0.0
    g = bend_factor(bend, prm[h + 11])
    tau = spring_torque(x, bend, prm[h], prm[h + 1], prm[h + 2], prm[h + 3])
    for i in range(3):
        z = element_step(mem_in[M_SLIP + i], dx, prm[h + 4 + i], prm[h + 7 + i], prm[h + 10], g)
        mem_out[M_SLIP + i] = z
        tau += prm[h + 4 + i] * z
    mem_out[M_TWIST] = x
    return tau


def accumulate_metrics(
    prm: FloatArray,
    ref: FloatArray,
    k: int,
    qpos: FloatArray,
    qvel: FloatArray,
    pre: FloatArray,
    acc: FloatArray,
    out: FloatArray,
    log: FloatArray,
) -> None:
    """Run metrics of one physics step: ``acc`` = ``pre`` + this step's sample.

    Sampled at the start of every step (the state the step integrates from) against the reference
    row of the current control tick ``k`` (the reference the controllers track); the torque
    estimate and motor commands are the ones held over the step. Independent of any logging.
    """
    row = min(k, int(prm[P_N_TICKS]) - 1) * REF_COLS
    acc[A_COUNT] = pre[A_COUNT] + 1.0
    for j in range(3):
        i = int(prm[P_QADR_Q1 + j])
        e = qpos[i] - ref[row + j] if i >= 0 else 0.0
        acc[A_SQ_ERR + j] = pre[A_SQ_ERR + j] + e * e
        acc[A_MAX_ERR + j] = max(pre[A_MAX_ERR + j], abs(e))
    te = log[L_TAU_MODEL] - log[L_TAU_SHAFT]
    acc[A_SQ_TAU_EST] = pre[A_SQ_TAU_EST] + te * te
    acc[A_MAX_TAU_EST] = max(pre[A_MAX_TAU_EST], abs(te))
    omega_rotor = coord(qvel, prm[P_DOF_ROT])
    tau_motor = out[2]
    acc[A_PEAK_MOTOR_TORQUE] = max(pre[A_PEAK_MOTOR_TORQUE], abs(tau_motor))
    acc[A_PEAK_ROTOR_SPEED] = max(pre[A_PEAK_ROTOR_SPEED], abs(omega_rotor))
    acc[A_PEAK_SHAFT_TORQUE] = max(pre[A_PEAK_SHAFT_TORQUE], abs(log[L_TAU_SHAFT]))
    acc[A_PEAK_TWIST] = max(pre[A_PEAK_TWIST], abs(twist_angle(prm, qpos)))
    acc[A_PEAK_TAU2] = max(pre[A_PEAK_TAU2], abs(out[1]))
    acc[A_MOTOR_WORK] = pre[A_MOTOR_WORK] + max(tau_motor * omega_rotor, 0.0) * prm[P_TIMESTEP]


def record_row(
    s: float, time: float, qpos: FloatArray, qvel: FloatArray, act: FloatArray, ud: FloatArray
) -> None:
    """The run recorder: at a recorded step (every ``U_REC_STRIDE`` steps from ``U_REC_NEXT``)
    write the row time, qpos, qvel, act, ``ud[:N_USERDATA_LOGGED]`` into the buffer; a later call
    at the same step (the step's own forward after a predicted one, extra forwards) overwrites
    its row, so the row holds the step's true state and the outputs computed from it."""
    stride = ud[U_REC_STRIDE]
    if stride <= 0.0:
        return
    rows = int(ud[U_REC_ROWS])
    if s == ud[U_REC_LAST] and rows > 0:
        row = rows - 1
    elif s == ud[U_REC_NEXT]:
        if rows >= int(ud[U_REC_CAP]):
            ud[U_REC_LOST] += 1.0
            return
        row = rows
        ud[U_REC_ROWS] = rows + 1.0
        ud[U_REC_LAST] = s
        ud[U_REC_NEXT] = s + stride
    else:
        return
    nq = qpos.shape[0]
    nv = qvel.shape[0]
    na = act.shape[0]
    w = rec_width(nq, nv, na)
    at = U_REC_BUF + row * w
    ud[at] = time
    at += 1
    for i in range(nq):
        ud[at + i] = qpos[i]
    at += nq
    for i in range(nv):
        ud[at + i] = qvel[i]
    at += nv
    for i in range(na):
        ud[at + i] = act[i]
    at += na
    for i in range(N_USERDATA_LOGGED):
        ud[at + i] = ud[i]


def step_of(prm: FloatArray, time: float, userdata: FloatArray) -> tuple[bool, bool, float, float]:
    """(at a physics step, a new one, its index, the last step seen: -1 none) of a call at
    ``time`` (:func:`control`: the clock counts steps)."""
    h = prm[P_TIMESTEP]
    tol = STEP_TOLERANCE * h
    at_step = False
    new_step = False
    s = 0.0
    last = userdata[U_STEP] - 1.0  # index of the last step seen, -1: none yet
    if last >= 0.0 and time > userdata[U_STEP_T] - tol:
        elapsed = time - userdata[U_STEP_T]
        if elapsed < tol:
            at_step = True
            s = last
        elif elapsed > h - tol:
            at_step = True
            new_step = True
            s = last + math.floor(elapsed / h + 0.5)
    else:  # first call, or time was set back: the step grid of this call's own time
        x = math.floor(time / h + 0.5)
        if x >= 0.0 and abs(time - x * h) < tol:
            at_step = True
            new_step = True
            s = x
            last = -1.0
    return at_step, new_step, s, last


def snapshot(
    prm: FloatArray, userdata: FloatArray, time: float, s: float, new_step: bool, last: float
) -> bool:
    """At physics step ``s`` (:func:`control`): snapshot the run metrics on a new step and the
    controller memory on a new tick; whether this call is RK4's predicted stage (the held
    outputs stay)."""
    predicted = False
    if new_step:
        for i in range(N_ACC):
            userdata[U_ACC_PRE + i] = userdata[U_ACC + i]
        userdata[U_STEP] = s + 1.0
        userdata[U_STEP_T] = time
        # Under RK4 the first call at a step that follows the last one seen is the 4th stage
        # of the step that ends on it, with a predicted state: keep the held output there
        # (zero-order hold); mj_step's own forward at that time redoes it from the true state.
        predicted = prm[P_RK4] > 0.5 and last >= 0.0
    per_tick = prm[P_STEPS_PER_TICK]
    k = int(math.floor(s / per_tick))  # noqa: RUF046  the tick this step belongs to (int for Numba)
    if k + 1.0 > userdata[U_TICK]:
        for i in range(N_MEM):
            userdata[U_PRE + i] = userdata[U_MEM + i]
        userdata[U_TICK] = k + 1.0
        userdata[U_TICK_STEP] = s
    return predicted


def control(
    prm: FloatArray,
    ref: FloatArray,
    time: float,
    qpos: FloatArray,
    qvel: FloatArray,
    act: FloatArray,
    bias: FloatArray,
    mass: FloatArray,
    userdata: FloatArray,
    ctrl: FloatArray,
) -> None:
    """mjcb_control body: run the controllers on their clock ticks, hold the outputs between.

    **The clock counts steps.** MuJoCo adds ``h`` to ``data.time`` every step, and that sum
    drifts by rounding (about 1e-4 s after an hour at h = 10 us), so "time is a multiple of the
    control period" stops matching after long enough. Instead, a call is *at a physics step* when
    its time is within ``STEP_TOLERANCE * h`` of the previous step's time (the same step again)
    or at least ``(1 - STEP_TOLERANCE) * h`` after it (a new step, whose index is counted from the
    previous one by the elapsed time over ``h``: an interval, free of the drift). The very first
    call, or a call whose time went back, is placed on the step grid of its own time. Control tick
    ``k`` is step ``k * P_STEPS_PER_TICK``.

    The first call of a new step snapshots the run metrics, and the first call of a new tick the
    controller memory; every later call at the same step recomputes from the snapshot. So extra
    ``mj_forward`` calls, finite differencing that perturbs the state (``mjd_transitionFD`` does
    not restore ``userdata``) and RK4's stage at t+h are all harmless: the last call before
    integration - ``mj_step``'s own forward at the start of the step - always has the final word,
    with the true state. Calls between steps (RK4's half-step stages) apply the held outputs
    unchanged, and so does RK4's last stage, which lands on the next step with a predicted state.
    """
    if prm[P_EN_CONTROL] < 0.5:
        return
    at_step, new_step, s, last = step_of(prm, time, userdata)
    if at_step and not snapshot(prm, userdata, time, s, new_step, last):
        tick = int(userdata[U_TICK]) - 1
        out = userdata[U_OUT : U_OUT + 3]
        log = userdata[U_LOG:]
        if s == userdata[U_TICK_STEP]:
            mem_in = userdata[U_PRE : U_PRE + N_MEM]
            mem_out = userdata[U_MEM : U_MEM + N_MEM]
            control_tick(prm, ref, tick, qpos, qvel, bias, mass, mem_in, mem_out, out, log)
        acc_pre = userdata[U_ACC_PRE : U_ACC_PRE + N_ACC]
        acc = userdata[U_ACC : U_ACC + N_ACC]
        accumulate_metrics(prm, ref, tick, qpos, qvel, acc_pre, acc, out, log)
        record_row(s, time, qpos, qvel, act, userdata)
    ctrl[int(prm[P_CTRL_J1])] = userdata[U_OUT]
    ctrl[int(prm[P_CTRL_J2])] = userdata[U_OUT + 1]
    ctrl[int(prm[P_CTRL_J3])] = userdata[U_OUT + 2]
