"""Seed 004: how ours is measured.

* Position transmission (Sec. III-IV, Tables 1-2): the paper's validation set-up on our
  tendon-sheath law with the bench's parameters (``tendon_sheath.SEED004_BENCH``: a single
  tendon; sheath stiffness, routing curvature and mu fitted to Table 2, estimate): the motor
  angle theta_1 runs a triangle between -pi/4 and +pi/4, counted from theta_1 = theta_2 at the
  start (Sec. III); the pitch joint carries the 1 kg load (eq. 16: tau_2 = M g l cos theta_2,
  lever l = 0.1 m: estimate) and follows quasi-statically ("the effects of acceleration are
  negligible"), the law's friction state advanced with the tendon's sliding (the sum of the
  motor's and the joint's steps, solved together). One full cycle after a warm-up stroke is
  recorded, eq. 19 is fitted per direction over the moving phases (phases C/F, the joint
  static, belong to neither), and the gap between the two curves at theta_2 = 0
  (M(R.C.) - M(R.A.)) and the fits' maximal errors are compared; Table 1 at bend pi (the text), Table 2 at 0.06 rad/s (``DEFAULT_SPEED``).
* Bandwidth (Sec. V-C): joint-3 torque on the held arm with the tendon-sheath transmission, which
  runs seed 004's dual-encoder position loop (``controllers/tendon_sheath_compliance.py``; the
  controller's stiffness fixed at the straight value), its sheath's own bend set to pi/2, pi,
  3pi/2 and joint 2 straight.
* Collision detection and hand guiding (Sec. V-A/B): :func:`fsarm_sim.studies.collision.run_battery`
  with the tendon-sheath transmission: seed 004's Algorithm 1 (eq. 19 identified at the run's
  load, the delta rule) and Algorithm 2 (the motor follows the joint), the momentum observer on
  the same runs for comparison.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.optimize import brentq

from fsarm_sim.plant.roots import bisect
from fsarm_sim.studies.reproduce.claims import Context, Measured, MeasureFn

LOAD_KG = 1.0  # Sec. III: "The joint is connected to a load of 1 kg"
LEVER_M = 0.1  # estimate: the load's lever arm is not given
AMPLITUDE_RAD = math.pi / 4.0  # Sec. III: theta_1 = pi/4 sin(...)
STEP_RAD = 0.002  # motor increment of the quasi-static solution
# the joint counts as moving (eq. 19's omega_2 != 0) while it follows the motor at >= this
# fraction of the motor's speed (estimate: the seed states no threshold; phases C/F are a stop)
MOVING_FRACTION = 0.3
WRAPS_RAD = (math.pi / 2.0, math.pi, 1.5 * math.pi)  # Table 2
SPEEDS_RAD_S = (0.02, 0.04, 0.06)  # Table 1
# Table 2's speed is not stated. Sec. IV runs Table 1 at total bend pi; Table 1's 0.06 rad/s row
# then equals Table 2's pi row (gap 0.477 vs 0.484 rad; M 0.361 in both R.C. rows), so Table 2 is
# read at 0.06 rad/s. (Table 1's 0.04 row also resembles Table 2's pi/2 row; reading Table 1 at
# pi/2 instead would contradict the text.)
DEFAULT_SPEED = 0.06
TENDON_RADII_M = (0.0010, 0.0012, 0.0015)  # Fig. 10(b)
HAND_CYCLES = 3  # Sec. V-B: "the joint is dragged for three cycles"
# the joint's step and the friction state's are solved together (``_bracketed_root``): the
# bracket grows by at most this many motor steps; the root is found to the tolerance
FIXED_POINT_ITERATIONS = 20
FIXED_POINT_TOL_RAD = 1e-9
TWIST_TOL_RAD = (
    1e-13  # the twist balancing the load (Brent's method; far below any result's digits)
)


def _ts() -> tuple[Any, Any]:
    from fsarm_sim.plant import transmissions
    from fsarm_sim.plant.transmissions import tendon_sheath

    return transmissions.get("tendon-sheath"), tendon_sheath


def _bracketed_root(gap: Callable[[float], float], scale: float) -> float:
    """The root of ``gap`` nearest 0 (the joint held), bracketed by steps of ``scale`` and
    found by Brent's method (the map can jump where the friction state reaches its target, so a
    plain fixed point alternates there)."""
    g0 = gap(0.0)
    if abs(g0) <= FIXED_POINT_TOL_RAD:
        return 0.0
    direction = math.copysign(scale, g0)
    a, b = 0.0, direction
    for _ in range(FIXED_POINT_ITERATIONS):
        if gap(b) * g0 <= 0.0:
            lo, hi = (a, b) if a < b else (b, a)
            return float(brentq(gap, lo, hi, xtol=FIXED_POINT_TOL_RAD))
        a, b = b, b + direction
    raise RuntimeError("tendon-sheath bench: no joint step balances the load near this step")


def _solve_twist(residual: Callable[[float], float], x: float) -> float:
    """The twist where ``residual`` (joint-end torque minus the load's) crosses zero, near x."""
    lo, hi = x - 2.0 * STEP_RAD, x + 2.0 * STEP_RAD
    while residual(lo) > 0.0:
        lo -= 4.0 * STEP_RAD
    while residual(hi) < 0.0:
        hi += 4.0 * STEP_RAD
    return float(brentq(residual, lo, hi, xtol=TWIST_TOL_RAD))


def _start_twist(ts: Any, block: Any, load_nm: float) -> float:
    """The tendon's stretch (as twist) that holds ``load_nm`` with the friction relaxed (z = 0),
    by bisection."""

    def below(x: float) -> bool:
        return float(ts.sensor_torque_nm(block, x, 0.0)) < load_nm

    hi = 1.0
    while below(hi):
        hi *= 2.0
    return bisect(below, 0.0, hi, 60)


def _fit_eq19(
    t1: np.ndarray, t2: np.ndarray, d: np.ndarray, moving: np.ndarray
) -> dict[str, dict[str, float]]:
    """Eq. 19 (theta_1 quadratic in theta_2) fitted per direction, with its maximal error.

    Eq. 19 describes "the state of motion" (omega_2 > 0 or < 0); phases C and F (the joint
    static while the motor turns) belong to neither branch."""
    fits = {}
    for name, sel in (("up", (d > 0.0) & moving), ("down", (d < 0.0) & moving)):
        coef = np.polyfit(t2[sel], t1[sel], 2)
        err = float(np.max(np.abs(np.polyval(coef, t2[sel]) - t1[sel])))
        fits[name] = {
            "P": float(coef[0]),
            "Q": float(coef[1]),
            "M": float(coef[2]),
            "max_error": err,
        }
    return fits


def _motor_step(
    ts: Any,
    block: Any,
    act: np.ndarray,
    residual: Callable[[float], float],
    now: tuple[float, float, float, float],
) -> tuple[float, float, float]:
    """One motor increment from ``now`` = (twist, motor step, friction state, duration):
    (the joint's step, the friction state, the twist) after it. The tendon slides with the sum
    of its ends' travels (tendon_sheath.state_rate): the motor's step and the joint's, solved
    together, the root nearest the joint held (phases C/F; a root far from it is another
    equilibrium of the load); ``act[0]`` holds the friction state ``residual`` reads."""
    x, step, z_start, dt = now

    def joint_gap(j: float) -> float:
        """The joint step that z(j) implies, minus j (0 at the solution)."""
        act[0] = float(ts.friction_step(block, x, step, 0.0, z_start, dt, j))
        return step - (_solve_twist(residual, x) - x) - j

    joint_step = _bracketed_root(joint_gap, abs(step))
    z = float(ts.friction_step(block, x, step, 0.0, z_start, dt, joint_step))
    act[0] = z
    return joint_step, z, _solve_twist(residual, x)


def position_transmission(
    wrap: float,
    speed: float,
    tendon_radius: float | None = None,
    overrides: dict[str, float] | None = None,
    sine_period_s: float | None = None,
) -> dict[str, Any]:
    """One validation cycle of seed 004's single TSA on our law, quasi-static (eq. 16:
    acceleration negligible); eq. 19 fitted per direction of motion.

    The motor runs a triangle at ``speed`` (rad/s) between -pi/4 and +pi/4 (counted from the
    start, where theta_1 = theta_2) - or, with ``sine_period_s``, Sec. III's sine
    ``theta_1 = pi/4 sin(2 pi t / period - pi/2)`` over the same strokes (each step lasts as long
    as the sine takes over it; ``speed`` is then its peak speed, for the record); each motor
    increment advances the law's friction state z by :func:`tendon_sheath.friction_step` over
    the tendon's sliding (the motor's step plus the joint's, solved together) and its duration,
    then solves the joint-end torque ``tau(x, z) = M g l cos(theta_2)``,
    ``theta_2 = theta_1 - x``, for the twist x."""
    tr, ts = _ts()
    over: dict[str, float] = {**ts.SEED004_BENCH, "wrap_rad": wrap}
    if tendon_radius is not None:
        over["tendon_radius_m"] = tendon_radius
    over.update(overrides or {})
    block = tr.block(over)
    mgl = LOAD_KG * 9.81 * LEVER_M
    a = AMPLITUDE_RAD
    # Sec. III: "the starting values of the motor angle theta_1 and the joint angle theta_2 are
    # equivalent": the motor angle is counted from where it holds the joint at theta_1's start
    # (-pi/4, the sine's start), so theta_2 swings about 0 as theta_1 does; x0 is the tendon's
    # stretch (as twist) there, the friction relaxed (z = 0)
    x0 = _start_twist(ts, block, mgl * math.cos(a))
    legs = [(-a, a, False), (a, -a, True), (-a, a, True)]  # warm-up stroke, then one cycle
    act = np.zeros(3)
    z = 0.0
    th1 = -a + x0  # the motor's own angle; the seed's theta_1 is th1 - x0
    x = x0
    dt = STEP_RAD / speed
    rec1, rec2, recd, recz = [], [], [], []
    recm: list[bool] = []

    def residual(x_new: float) -> float:
        return float(ts.torque_nm(block, x_new, 0.0, 0.0, act, 0)) - mgl * math.cos(th1 - x_new)

    for start, end, keep in legs:
        n = round(abs(end - start) / STEP_RAD)
        step = (end - start) / n
        for _ in range(n):
            th1 += step
            if sine_period_s is not None:  # the sine's speed at the step's middle
                mid = th1 - x0 - 0.5 * step
                dt = STEP_RAD / ((2.0 * math.pi / sine_period_s) * math.sqrt(a * a - mid * mid))
            joint_step, z, x = _motor_step(ts, block, act, residual, (x, step, z, dt))
            if keep:
                recm.append(joint_step * math.copysign(1.0, step) >= MOVING_FRACTION * STEP_RAD)
                rec1.append(th1 - x0)
                rec2.append(th1 - x)
                recd.append(math.copysign(1.0, step))
                recz.append(z)
    t1, t2, d, moving = np.array(rec1), np.array(rec2), np.array(recd), np.array(recm)
    fits = _fit_eq19(t1, t2, d, moving)
    return {
        "speed_rad_s": speed,
        "gap": abs(fits["up"]["M"] - fits["down"]["M"]),
        "max_error": max(f["max_error"] for f in fits.values()),
        "fits": fits,
        "theta1": t1,
        "theta2": t2,
        "direction": d,
        "moving": moving,
        "friction_state": np.array(recz),
    }


def _runs(
    ctx: Context, key: str, conditions: list[tuple[float, float, float | None]]
) -> list[dict[str, Any]]:
    return ctx.once(f"004/{key}", lambda: [position_transmission(*c) for c in conditions])


def _by_bend(ctx: Context) -> list[dict[str, Any]]:
    return _runs(ctx, "bend", [(wr, DEFAULT_SPEED, None) for wr in WRAPS_RAD])


def _by_speed(ctx: Context) -> list[dict[str, Any]]:
    """Sec. IV's velocity runs (bend π, as the text says; Table 2 is then read at 0.06 rad/s,
    see ``DEFAULT_SPEED``)."""
    return _runs(ctx, "speed", [(math.pi, v, None) for v in SPEEDS_RAD_S])


TABLE2_GAPS = (0.364, 0.484, 0.585)  # Table 2: M(R.C.) - M(R.A.) at pi/2, pi, 3pi/2
TABLE1_GAPS = (0.206, 0.363, 0.477)  # Table 1: M(R.C.) - M(R.A.) at 0.02, 0.04, 0.06 rad/s

NOTE = (
    f"seed 004's bench on our law (tendon_sheath.SEED004_BENCH: single tendon, sheath stiffness, "
    f"routing curvature and mu fitted to Tables 1-2, estimate), 1 kg load at an estimated "
    f"{LEVER_M:g} m lever, motor triangle ±π/4 from θ1 = θ2, eq. 19 fitted to the moving phases"
)


def _vs_table(gaps: list[float], table: tuple[float, ...]) -> str:
    return ", ".join(
        f"{g:.3g}/{t:.3g} ({100 * g / t:.0f} %)" for g, t in zip(gaps, table, strict=True)
    )


def gap_vs_bend(ctx: Context) -> Measured:
    gaps = [r["gap"] for r in _by_bend(ctx)]
    return Measured(
        ours=gaps,
        text="gap "
        + " → ".join(f"{g:.3g}" for g in gaps)
        + " rad (π/2, π, 3π/2); ours/Table 2: "
        + _vs_table(gaps, TABLE2_GAPS),
        details={"fits": [r["fits"] for r in _by_bend(ctx)], "table_2": TABLE2_GAPS},
        note=NOTE + f"; at {DEFAULT_SPEED:g} rad/s (Table 2's speed, read from Table 1)",
    )


def gap_vs_velocity(ctx: Context) -> Measured:
    gaps = [r["gap"] for r in _by_speed(ctx)]
    return Measured(
        ours=gaps,
        text="gap " + " → ".join(f"{g:.4g}" for g in gaps) + " rad (0.02, 0.04, 0.06 rad/s); "
        "ours/Table 1: " + _vs_table(gaps, TABLE1_GAPS),
        details={"fits": [r["fits"] for r in _by_speed(ctx)], "table_1": TABLE1_GAPS},
        note=NOTE + "; the speed enters through the velocity-strengthening friction "
        "|v|/(|v| + v0) (friction_speed_rad_s = 0.118 rad/s, fitted with the bench's other "
        "three parameters to both tables' six gaps, so this trend is partly by construction)",
    )


# The joint's "small-sized magnetic encoder" (Sec. II-B) read through a coarse resolution: the
# seed names neither the encoder nor its resolution; 10 bits is the coarsest such encoders
# commonly have (estimate), used only to size what quantisation alone adds to eq. 19's error
JOINT_ENCODER_BITS = 10


def max_error_read(run: dict[str, Any], bits: int) -> float:
    """Eq. 19's maximal error (both directions) with the joint angle read by an encoder of
    ``bits`` per turn (theta_2 rounded to its count) instead of exactly."""
    if bits < 1:
        raise ValueError(f"encoder bits must be >= 1, got {bits}")
    q = 2.0 * math.pi / 2**bits
    t1, d, moving = run["theta1"], run["direction"], run["moving"]
    t2 = np.round(run["theta2"] / q) * q
    err = 0.0
    for sel in ((d > 0.0) & moving, (d < 0.0) & moving):
        coef = np.polyfit(t2[sel], t1[sel], 2)
        err = max(err, float(np.max(np.abs(np.polyval(coef, t2[sel]) - t1[sel]))))
    return err


def eq19_max_error(ctx: Context) -> Measured:
    runs = _by_bend(ctx) + _by_speed(ctx)
    errs = [r["max_error"] for r in runs]
    read = [max_error_read(r, JOINT_ENCODER_BITS) for r in runs]
    return Measured(
        ours=errs,
        text=f"M.E. {min(errs):.3g}…{max(errs):.3g} rad; with θ2 read by a "
        f"{JOINT_ENCODER_BITS}-bit encoder {min(read):.3g}…{max(read):.3g} rad",
        details={"max_error_rad": errs, f"max_error_{JOINT_ENCODER_BITS}bit_rad": read},
        note="each condition's maximal error (both directions) at the three bends and speeds; "
        "our transmission is noise-free, quasi-static, and its joint encoder needs no "
        "compensation (eq. 15), so eq. 19 fits it closer than the paper's measurements. "
        f"Quantisation is not the missing part: a {JOINT_ENCODER_BITS}-bit joint encoder "
        "(estimate, the coarsest common one; the seed names no resolution) adds at most "
        f"{max(b - a for a, b in zip(errs, read, strict=True)):.2g} rad; the paper's "
        "0.021–0.055 rad need a systematic joint-encoder error (its eq. 15 compensates an "
        "uncalibrated magnetic encoder with a quadratic) or dynamics the quasi-static bench "
        "leaves out, neither sized in the text",
    )


def error_greatest_at_reversal(ctx: Context) -> Measured:
    """Sec. V-B: the cycle at total bend pi/2 (``_by_bend``); per recorded step the distance of
    theta_1 to the nearer of eq. 19's two fitted branches at the joint's angle; where the
    largest lies (a reversal's dwell: the joint static, phases C/F, or a moving phase)."""
    r = _by_bend(ctx)[0]
    t1, t2, moving = r["theta1"], r["theta2"], r["moving"]
    branch = [np.polyval([r["fits"][b][k] for k in ("P", "Q", "M")], t2) for b in ("up", "down")]
    err = np.minimum(np.abs(t1 - branch[0]), np.abs(t1 - branch[1]))
    i = int(np.argmax(err))
    dwell = not bool(moving[i])
    return Measured(
        ours=[dwell],
        text=f"largest nearer-branch error {err[i]:.3g} rad at θ2 = {t2[i]:+.3g} rad, "
        + ("in a reversal's dwell" if dwell else "in a moving phase")
        + f"; largest in the moving phases {float(np.max(err[moving])):.3g} rad",
        details={"max_error_rad": float(err[i]), "at_theta2_rad": float(t2[i])},
        note=NOTE + "; total bend π/2 (Sec. III), Algorithm 2's nearer branch",
    )


def error_vs_bend(ctx: Context) -> Measured:
    errs = [r["max_error"] for r in _by_bend(ctx)]
    return Measured(ours=errs, text="M.E. " + " → ".join(f"{e:.3g}" for e in errs) + " rad")


def plate_radius(ctx: Context) -> Measured:
    _, ts = _ts()
    tr, _ = _ts()
    block = tr.block({"wrap_rad": math.pi})
    # the law's capstan integral: mu * (total curvature angle); no radius enters
    k = [ts.branch_stiffness_pull(block, 0.0), ts.branch_stiffness_release(block, 0.0)]
    return Measured(
        ours=0.0,
        text="0 rad: the law reads only the total bend angle (∫κ dx), not the radius",
        details={"k_pull": k[0], "k_release": k[1]},
    )


def tendon_radius(ctx: Context) -> Measured:
    runs = _runs(ctx, "tendon", [(math.pi, DEFAULT_SPEED, r) for r in TENDON_RADII_M])
    grid = np.linspace(-0.6, 0.6, 121)
    worst = 0.0
    for branch in ("up", "down"):
        curves = [np.polyval([r["fits"][branch][k] for k in ("P", "Q", "M")], grid) for r in runs]
        for c in curves[1:]:
            worst = max(worst, float(np.max(np.abs(c - curves[0]))))
    return Measured(
        ours=worst,
        text=f"largest difference between the radii's curves {worst:.3g} rad",
        note="tendon radius 1.0, 1.2, 1.5 mm at total bend π",
    )


def bandwidth_vs_wrap(ctx: Context) -> Measured:
    """Joint-3 torque response on the held arm per total bend; its -3 dB point read as a Bode
    plot is (against the response's own low-frequency level: the capstan's stick band passes
    only part of a small torque command to the joint, so the level itself is below 1)."""
    from fsarm_sim.engine.model import Gains, SimConfig
    from fsarm_sim.studies.arm_metrics import minus_3db, torque_bandwidth

    bw, low = [], []
    for wrap in WRAPS_RAD:
        cfg = SimConfig(
            transmission="tendon-sheath",
            transmission_params=(("wrap_rad", wrap),),
            gains=Gains(gain_schedule=False),
        )
        b = torque_bandwidth(cfg, 0.0, backend=ctx.backend)
        bw.append(float(minus_3db(b.freq_hz, b.gain, float(b.gain[0]))))
        low.append(float(b.gain[0]))
    return Measured(
        ours=bw,
        text=" → ".join(f"{b:.3g}" for b in bw)
        + " Hz (total bend π/2, π, 3π/2); low-frequency gain "
        + " → ".join(f"{g:.2g}" for g in low),
        details={"low_frequency_gain": low},
        note="joint-3 torque on the held arm through seed 004's dual-encoder position loop "
        "(the controller's stiffness fixed at the straight value), joint 2 straight; -3 dB "
        "against the response's low-frequency level. The joint end carries the tension after "
        "the sheath's friction, and a small command inside the capstan's stick band barely "
        "reaches the joint (the gain's level)",
    )


def _battery(ctx: Context) -> Any:
    def run() -> Any:
        from fsarm_sim.engine.model import SimConfig
        from fsarm_sim.studies.collision import run_battery

        return run_battery(SimConfig(transmission="tendon-sheath"), backend=ctx.backend)

    return ctx.once("004/battery", run)


def collision_detection(ctx: Context) -> Measured:
    """Seed 004's Algorithm 1 as written (eq. 19 identified at the run's load, delta rule) on
    the battery's runs at that load; the momentum observer on the same runs in the text."""
    b = _battery(ctx)
    if b.position_model is None:
        return Measured(ours=[False, False], text=f"not run: {b.position_model_skipped}")
    same_load = [r for r in b.detection_alg1 if r.skipped is None and r.run != "p2p-payload"]
    hit = [r for r in same_load if r.contact_s is not None]
    detected = bool(hit) and all(r.detected_s is not None for r in hit)
    # the claim: no alarm on the collision-free runs; a hit run's alarms after its contact are
    # re-alarms of that hit (the sheath's friction holds the hit's deflection, and Algorithm 1's
    # hold/resume re-triggers), reported beside it
    free = [r for r in same_load if r.contact_s is None]
    clean = bool(free) and all((r.false_alarms or 0) == 0 for r in free)
    after_hit = sum((r.false_alarms or 0) for r in hit)
    delays = [r.delay_s for r in hit if r.delay_s is not None]
    other = [r for r in b.detection_alg1 if r.run == "p2p-payload" and r.skipped is None]
    obs_hit = [r for r in b.detection if r.contact_s is not None and r.delay_s is not None]
    text = (
        "Algorithm 1: "
        + ("detected" if detected else "missed")
        + (f" after {1000 * delays[0]:.0f} ms" if delays else "")
        + f", false alarms {sum((r.false_alarms or 0) for r in free)} on {len(free)} "
        "collision-free run(s)"
        + f", {after_hit} re-alarm(s) after the hit"
        + f" (delta_a {b.position_model.threshold_rad:.3g} rad)"
    )
    if other:
        text += f"; at another payload (p2p-payload) {other[0].false_alarms} false alarm(s)"
    if obs_hit:
        text += f"; observer on the same hit: {1000 * (obs_hit[0].delay_s or 0.0):.0f} ms"
    return Measured(
        ours=[detected, clean],
        text=text,
        details={"threshold_rad": b.position_model.threshold_rad},
        note="eq. 19 identified without disturbance at the runs' load (no payload), as the seed "
        "identifies at its one load; a run with another payload is outside that model",
    )


def hand_guiding(ctx: Context) -> Measured:
    """Seed 004's Algorithm 2 (the motor follows the joint to the no-load relation) on the
    hand-guide scenario; the observer + admittance loop on the same scenario in the note."""
    b = _battery(ctx)
    g = b.guiding_alg2
    if g is None:
        return Measured(ours=[False] * 5, text=f"not run: {b.guiding_skipped}")
    cycles = g.cycles()
    text = f"Algorithm 2, {cycles} cycle(s): " + "; ".join(
        f"push {p['mean_push_nm']:+.3g} N·m → {p['travel_rad']:+.3g} rad (motor's "
        f"share {p['motor_share']:.2f}), then {p['speed_after_release_rad_s']:.3g} rad/s, "
        f"drift {p['drift_after_release_rad']:+.3g} rad"
        for p in g.pushes
    )
    note = "the joint-3 reference follows the joint encoder, so the motor goes to the "
    note += "controller's no-load relation at the measured angle (its law copy for eq. 19); "
    note += "the hand (25 N on the flange, 1 s pushes) is an estimate, the seed gives no force. "
    note += "A push moves the joint only ~2° a second: the joint moves only as far as the "
    note += "tendon stretches (τ_h/K, K ≈ 1.4e4 N·m/rad at the joint for the arm's steel tendon "
    note += "and rigid sheath) and the motor's position loop follows that stretch at its gain "
    note += "(60 rad/s, an estimate: the seed prints no gains), so the joint drifts at "
    note += "≈ 60 τ_h/K ≈ 0.04 rad/s. The seed's bench is ~100× softer (Sec. III: a steel "
    note += "tendon of 0.6 mm radius, 1.2 m long, on a 25 mm pulley: EA r²/L ≈ 120 N·m/rad at "
    note += "E = 200 GPa, before the sheath's own give), so the same loop would follow a hand "
    note += "~100× faster there"
    if b.guiding is not None:
        note += "; observer + admittance on the same pushes: travel " + ", ".join(
            f"{p['travel_rad']:+.3g} rad" for p in b.guiding.pushes
        )
    ours = [g.follows(), cycles >= HAND_CYCLES, g.motor_follows(), g.holds(), g.stays()]
    return Measured(ours=ours, text=text, note=note)


def capstan_ratio(ctx: Context) -> Measured:
    tr, ts = _ts()
    worst = 0.0
    for wrap in WRAPS_RAD:
        block = tr.block({"wrap_rad": wrap})
        mu = float(block[tr.param_names().index("mu")])
        expected = math.exp(mu * wrap)
        worst = max(worst, abs(ts.capstan_ratio(mu, wrap) / expected - 1.0))
        ratio = ts.compliance_release(block, 0.0) / ts.compliance_pull(block, 0.0)
        worst = max(worst, abs(ratio / expected - 1.0))
    return Measured(ours=worst, text=f"largest relative error {worst:.2g}")


def geometry(ctx: Context) -> Measured:
    tr, _ = _ts()
    block = tr.block()
    names = tr.param_names()

    def val(name: str) -> float:
        return float(block[names.index(name)])

    checks = [
        abs(val("tendon_radius_m") - 0.0006) < 1e-12,
        abs(val("sheath_length_m") - 0.8) < 1e-12,
        abs(val("tendon_length_m") - 1.2) < 1e-12,
        abs(val("wrap_rad") - math.pi / 2.0) < 1e-9,
        abs(val("pulley_radius_m") - 0.025) < 1e-12,
    ]
    return Measured(
        ours=checks,
        text=f"r_t {1000 * val('tendon_radius_m'):g} mm, L_s {val('sheath_length_m'):g} m, "
        f"L_t {val('tendon_length_m'):g} m, Θ {val('wrap_rad'):.4g} rad, "
        f"r {1000 * val('pulley_radius_m'):g} mm",
    )


def pull_only(ctx: Context) -> Measured:
    """Seed 004's single tendon (``single_tendon`` = 1): no torque for a slack tendon."""
    tr, ts = _ts()
    block = tr.block({"single_tendon": 1.0})
    act = np.zeros(3)
    tau = [float(ts.torque_nm(block, x, 0.0, 0.0, act, 0)) for x in (-0.001, -0.01, -0.05)]
    taut = float(ts.torque_nm(block, 0.01, 0.0, 0.0, act, 0))
    slack_free = all(abs(t) < 1e-12 for t in tau) and taut > 0.0
    return Measured(
        ours=[slack_free],
        text="single tendon, torque at twist −1, −10, −50 mrad: "
        + ", ".join(f"{t:.3g}" for t in tau)
        + f" N·m (+10 mrad: {taut:.3g} N·m)",
        note="the arm's joint 3 defaults to a pull-pull pair (single_tendon = 0) so that it can "
        "be driven both ways",
    )


SEC3_WRAP_RAD = math.pi / 2.0  # Sec. III: "The whole bending angle ... is designed to pi/2 rad"
SEC3_PERIOD_S = 90.0  # Sec. III: theta_1 = pi/4 sin(pi/45 t - pi/2): 2 pi / (pi/45) = 90 s


def eq23_gap(ctx: Context) -> Measured:
    """Sec. III's validation run (the sine, bend pi/2) on the bench; eq. 19 fitted per
    direction as eq. 23 was; the branches' gap at theta_2 = 0."""
    peak = AMPLITUDE_RAD * 2.0 * math.pi / SEC3_PERIOD_S
    r = ctx.once(
        "004/eq23",
        lambda: position_transmission(SEC3_WRAP_RAD, peak, sine_period_s=SEC3_PERIOD_S),
    )
    f = r["fits"]
    return Measured(
        ours=r["gap"],
        text=f"gap {r['gap']:.3g} rad: up {f['up']['P']:.3g}θ² + {f['up']['Q']:.3g}θ + "
        f"{f['up']['M']:.3g}, down {f['down']['P']:.3g}θ² + {f['down']['Q']:.3g}θ + "
        f"{f['down']['M']:.3g} (M.E. {r['max_error']:.3g} rad)",
        details={"fits": f},
        note=NOTE.replace("motor triangle", "motor sine (Sec. III, period 90 s)"),
    )


MEASURES: dict[str, MeasureFn] = {
    "error_greatest_at_reversal": error_greatest_at_reversal,
    "eq23_gap": eq23_gap,
    "pull_only": pull_only,
    "bandwidth_vs_wrap": bandwidth_vs_wrap,
    "gap_vs_bend": gap_vs_bend,
    "gap_vs_velocity": gap_vs_velocity,
    "eq19_max_error": eq19_max_error,
    "error_vs_bend": error_vs_bend,
    "plate_radius": plate_radius,
    "tendon_radius": tendon_radius,
    "collision_detection": collision_detection,
    "hand_guiding": hand_guiding,
    "capstan_ratio": capstan_ratio,
    "geometry": geometry,
}
