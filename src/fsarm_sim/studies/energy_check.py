"""Energy bookkeeping of the free arm: with every dissipation off, the total energy is constant.

The arm without controllers, joint damping, joint limits or any dissipative element of its
transmission (each module's ``CONSERVATIVE`` overrides), bent at joint 2 and set swinging with a
twisted transmission, integrated with RK4 at a small step. Its total energy - MuJoCo's kinetic
and gravity energy plus the transmission's stored energy (``physics.shaft_potential``) - may then
change only by integration error. A transmission routed over joint 2 whose law depends on the bend
stores energy that changes when joint 2 moves; without the matching -dV/dphi_B torque on joint 2
(``physics.bend_coupling_torque``) the arm gains or loses that energy (the RTCA shaft lost 4.2 mJ
in 2 s before every transmission got it from the interface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import Effects, Gains, SimConfig, build_model, read_structure
from fsarm_sim.kernels import layout, physics
from fsarm_sim.plant import transmissions
from fsarm_sim.sim.simulation import initial_state, raise_on_warning

DEFAULT_BEND_RAD = math.radians(45.0)  # bent, and joint 2 then swings through the range where
# every routed law still changes with the bend (the RTCA scaling saturates beyond ~1.2 rad)
DEFAULT_SECONDS = 2.0
DEFAULT_TIMESTEP_S = 5e-5  # RK4: integration error of the ~30 J arm below 1 uJ in 2 s (eq. 3's
# kink at zero bend makes it converge at order 2 only: 1.1 uJ at 1e-4 s, 0.24 uJ at 5e-5 s)
TWIST_FRACTION = 0.2  # initial extra twist, of the transmission's valid twist range
Q2_RATE_RAD_S = 0.5  # joint 2 swings: the bend changes under the twisted transmission


@dataclass(frozen=True)
class EnergyDrift:
    transmission: str
    bend_rad: float
    seconds: float
    timestep_s: float
    energy_j: float  # total energy at the start
    drift_j: float  # largest |E(t) - E(0)| over the run
    bend_swing_rad: float  # how far joint 2 moved
    coupling_work_j: float  # energy the -dV/dphi_B torque moved in and out (sum of |P| dt)


def conservative_config(name: str, timestep_s: float = DEFAULT_TIMESTEP_S) -> SimConfig:
    """The free arm with transmission ``name`` and every dissipation switched off."""
    tr = transmissions.get(name)
    overrides = dict(getattr(tr.module, "CONSERVATIVE", {}))
    base = SimConfig(
        transmission=name,
        effects=Effects(control=False, bending=True, conduit=False, slip=False),
        joint_damping=False,
        integrator="RK4",
        timestep_s=timestep_s,
        gains=Gains(ctrl_dt_s=timestep_s),
    )
    return base.with_(transmission_params=tuple(overrides.items()))


def free_arm_energy_drift(
    name: str,
    bend_rad: float = DEFAULT_BEND_RAD,
    seconds: float = DEFAULT_SECONDS,
    timestep_s: float = DEFAULT_TIMESTEP_S,
    backend: str = "native",
) -> EnergyDrift:
    """Largest change of the free, undamped arm's total energy over ``seconds`` (J)."""
    cfg = conservative_config(name, timestep_s)
    table = np.zeros((1, layout.REF_COLS))
    table[0, :3] = (0.0, bend_rad, 0.4)
    m = build_model(cfg, table)
    m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT
    d = mujoco.MjData(m)
    st = read_structure(m)
    initial_state(m, d, st)
    tr = cfg.transmission_model()
    d.qpos[st.qadr[3]] += TWIST_FRACTION * tr.twist_range_rad / st.coef_m
    d.qvel[st.dof[1]] = Q2_RATE_RAD_S
    prm = m.numeric(layout.PARAMS_NAME).data
    q2 = [float(d.qpos[st.qadr[1]])]

    def energy() -> float:
        mujoco.mj_forward(m, d)
        return float(d.energy[0] + d.energy[1]) + physics.shaft_potential(prm, d.qpos, d.act)

    work = 0.0
    with callbacks.active(backend):
        e0 = energy()
        drift = 0.0
        for _ in range(round(seconds / timestep_s)):
            mujoco.mj_step(m, d)
            drift = max(drift, abs(energy() - e0))
            q2.append(float(d.qpos[st.qadr[1]]))
            tau_c = physics.bend_coupling_torque(prm, d.qpos, d.act)
            work += abs(tau_c * d.qvel[st.dof[1]]) * timestep_s
    raise_on_warning(d)
    return EnergyDrift(name, bend_rad, seconds, timestep_s, e0, drift, float(np.ptp(q2)), work)
