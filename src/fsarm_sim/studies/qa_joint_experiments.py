"""Seed 002's QA-Joint experiments on a single-joint bench: strike-out throws (Sec. VI) and impact.

Source: /work/shared/seeds/002_93b61736cab1a199.txt. The arm is not the paper's set-up (the paper
tests one joint with its own link), so this is a one-joint bench of the paper's two-mass model:

    B theta'' = tau_m - tau_J                                    (eq. 14)
    M q''     = tau_J - tau_ext        (tau_g = 0: horizontal axis) (eq. 15)
    tau_m     = sat(K_P (theta_ref - theta) + K_D (theta'_ref - theta'), tau_m,max)

with Table V (M = 0.523808 kg m^2, B = 0.993374 kg m^2, K_P = 25371, K_D = 288, tau_m,max = 160
N m: "the motor is controlled with simple PD control", Sec. IV-C and footnote 2). ``tau_J`` is
our transmission's law (:mod:`fsarm_sim.plant.transmissions.qa_joint`, Table IV row of the preset:
eq. 16 spring + eq. 19 friction as a Dahl element in parallel, state ``z``), written here with
numpy over a batch of runs (``tests/test_qa_joint_experiments.py`` checks it against the kernel);
the preset ``sigma`` follows the module's stiffness drive (Table III: full range in 0.12 s) or,
for "ideal" adjustment (Sec. VI: "the stiffness adjuster is assumed to show ideal behavior for the
simulation"), its command directly.

Strike-out throw (Sec. VI, Fig. 10-12). The paper's optimal control [16] is not printed ("a paper
fully describing the theory is currently under preparation"); what it states is the premise:
*maximum deflection with one switching cycle* within the motor-velocity bound, and the
constraints on joint torque (40 N m, Table III), motor torque (160 N m) and deflection
(|phi| <= sigma, eq. 11). Our reconstruction: the motor velocity reference is bang-bang with one
switch, ``-v`` (strike-out backwards) until ``t_s``, then ``+v``; ``t_s`` is chosen to maximise
the final link velocity - the link velocity when the forward deflection has relaxed to zero
(``tau_J`` ~ 0: the link stops gaining speed) - subject to the constraints over the whole throw.
A speed ``v`` is feasible when some ``t_s`` reaches the maximum deflection (``max phi >= (1 -
DEFLECTION_REACH) sigma``) without violating them: a minimum and a maximum velocity result, as
the paper says. ``epsilon = q'_final / v`` (Sec. VI).

Stiffness adjustment (eq. 20): in the relaxation phase of the throw (forward deflection past its
peak) the preset command follows the deflection, ``sigma_d = phi`` (clamped to the preset range).

Impact (Sec. VII, Fig. 13): :func:`impact` - a rigid 4.2 kg impactor at 1.07 m/s hits the link at
a lever arm ``r`` that the paper does not give; the link is held by the motor's PD (position
control). The collision is a short stiff contact (a Hertz-free linear spring-damper, estimate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError

FloatArray = npt.NDArray[np.float64]
DEG = math.pi / 180.0

# Table V (seed 002)
LINK_INERTIA_KGM2 = 0.523808
MOTOR_INERTIA_KGM2 = 0.993374
KP_NM_PER_RAD = 25371.0
KD_NMS_PER_RAD = 288.0
TAU_M_MAX_NM = 160.0
TAU_J_MAX_NM = 40.0  # Table III torque capacity
DT_S = 2e-4  # converged: epsilon changes < 0.1 % between 4e-4 s and 5e-5 s (estimate)
DEFLECTION_REACH = 0.02  # "maximum deflection" reached within 2 % of sigma (estimate)
DEFLECTION_SLACK = 0.02  # |phi| <= (1 + 2 %) sigma counts as within the end stop (estimate)
SWITCH_GRID = 121  # candidate switch times per throw (first pass)
# Sec. VII impact (seed 002)
IMPACTOR_KG = 4.2
IMPACT_SPEED_M_S = 1.07
CONTACT_STIFFNESS_N_PER_M = 5.0e6  # estimate: rigid aluminium-brass contact, ~ms duration
CONTACT_DAMPING_RATIO = 0.05  # estimate: a nearly elastic metal contact


class QaExperimentError(FsarmError, ValueError):
    """An experiment argument the bench cannot run (the message says the allowed range)."""


ADJUST_MODES = ("none", "drive", "ideal")
# The impact's lever arm (where the impactor meets the link), an input the user chooses: Sec. VII
# gives no link length or impact point. Accepted from 5 cm (a short flange) to 2 m (a long
# manipulator link; seed 002's is far shorter): an input range, not a physical value (estimate).
LEVER_ARM_RANGE_M = (0.05, 2.0)


def check_speed_deg_s(v_deg_s: float, name: str = "motor speed") -> None:
    """A throw's motor speed, deg/s: finite and > 0 (``name``: what the message calls it)."""
    if not (math.isfinite(v_deg_s) and v_deg_s > 0.0):
        raise QaExperimentError(f"{name} must be finite and > 0 deg/s, got {v_deg_s:g}")


def check_adjust(adjust: str, name: str = "adjust") -> None:
    """The stiffness adjustment of a throw: one of :data:`ADJUST_MODES`."""
    if adjust not in ADJUST_MODES:
        raise QaExperimentError(
            f"{name} must be {', '.join(ADJUST_MODES[:-1])} or {ADJUST_MODES[-1]}, got {adjust!r}"
        )


def check_lever_arm(lever_arm_m: float, name: str = "lever arm") -> None:
    """The impact's lever arm, m: within :data:`LEVER_ARM_RANGE_M`."""
    lo, hi = LEVER_ARM_RANGE_M
    if not (math.isfinite(lever_arm_m) and lo <= lever_arm_m <= hi):
        raise QaExperimentError(f"{name} must be within {lo:g}..{hi:g} m, got {lever_arm_m:g}")


@dataclass(frozen=True)
class Bench:
    """Table V's two-mass model around a QA-Joint parameter block."""

    block: FloatArray
    link_inertia: float = LINK_INERTIA_KGM2
    motor_inertia: float = MOTOR_INERTIA_KGM2
    kp: float = KP_NM_PER_RAD
    kd: float = KD_NMS_PER_RAD
    tau_m_max: float = TAU_M_MAX_NM
    dt: float = DT_S


def bench(sigma_deg: float, **overrides: float) -> Bench:
    """The bench at a Table IV preset (its identified row: the real joint of Sec. V)."""
    from fsarm_sim.plant import transmissions
    from fsarm_sim.plant.transmissions import qa_joint

    tr = transmissions.get("qa-joint")
    try:
        block = tr.block(qa_joint.table_iv_overrides(float(sigma_deg)))
    except Exception as exc:
        raise QaExperimentError(str(exc)) from exc
    return Bench(block=np.asarray(block, dtype=float), **overrides)


def _p(b: Bench) -> dict[str, float]:
    from fsarm_sim.plant.transmissions import qa_joint as qa

    t = b.block
    return {
        "a_s": float(t[qa.I_A_S]),
        "b_s": float(t[qa.I_B_S]),
        "a_f": float(t[qa.I_A_F]),
        "b_f": float(t[qa.I_B_F]),
        "b": float(t[qa.I_B_EXP]),
        "s_min": float(t[qa.I_SIGMA_MIN]),
        "s_max": float(t[qa.I_SIGMA_MAX]),
        "s_cmd": float(t[qa.I_SIGMA_CMD]),
        "s_tau": float(t[qa.I_SIGMA_TAU]),
        "s_rate": float(t[qa.I_SIGMA_RATE]),
        "delta": float(t[qa.I_DELTA]),
        "scale": float(t[qa.I_SCALE]),
    }


def joint_torque(
    p: dict[str, float], x: FloatArray, sigma: FloatArray, z: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """(tau_J incl. friction, elastic part) of qa_joint.torque_nm, over arrays."""
    b = p["b"]
    ep = np.exp(b * (x - sigma))
    en = np.exp(b * (-x - sigma))
    elastic = p["a_s"] * ep - p["b_s"] * en
    fric = (p["a_f"] * ep + p["b_f"] * en) * np.clip(z, -1.0, 1.0)
    return p["scale"] * (elastic + fric), p["scale"] * elastic


@dataclass
class ThrowBatch:
    """One throw per switch time: final link velocity and the constraint margins."""

    v: float
    sigma: float
    t_switch: FloatArray
    q_dot_final: FloatArray  # rad/s (nan: the forward deflection never relaxed)
    phi_max: FloatArray  # largest forward deflection, rad
    phi_min: FloatArray  # most negative deflection, rad
    tau_j_max: FloatArray  # largest |tau_J|, N m
    t_final: FloatArray
    traces: dict[str, FloatArray] = field(default_factory=dict)

    def feasible(self) -> npt.NDArray[np.bool_]:
        lim = (1.0 + DEFLECTION_SLACK) * self.sigma
        return (
            np.isfinite(self.q_dot_final)
            & (self.phi_max <= lim)
            & (self.phi_min >= -lim)
            & (self.tau_j_max <= TAU_J_MAX_NM)
            & (self.phi_max >= (1.0 - DEFLECTION_REACH) * self.sigma)
        )


def _adjusted_preset(
    p: dict[str, float],
    adjust: str,
    sig: FloatArray,
    phi: FloatArray,
    relax: npt.NDArray[np.bool_],
    dt: float,
) -> FloatArray:
    """Eq. 20: in the relaxation phase the preset follows the deflection (clamped to the
    presets' range), at once (``"ideal"``) or through the stiffness drive's rate (``"drive"``)."""
    cmd = np.where(relax, np.clip(phi, p["s_min"], p["s_max"]), p["s_cmd"])
    if adjust == "ideal":
        return np.where(relax, cmd, sig)
    rate = np.clip((cmd - sig) / p["s_tau"], -p["s_rate"], p["s_rate"])
    return np.clip(sig + dt * rate, p["s_min"], p["s_max"])


def _euler_step(
    b: Bench,
    p: dict[str, float],
    state: tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray],
    tau_m: FloatArray,
    tau_j: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """One semi-implicit Euler step of (motor angle, its speed, link angle, its speed, Dahl
    state): the Dahl state (qa_joint.dahl_rate), motor and link (eq. 14-15)."""
    th, thd, q, qd, z = state
    dt = b.dt
    xdot = thd - qd
    z = np.clip(z + dt * (xdot - np.abs(xdot) * z) / p["delta"], -1.0, 1.0)
    thd = thd + dt * (tau_m - tau_j) / b.motor_inertia
    qd = qd + dt * tau_j / b.link_inertia
    return th + dt * thd, thd, q + dt * qd, qd, z


def simulate_throws(
    b: Bench,
    v_rad_s: float,
    t_switch: FloatArray,
    *,
    adjust: str = "none",
    tail_s: float = 1.5,
    keep_trace: bool = False,
) -> ThrowBatch:
    """Throws at motor speed ``v`` for each switch time (0: no strike-out backwards).

    ``adjust``: ``"none"`` (constant preset), ``"drive"`` (eq. 20 through the module's stiffness
    drive, Table III rate) or ``"ideal"`` (eq. 20 with an ideal adjuster, as the paper's
    simulation).
    """
    check_speed_deg_s(v_rad_s / DEG)
    check_adjust(adjust)
    ts = np.asarray(t_switch, dtype=float)
    if ts.ndim != 1 or ts.size == 0 or np.any(ts < 0.0) or not np.all(np.isfinite(ts)):
        raise QaExperimentError("t_switch must be a non-empty 1-D array of times >= 0 s")
    p = _p(b)
    n = ts.size
    dt = b.dt
    steps = math.ceil((float(ts.max()) + tail_s) / dt)
    th, thd, q, qd, z = (np.zeros(n) for _ in range(5))
    sig = np.full(n, p["s_cmd"])
    ref = np.zeros(n)
    phi_max = np.zeros(n)
    phi_min = np.zeros(n)
    tau_max = np.zeros(n)
    q_final = np.full(n, np.nan)
    t_final = np.full(n, np.nan)
    forward_peaked = np.zeros(n, dtype=bool)
    done = np.zeros(n, dtype=bool)
    prev_phi = np.zeros(n)
    trace: dict[str, list[FloatArray]] = {k: [] for k in ("t", "q_dot", "phi", "tau_j", "sigma")}
    for k in range(steps):
        t = k * dt
        vref = np.where(t < ts, -v_rad_s, v_rad_s)
        phi = th - q
        tau_j, _ = joint_torque(p, phi, sig, z)
        tau_m = np.clip(b.kp * (ref - th) + b.kd * (vref - thd), -b.tau_m_max, b.tau_m_max)
        live = ~done
        phi_max = np.where(live, np.maximum(phi_max, phi), phi_max)
        phi_min = np.where(live, np.minimum(phi_min, phi), phi_min)
        tau_max = np.where(live, np.maximum(tau_max, np.abs(tau_j)), tau_max)
        if keep_trace:
            for name, value in zip(trace, (np.full(n, t), qd, phi, tau_j, sig), strict=True):
                trace[name].append(value.copy())
        # relaxation phase: forward deflection past its peak (eq. 20 acts there)
        after = t >= ts
        forward_peaked |= after & (phi > 0.5 * p["s_min"]) & (phi < prev_phi)
        ended = live & forward_peaked & (phi <= 0.0)
        q_final = np.where(ended, qd, q_final)
        t_final = np.where(ended, t, t_final)
        done |= ended
        if adjust != "none":
            sig = _adjusted_preset(p, adjust, sig, phi, forward_peaked & ~done, dt)
        th, thd, q, qd, z = _euler_step(b, p, (th, thd, q, qd, z), tau_m, tau_j)
        ref = ref + dt * vref
        prev_phi = phi
        if done.all() and not keep_trace:
            break
    out = ThrowBatch(
        v=v_rad_s,
        sigma=p["s_cmd"],
        t_switch=ts,
        q_dot_final=q_final,
        phi_max=phi_max,
        phi_min=phi_min,
        tau_j_max=tau_max,
        t_final=t_final,
    )
    if keep_trace:
        out.traces = {k: np.array(v) for k, v in trace.items()}
    return out


@dataclass(frozen=True)
class Throw:
    """The best one-switch throw at one (v, sigma)."""

    v_deg_s: float
    sigma_deg: float
    feasible: bool
    t_switch_s: float
    link_velocity_deg_s: float
    epsilon: float
    phi_max_deg: float
    tau_j_max_nm: float


def _best(batch: ThrowBatch) -> int | None:
    ok = batch.feasible()
    if not ok.any():
        return None
    return int(np.flatnonzero(ok)[np.argmax(batch.q_dot_final[ok])])


def best_throw(
    b: Bench, v_deg_s: float, *, t_switch_max_s: float | None = None, adjust: str = "none"
) -> Throw:
    """Search the switch time (grid, then a finer grid around the best) for the best throw."""
    check_speed_deg_s(v_deg_s)
    check_adjust(adjust)
    p = _p(b)
    if t_switch_max_s is None:
        k0 = 2.0 * (p["a_s"] + p["b_s"]) * p["b"] * math.exp(-p["b"] * p["s_cmd"])
        t_switch_max_s = 1.2 * 2.0 * math.pi * math.sqrt(LINK_INERTIA_KGM2 / k0)
    v = v_deg_s * DEG
    grid = np.linspace(0.0, t_switch_max_s, SWITCH_GRID)
    batch = simulate_throws(b, v, grid, adjust=adjust)
    i = _best(batch)
    if i is not None:
        h = grid[1] - grid[0]
        fine = np.clip(np.linspace(grid[i] - 2 * h, grid[i] + 2 * h, 41), 0.0, None)
        b2 = simulate_throws(b, v, fine, adjust=adjust)
        j = _best(b2)
        if j is not None and b2.q_dot_final[j] > batch.q_dot_final[i]:
            batch, i = b2, j
    sigma_deg = p["s_cmd"] / DEG
    if i is None:
        return Throw(v_deg_s, sigma_deg, False, math.nan, math.nan, math.nan, math.nan, math.nan)
    qf = float(batch.q_dot_final[i])
    return Throw(
        v_deg_s=v_deg_s,
        sigma_deg=sigma_deg,
        feasible=True,
        t_switch_s=float(batch.t_switch[i]),
        link_velocity_deg_s=qf / DEG,
        epsilon=qf / v,
        phi_max_deg=float(batch.phi_max[i]) / DEG,
        tau_j_max_nm=float(batch.tau_j_max[i]),
    )


# ------------------------------------------------------------------------------------ impact


@dataclass(frozen=True)
class Impact:
    sigma_deg: float
    lever_arm_m: float
    peak_joint_torque_nm: float
    peak_contact_force_n: float
    link_speed_after_deg_s: float


def impact(
    sigma_deg: float, lever_arm_m: float, *, duration_s: float = 0.4, dt: float = 1e-5
) -> Impact:
    """Sec. VII: the impactor (4.2 kg, 1.07 m/s) hits the link at ``lever_arm_m``; peak |tau_J|.

    The joint holds position (motor PD of Table V, reference 0, preset fixed). The contact is a
    stiff linear spring-damper (estimate, see CONTACT_*) along the link's tangent at the lever arm;
    the impactor then flies freely. Gravity is left out: the drop's geometry is not given, and
    over the ~3 ms contact it changes the impactor's speed by 0.03 m/s (3 %).
    """
    check_lever_arm(lever_arm_m)
    b = bench(sigma_deg)
    p = _p(b)
    m = IMPACTOR_KG
    k_c = CONTACT_STIFFNESS_N_PER_M
    m_eff = 1.0 / (1.0 / m + lever_arm_m**2 / b.link_inertia)
    c_c = 2.0 * CONTACT_DAMPING_RATIO * math.sqrt(k_c * m_eff)
    from fsarm_sim.plant.transmissions import qa_joint as qa

    th = thd = q = qd = 0.0
    act = np.array([p["s_cmd"], 0.0])
    y, yd = -1e-4, IMPACT_SPEED_M_S  # impactor position along the link's tangent at r
    tau_peak = f_peak = 0.0
    steps = int(duration_s / dt)
    for _ in range(steps):
        phi = th - q
        tau_j = qa.torque_nm(b.block, phi, thd - qd, 0.0, act, 0)
        pen = y - lever_arm_m * q
        pen_d = yd - lever_arm_m * qd
        f = max(0.0, k_c * pen + c_c * pen_d) if pen > 0.0 else 0.0
        tau_m = min(max(-b.kp * th - b.kd * thd, -b.tau_m_max), b.tau_m_max)
        tau_peak = max(tau_peak, abs(tau_j))
        f_peak = max(f_peak, f)
        act[1] = min(
            1.0, max(-1.0, act[1] + dt * qa.state_rate(b.block, phi, thd - qd, 0.0, act, 0, 1))
        )
        thd += dt * (tau_m - tau_j) / b.motor_inertia
        qd += dt * (tau_j + f * lever_arm_m) / b.link_inertia
        yd += dt * (-f) / m
        th += dt * thd
        q += dt * qd
        y += dt * yd
    return Impact(sigma_deg, lever_arm_m, tau_peak, f_peak, qd / DEG)
