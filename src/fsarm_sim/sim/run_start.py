"""What a run checks and sets before and while it steps: the control clock against the timestep,
MuJoCo's warnings, and the initial state (the shaft's static twist under gravity).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.controllers.joint3_hysteresis import initial_elements
from fsarm_sim.engine.model import (
    ArmStructure,
)
from fsarm_sim.errors import (
    CallbackBypassError,
    SimulationWarningError,
)
from fsarm_sim.kernels import layout
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.effects.base import TWIST, hooks
from fsarm_sim.sim.run_memory import MADV_POPULATE_WRITE as MADV_POPULATE_WRITE
from fsarm_sim.sim.run_memory import MAX_STEPS as MAX_STEPS
from fsarm_sim.sim.run_memory import MEMORY_SHARE as MEMORY_SHARE
from fsarm_sim.sim.run_memory import PAGE_BYTES as PAGE_BYTES
from fsarm_sim.sim.run_memory import available_memory_bytes as available_memory_bytes
from fsarm_sim.sim.run_memory import resident_empty as resident_empty
from fsarm_sim.sim.run_metrics import compute_metrics as compute_metrics

Array = npt.NDArray[np.float64]


def clock_gap_steps(
    model: mujoco.MjModel, data: mujoco.MjData, params: Array | None = None
) -> float | None:
    """Timesteps between ``data.time`` and the last step the control clock saw (None when the
    controllers, and so the clock, are switched off). After ``mj_step`` with the callbacks active
    it is 0 (RK4) or 1; before the first step ``U_STEP_T`` holds the start time
    (``initial_state``, ``Simulation.start_at``). ``params``: the model's ``fsarm_params`` if
    the caller holds them (None: looked up by name)."""
    prm = model.numeric(layout.PARAMS_NAME).data if params is None else params
    if prm[layout.P_EN_CONTROL] < 0.5:
        return None
    return (float(data.time) - float(data.userdata[layout.U_STEP_T])) / float(model.opt.timestep)


def check_clock(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Raise :class:`CallbackBypassError` if ``data`` was stepped without fsarm's callbacks.

    The control clock (``physics.control``) notes the time of the last step it saw; after
    ``mj_step`` with the callbacks active, ``data.time`` is at most one step past it. A larger gap
    means MuJoCo stepped this model with no shaft and no controllers (e.g. ``mujoco.mj_step``
    outside :func:`fsarm_sim.engine.callbacks.active`).
    """
    steps = clock_gap_steps(model, data)
    if steps is not None and steps > 1.5:
        raise CallbackBypassError(
            f"this fsarm model was stepped about {steps:.0f} steps (to t = {data.time:.6g} s) "
            "without fsarm's callbacks, so the shaft and the controllers did not act: step it with "
            "Simulation.step/run, or call mujoco.mj_step inside fsarm_sim.engine.callbacks.active()"
        )


def raise_on_warning(data: mujoco.MjData) -> None:
    """Turn any MuJoCo warning into a SimulationWarningError naming it."""
    # the usual case, in ~1 us (the list below takes ~0.1 ms): a list of 8 ints beats numpy's any
    if not any(data.warning.number.tolist()):
        return
    hits = [
        f"{mujoco.mjtWarning(i).name} (x{int(w.number)}, info {int(w.lastinfo)})"
        for i, w in enumerate(data.warning)
        if w.number > 0
    ]
    if hits:
        raise SimulationWarningError(f"MuJoCo warned at t = {data.time:.4f} s: {'; '.join(hits)}")


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, st: ArmStructure) -> None:
    """Start at the reference's first pose in static equilibrium.

    The shaft is pre-twisted to carry joint 3's gravity torque, the conduit branches are relaxed,
    and the speed-loop integrator already holds the motor torque that twist needs (bumpless start).
    """
    prm = model.numeric(layout.PARAMS_NAME).data
    ref = model.numeric(layout.REF_NAME).data
    mujoco.mj_resetData(model, data)
    for j in range(3):
        data.qpos[st.qadr[j]] = ref[j]
    data.qvel[:] = 0.0
    data.qpos[st.qadr[3]] = data.qpos[st.qadr[2]] * st.coef_s / st.coef_m
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    mujoco.mj_rne(model, data, 0, data.qfrc_bias)  # gravity only (qvel = 0)
    tau_shaft = float(data.qfrc_bias[st.dof[2]]) / st.coef_s
    bend = data.qpos[st.qadr[1]]
    twist = static_twist(prm, tau_shaft, bend)
    data.qpos[st.qadr[3]] = (st.coef_s * data.qpos[st.qadr[2]] + twist) / st.coef_m
    tr = transmissions.by_kind(prm[layout.P_TRANS])
    block = prm[layout.P_TR : layout.P_TR + layout.N_TR]
    # the transmission's states at the twist its law sees (the backlash play taken up is not)
    elastic = tr.twist_for_torque(block, tau_shaft, bend) if prm[layout.P_EN_SERIES] >= 0.5 else 0.0
    for i, v in enumerate(tr.initial_states(block, elastic, bend)):
        data.act[st.act_slip + i] = v
    data.act[st.act_branch[0]] = bend
    data.act[st.act_branch[1]] = bend
    if prm[layout.P_SPD_KI] > 0.0:
        data.userdata[layout.U_MEM + layout.M_SPD_I] = st.coef_m * tau_shaft / prm[layout.P_SPD_KI]
    if prm[layout.P_CTRL_KIND] == layout.CTRL_HYSTERESIS:
        # the controller's hysteresis model starts loaded like the shaft: a static start holds
        # joint 3's gravity torque, which the controller's model of the arm knows
        hm = prm[layout.P_HM : layout.P_HM + layout.N_HM]
        z = initial_elements(twist, bend, tau_shaft, *(float(v) for v in hm))
        data.userdata[layout.U_MEM + layout.M_SLIP : layout.U_MEM + layout.M_SLIP + 3] = z
    for b in layout.ARM_LAW_BLOCKS:  # the registry laws' own states start at their declared values
        if prm[b.on] > 0.5 and prm[b.act] >= 0.0:
            law = registry.get(b.name).law
            assert law is not None
            for i, d in enumerate(law.STATES):
                data.act[int(prm[b.act]) + i] = d.default
    data.userdata[layout.U_TICK] = 0.0
    data.time = 0.0


def static_twist(prm: Array, tau_shaft: float, bend: float) -> float:
    """Twist at which joint 3's transmission holds ``tau_shaft`` statically (0: no spring)."""
    if prm[layout.P_EN_SERIES] < 0.5:
        return 0.0
    tr = transmissions.by_kind(prm[layout.P_TRANS])
    twist = tr.twist_for_torque(prm[layout.P_TR : layout.P_TR + layout.N_TR], tau_shaft, bend)
    # the registry's twist laws that are on, undone last first (a play is taken up first, on
    # the loaded flank)
    for b in reversed(layout.ARM_LAW_BLOCKS):
        law: Any = registry.get(b.name).law  # (a twist law: the hook's members, base.hooks)
        if prm[b.on] > 0.5 and TWIST in hooks(law):
            twist = law.twist_for_transmitted(prm[b.start : b.end], twist)
    return twist
