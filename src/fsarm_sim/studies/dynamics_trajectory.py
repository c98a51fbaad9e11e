"""MuJoCo RK4 closed loop vs an independent RK4 on Pinocchio ABA, with convergence orders in the
time step (check 6).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import SimConfig, build_model, read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout, physics
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import initial_state, raise_on_warning
from fsarm_sim.studies import pinocchio_model as pm
from fsarm_sim.studies.dynamics_pointwise import (
    CheckResult,
    FloatArray,
    Pair,
    actuator_forces,
    make_pair,
)

# --- check 6: closed-loop trajectories, MuJoCo vs an independent Pinocchio integration ------
#
# The reference integrates the same closed loop with its own fixed-step RK4: Pinocchio ABA, the
# same constitutive forces and state rates (physics.passive_forces / state_rate), the same
# controller (physics.control_tick fed with Pinocchio's bias and inertia diagonal), zero-order
# hold between control ticks, the same reference table and initial state.
#
# MuJoCo's RK4 calls mjcb_control at every stage; its fourth stage of the step that ends on a
# control tick sits exactly on that tick. physics.control keeps the held output there (P_RK4), so
# MuJoCo's closed loop is a true zero-order hold like the reference's, and the two can be compared
# step for step at the same dt (applying tick k+1 in that stage would make the loop only first
# order: this check would find it).

STATE_ACT_DYN = int(mujoco.mjtDyn.mjDYN_USER)


@dataclass(frozen=True)
class ArmState:
    qpos: FloatArray
    qvel: FloatArray
    act: FloatArray

    def moved(self, h: float, rate: ArmState) -> ArmState:
        return ArmState(
            self.qpos + h * rate.qpos, self.qvel + h * rate.qvel, self.act + h * rate.act
        )


def _check_integrable(m: mujoco.MjModel) -> None:
    if m.nq != m.nv or np.any(
        (m.jnt_type != mujoco.mjtJoint.mjJNT_HINGE) & (m.jnt_type != mujoco.mjtJoint.mjJNT_SLIDE)
    ):
        raise ModelStructureError("the reference integrator supports hinge and slide joints only")
    for a in range(m.nu):
        if int(m.actuator_dyntype[a]) not in (int(mujoco.mjtDyn.mjDYN_NONE), STATE_ACT_DYN):
            raise ModelStructureError("actuator states must be dyntype 'user' (mjcb_act_dyn)")


def state_rates(
    pair: Pair, x: ArmState, tau_ctrl: FloatArray, state_act: tuple[int, ...]
) -> ArmState:
    """d/dt (qpos, qvel, act) on Pinocchio: ABA with the shaft forces, damping and motor forces."""
    prm, m = pair.params, pair.mj
    tau = np.zeros(m.nv)
    ud = np.zeros(layout.N_USERDATA)
    physics.passive_forces(prm, x.qpos, x.qvel, x.act, tau, ud)
    tau += tau_ctrl - pair.arm.damping * x.qvel
    act_dot = np.zeros(m.na)
    for adr in state_act:
        act_dot[adr] = physics.state_rate(prm, x.qpos, x.qvel, x.act, adr, ud)
    return ArmState(x.qvel.copy(), pm.forward_dynamics(pair.arm, x.qpos, x.qvel, tau), act_dot)


def control_forces(
    pair: Pair, k: int, x: ArmState, mem: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Control tick k on Pinocchio's model terms: (generalized motor forces, new memory)."""
    m, st = pair.mj, pair.st
    bias = pm.bias(pair.arm, x.qpos, x.qvel)
    full = pm.mass_matrix(pair.arm, x.qpos)
    mass = np.zeros(m.nM)
    for i in range(3):
        mass[st.madr[i]] = full[st.dof[i], st.dof[i]]
    mem_out = mem.copy()
    out = np.zeros(3)
    physics.control_tick(
        pair.params,
        pair.reference,
        k,
        x.qpos,
        x.qvel,
        bias,
        mass,
        mem,
        mem_out,
        out,
        np.zeros(layout.N_LOG),
    )
    ctrl = np.zeros(m.nu)
    ctrl[list(st.ctrl)] = out
    return actuator_forces(m, ctrl, x.act), mem_out


def rk4_step(pair: Pair, x: ArmState, h: float, tau_ctrl: FloatArray) -> ArmState:
    """One classic RK4 step with the control held (zero-order hold)."""
    acts = pair.state_act
    k1 = state_rates(pair, x, tau_ctrl, acts)
    k2 = state_rates(pair, x.moved(0.5 * h, k1), tau_ctrl, acts)
    k3 = state_rates(pair, x.moved(0.5 * h, k2), tau_ctrl, acts)
    x4 = x.moved(h, k3)
    k4 = state_rates(pair, x4, tau_ctrl, acts)
    rate = ArmState(
        (k1.qpos + 2 * k2.qpos + 2 * k3.qpos + k4.qpos) / 6.0,
        (k1.qvel + 2 * k2.qvel + 2 * k3.qvel + k4.qvel) / 6.0,
        (k1.act + 2 * k2.act + 2 * k3.act + k4.act) / 6.0,
    )
    nxt = x.moved(h, rate)
    return ArmState(nxt.qpos, nxt.qvel, _clamp_act(pair.mj, nxt.act))


def _clamp_act(m: mujoco.MjModel, act: FloatArray) -> FloatArray:
    out = act.copy()
    for a in range(m.nu):
        adr = int(m.actuator_actadr[a])
        if adr >= 0 and m.actuator_actlimited[a]:
            out[adr] = min(max(out[adr], m.actuator_actrange[a, 0]), m.actuator_actrange[a, 1])
    return out


def substeps(pair: Pair, dt: float) -> int:
    ctrl_dt = float(pair.params[layout.P_CTRL_DT])
    n = round(ctrl_dt / dt)
    if n < 1 or abs(n * dt - ctrl_dt) > 1e-9 * ctrl_dt:
        raise InvalidParameterError(
            f"time step {dt:g} s must divide the control period {ctrl_dt:g} s a whole number of times"
        )
    return n


def start_state(pair: Pair) -> tuple[ArmState, FloatArray]:
    """simulation.initial_state on the MuJoCo side, copied: (state, controller memory)."""
    d = mujoco.MjData(pair.mj)
    initial_state(pair.mj, d, pair.st)
    mem = np.array(d.userdata[layout.U_MEM : layout.U_MEM + layout.N_MEM])
    return ArmState(d.qpos.copy(), d.qvel.copy(), d.act.copy()), mem


def integrate_pinocchio(pair: Pair, n_ticks: int, dt: float) -> FloatArray:
    """qpos at every control tick (n_ticks + 1 rows) of the Pinocchio closed loop."""
    _check_integrable(pair.mj)
    n_sub = substeps(pair, dt)
    x, mem = start_state(pair)
    out = np.empty((n_ticks + 1, pair.mj.nq))
    out[0] = x.qpos
    for k in range(n_ticks):
        tau_ctrl, mem = control_forces(pair, k, x, mem)
        for _ in range(n_sub):
            x = rk4_step(pair, x, dt, tau_ctrl)
        if not (np.all(np.isfinite(x.qpos)) and np.all(np.isfinite(x.qvel))):
            raise InvalidParameterError(f"Pinocchio reference diverged at tick {k} (dt = {dt:g} s)")
        out[k + 1] = x.qpos
    return out


def integrate_mujoco(
    config: SimConfig, ref_table: FloatArray, n_ticks: int, dt: float, integrator: str
) -> FloatArray:
    """qpos at every control tick of MuJoCo's own closed loop (Python callbacks)."""
    m = build_model(config.with_(integrator=integrator, timestep_s=dt), ref_table)
    d = mujoco.MjData(m)
    initial_state(m, d, read_structure(m))
    n_sub = round(config.gains.ctrl_dt_s / dt)
    out = np.empty((n_ticks + 1, m.nq))
    out[0] = d.qpos
    with callbacks.active("python"):
        for k in range(n_ticks):
            mujoco.mj_step(m, d, nstep=n_sub)
            out[k + 1] = d.qpos
    raise_on_warning(d)
    return out


TRAJECTORY_SCENARIO = "fig14-sine"
TRAJECTORY_DTS = (1e-3, 5e-4, 2.5e-4)  # s; each divides the 1 ms control period
TOL_SAME_DT_RAD = 1e-9  # MuJoCo RK4 vs the Pinocchio RK4 loop, same dt
TOL_TRAJECTORY_RAD = 1e-4  # MuJoCo RK4 at the largest dt vs the converged zero-order-hold loop
MIN_ORDER_MUJOCO = 3.5  # MuJoCo's RK4 closed loop is fourth order too (zero-order hold)
MIN_ORDER_REFERENCE = 3.5  # the reference RK4 is itself fourth order


@dataclass(frozen=True)
class ConvergenceRow:
    dt_s: float
    mujoco_vs_reference_rad: float  # MuJoCo RK4 vs converged zero-order-hold reference
    pinocchio_vs_reference_rad: float  # Pinocchio RK4 (zero-order hold) at dt vs reference
    mujoco_vs_pinocchio_same_dt_rad: float  # MuJoCo RK4 vs Pinocchio RK4, same dt
    order_mujoco: float | None  # observed order from the previous (larger) dt
    order_pinocchio: float | None


@dataclass(frozen=True)
class TrajectoryStudy:
    scenario: str
    duration_s: float
    reference_dt_s: float
    rows: tuple[ConvergenceRow, ...]
    mujoco_euler_default_rad: float  # the simulator's default (Euler, 1 ms) vs the reference


def _q_error(a: FloatArray, b: FloatArray, qadr: tuple[int, ...]) -> float:
    cols = list(qadr[:3])
    return float(np.max(np.abs(a[:, cols] - b[:, cols])))


def _order(e_big: float, e_small: float, dt_big: float, dt_small: float) -> float:
    if e_small <= 0.0 or e_big <= 0.0:
        return float("nan")
    return math.log(e_big / e_small) / math.log(dt_big / dt_small)


def trajectory_study(
    duration_s: float,
    dts: tuple[float, ...] = TRAJECTORY_DTS,
    config: SimConfig | None = None,
    arm: pm.PinocchioArm | None = None,
) -> TrajectoryStudy:
    """Run fig14-sine on MuJoCo (RK4 at each dt) and on Pinocchio; errors on q1..q3 (rad).

    ``arm`` replaces the Pinocchio model (tests use it to show that a wrong model fails).
    """
    if not dts or any(b >= a for a, b in itertools.pairwise(dts)):
        raise InvalidParameterError(
            f"time steps must be a decreasing, non-empty sequence, got {dts}"
        )
    sc = scenarios.get(TRAJECTORY_SCENARIO)
    cfg = config or SimConfig(payload_kg=sc.payload_kg)
    n_ticks = round(duration_s / cfg.gains.ctrl_dt_s)
    if n_ticks < 1:
        raise InvalidParameterError(
            f"duration must cover at least one control tick, got {duration_s!r} s"
        )
    table = sc.reference(np.arange(n_ticks + 1, dtype=np.float64) * cfg.gains.ctrl_dt_s)
    pair = make_pair(cfg, table, TRAJECTORY_SCENARIO)
    if arm is not None:
        pair.arm = arm
    ref_dt = dts[-1] / 2.0
    reference = integrate_pinocchio(pair, n_ticks, ref_dt)
    qadr = pair.st.qadr
    rows: list[ConvergenceRow] = []
    for i, dt in enumerate(dts):
        mj = integrate_mujoco(cfg, table, n_ticks, dt, "RK4")
        zoh = integrate_pinocchio(pair, n_ticks, dt)
        e_mj, e_pin = _q_error(mj, reference, qadr), _q_error(zoh, reference, qadr)
        prev = rows[-1] if rows else None
        rows.append(
            ConvergenceRow(
                dt_s=dt,
                mujoco_vs_reference_rad=e_mj,
                pinocchio_vs_reference_rad=e_pin,
                mujoco_vs_pinocchio_same_dt_rad=_q_error(mj, zoh, qadr),
                order_mujoco=_order(prev.mujoco_vs_reference_rad, e_mj, dts[i - 1], dt)
                if prev
                else None,
                order_pinocchio=_order(prev.pinocchio_vs_reference_rad, e_pin, dts[i - 1], dt)
                if prev
                else None,
            )
        )
    euler = integrate_mujoco(cfg, table, n_ticks, cfg.gains.ctrl_dt_s, "Euler")
    return TrajectoryStudy(
        TRAJECTORY_SCENARIO,
        n_ticks * cfg.gains.ctrl_dt_s,
        ref_dt,
        tuple(rows),
        _q_error(euler, reference, qadr),
    )


def _orders(values: list[float | None]) -> float:
    real = [v for v in values if v is not None]
    return min(real) if real else float("nan")


def check_trajectory(study: TrajectoryStudy) -> list[CheckResult]:
    rows = study.rows
    same = max(r.mujoco_vs_pinocchio_same_dt_rad for r in rows)
    dts = ", ".join(f"{r.dt_s:g}" for r in rows)
    results = [
        CheckResult(
            "trajectory_same_dt",
            "trajectory, same dt: MuJoCo RK4 vs Pinocchio RK4 (both zero-order hold)",
            same,
            TOL_SAME_DT_RAD,
            "rad",
            f"{study.scenario}, {study.duration_s:g} s, dt = {dts} s; max |q_mj - q_pin|, q1-q3",
        ),
        CheckResult(
            "trajectory",
            "trajectory: MuJoCo RK4 vs converged zero-order-hold Pinocchio loop",
            rows[0].mujoco_vs_reference_rad,
            TOL_TRAJECTORY_RAD,
            "rad",
            f"at dt = {rows[0].dt_s:g} s; reference RK4 at {study.reference_dt_s:g} s",
        ),
    ]
    if len(rows) > 1:
        results += [
            CheckResult(
                "order_mujoco",
                "convergence order of MuJoCo RK4 toward the reference (at least)",
                _orders([r.order_mujoco for r in rows]),
                MIN_ORDER_MUJOCO,
                "-",
                "fourth order expected with a zero-order-hold controller",
                at_least=True,
            ),
            CheckResult(
                "order_reference",
                "convergence order of the Pinocchio RK4 reference (at least)",
                _orders([r.order_pinocchio for r in rows]),
                MIN_ORDER_REFERENCE,
                "-",
                "fourth order expected with a zero-order-hold controller",
                at_least=True,
            ),
        ]
    return results
