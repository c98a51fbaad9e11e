"""The arm's structure read back by name from a compiled model (joint, dof and actuator indices,
the shaft tendon's coefficients): the MJCF is the one place it is written.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from fsarm_sim.errors import ModelStructureError


@dataclass(frozen=True)
class ArmStructure:
    """Indices and ratios read from the compiled MJCF."""

    qadr: tuple[int, int, int, int]  # q1, q2, q3, rotor
    dof: tuple[int, int, int, int]
    coef_m: float  # 1 / i_G1
    coef_s: float  # i_G2
    act_branch: tuple[int, int]
    act_slip: int
    ctrl: tuple[int, int, int]
    madr: tuple[int, int, int]
    tau_max: tuple[float, float, float]  # j1, j2 joint torque; j3 motor (rotor) torque
    motor_speed_limit: float
    twist_tendon: int

    @property
    def i_g1(self) -> float:
        return 1.0 / self.coef_m

    @property
    def i_g2(self) -> float:
        return self.coef_s


def named_id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    """The id of the MJCF element ``name`` of ``kind``; a named error where the MJCF lacks it."""
    i = mujoco.mj_name2id(model, kind, name)
    if i < 0:
        raise ModelStructureError(
            f"the MJCF has no {kind.name[6:].lower()} named '{name}', which fsarm-sim needs"
        )
    return int(i)


def fixed_tendon(model: mujoco.MjModel, name: str) -> dict[int, float]:
    t = named_id(model, mujoco.mjtObj.mjOBJ_TENDON, name)
    adr, num = int(model.tendon_adr[t]), int(model.tendon_num[t])
    out: dict[int, float] = {}
    for w in range(adr, adr + num):
        if model.wrap_type[w] != mujoco.mjtWrap.mjWRAP_JOINT:
            raise ModelStructureError(f"tendon '{name}' must be a fixed tendon of joints")
        out[int(model.wrap_objid[w])] = float(model.wrap_prm[w])
    return out


def read_structure(model: mujoco.MjModel) -> ArmStructure:
    """Find joints, gear ratios, states and limits by name; check they are consistent."""
    J = mujoco.mjtObj.mjOBJ_JOINT
    joints = [named_id(model, J, n) for n in ("q1", "q2", "q3", "j3_rotor")]
    rotor, q3 = joints[3], joints[2]
    tm, ts, tw = (
        fixed_tendon(model, "theta_m"),
        fixed_tendon(model, "theta_s"),
        fixed_tendon(model, "shaft_twist"),
    )
    if set(tm) != {rotor} or set(ts) != {q3}:
        raise ModelStructureError("tendon 'theta_m' must use only j3_rotor and 'theta_s' only q3")
    coef_m, coef_s = tm[rotor], ts[q3]
    if coef_m <= 0.0 or coef_s <= 0.0:
        raise ModelStructureError(
            "gear-ratio coefficients of 'theta_m' and 'theta_s' must be positive"
        )
    if set(tw) != {rotor, q3} or abs(tw[rotor] - coef_m) > 1e-12 or abs(tw[q3] + coef_s) > 1e-12:
        raise ModelStructureError(
            "tendon 'shaft_twist' must equal theta_m - theta_s (same coefficients)"
        )
    A = mujoco.mjtObj.mjOBJ_ACTUATOR
    br = [named_id(model, A, f"conduit_branch{i}") for i in (1, 2)]
    slips = [named_id(model, A, f"shaft_slip{i}") for i in (1, 2, 3)]
    slip_adr = [int(model.actuator_actadr[a]) for a in slips]
    if slip_adr != [slip_adr[0], slip_adr[0] + 1, slip_adr[0] + 2]:
        raise ModelStructureError("the three shaft_slip actuators must be consecutive")
    motors = [named_id(model, A, n) for n in ("j1_motor", "j2_motor", "j3_motor")]
    tau_max = tuple(
        float(max(abs(model.actuator_ctrlrange[a, 0]), abs(model.actuator_ctrlrange[a, 1])))
        for a in motors
    )
    speed = model.numeric("j3_motor_speed_limit").data
    dofs = [int(model.jnt_dofadr[j]) for j in joints]
    madr = [int(model.M_rowadr[d] + model.M_rownnz[d] - 1) for d in dofs[:3]]
    return ArmStructure(
        qadr=tuple(int(model.jnt_qposadr[j]) for j in joints),  # type: ignore[arg-type]
        dof=tuple(dofs),  # type: ignore[arg-type]
        coef_m=coef_m,
        coef_s=coef_s,
        act_branch=(int(model.actuator_actadr[br[0]]), int(model.actuator_actadr[br[1]])),
        act_slip=slip_adr[0],
        ctrl=tuple(motors),  # type: ignore[arg-type]
        madr=tuple(madr),  # type: ignore[arg-type]
        tau_max=tau_max,  # type: ignore[arg-type]
        motor_speed_limit=float(speed[0]),
        twist_tendon=named_id(model, mujoco.mjtObj.mjOBJ_TENDON, "shaft_twist"),
    )
