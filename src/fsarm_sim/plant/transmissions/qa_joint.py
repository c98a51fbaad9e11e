"""DLR QA-Joint (seed 002): exponential quasi-antagonistic spring, preset drive, Coulomb friction.

Source: seed 002_93b61736cab1a199.txt (Eiberger et al., "On joint design with intrinsic variable
compliance: derivation of the DLR QA-Joint"). Twist ``x = theta_m - theta_s`` plays the paper's
elastic deflection ``phi = theta - q`` (eq. 5, 11).

Elastic torque (eq. 13 design, eq. 16 identified; ``b = 15 1/rad``, eq. 12)::

    tau_J(phi, sigma) = a_S exp(b (phi - sigma)) - b_S exp(b (-phi - sigma))          (eq. 16)
    K(phi, sigma)     = b (a_S exp(b (phi - sigma)) + b_S exp(b (-phi - sigma)))      (d tau_J/d phi)
    V(phi, sigma)     = a_S/b (exp(b (phi - sigma)) - exp(-b sigma))
                      + b_S/b (exp(b (-phi - sigma)) - exp(-b sigma))                  (V(0) = 0)

With ``a_S = b_S = 40 N*m`` this is the design law eq. 13; the defaults are the identified row of
Table IV at the default preset. ``sigma`` (rad) is the stiffness preset: *larger sigma = softer*
and it bounds the deflection, ``|phi| <= sigma`` (eq. 11; the mechanical end stop is not modelled,
the exponential simply continues beyond it).

Friction (eq. 19, Table IV): magnitude ``tau_F(phi, sigma) = a_F exp(b (phi - sigma))
+ b_F exp(b (-phi - sigma))``. The paper models it as pure Coulomb, ``sgn(phi')`` (Sec. IV-C,
Fig. 7). Here it sits in parallel with the spring (the clamped-link test of Sec. V measures it as
the half-width of the torque hysteresis), as a Dahl presliding element so that explicit 1 ms steps
stay benign (state slot 1, ``|z| <= 1``, ``delta`` = presliding deflection)::

    dz/dt = (x' - |x'| z) / delta   ( = x'/delta (1 - sgn(x') z), no sign() needed )
    tau   = scale (tau_J(x, sigma) + tau_F(x, sigma) z)

Sign convention: eq. 15 writes ``-tau_F`` on the link; in parallel with the spring the element
must carry ``+tau_F sgn(phi')`` to dissipate (positive loop area), which is what is used here.

Stiffness drive (state slot 0): ``sigma`` follows the commanded preset ``sigma_cmd`` (within
the preset range 3...15 deg, Table III/IV: a command outside ``[sigma_min, sigma_max]`` is refused
when the block is built, see :func:`validate`; the kernels still clamp to the range) through a
first-order lag with time constant
``sigma_tau_s`` (estimate, the paper gives none) limited to ``sigma_rate``, the speed with which
a full-range move settles in 0.12 s (Table III "maximum stiffness adjustment time 0.12 s", Sec.
IV-A "~120 ms for full stiffness range"; :data:`SIGMA_RATE_TABLE_III`)::

    dsigma/dt = clamp((sigma_cmd - sigma) / sigma_tau_s, -sigma_rate, +sigma_rate)

The virtual torque sensor (``sensor_torque_nm``) has no access to the states, so it evaluates
eq. 16 at the commanded preset ``sigma_cmd`` (the state equals it once the drive has settled).
Joint-3 placement: the QA-Joint carries up to ``a_S`` = 23-27 N*m (Table IV) at ``phi = sigma``,
3.2x the 7.1 N*m of the arm's 15 kg sine; ``scale`` (default 1) multiplies every torque.
"""

from __future__ import annotations

import math
from typing import Any

from fsarm_sim.plant.roots import bisect
from fsarm_sim.plant.transmissions.base import (
    FloatArray,
    Param,
    TransmissionError,
    non_negative,
    positive,
)
from fsarm_sim.studies.reproduce.targets import claim_value

NAME = "qa-joint"
TITLE = "DLR QA-Joint: exponential quasi-antagonistic spring with stiffness preset (seed 002)"
SOURCE = (
    "seed 002 (DLR QA-Joint): eq. 12-13, 16 elastic torque, eq. 19 + Table IV friction, "
    "Table III preset range and adjustment time"
)
ROUTED_OVER_JOINT2 = False
TWIST_RANGE_RAD = math.radians(15.0)  # largest elastic deflection of any preset (Table III)
STATES: tuple[str, ...] = ("sigma_rad", "z_friction")
# parameter values that switch every dissipation of the law off (energy checks)
CONSERVATIVE: dict[str, float] = {"a_f": 0.0, "b_f": 0.0}

# Table IV: sigma [deg] -> (a_S, b_S, a_F, b_F) [N*m], identified on the real joint (seed 002).
TABLE_IV: dict[float, tuple[float, float, float, float]] = {
    3.0: (26.2760, 26.2221, 2.5172, 3.8480),
    5.0: (26.6049, 27.1703, 2.6125, 3.2755),
    7.0: (26.8106, 27.8989, 2.9776, 3.1582),
    9.0: (26.4714, 28.4042, 2.3106, 3.0784),
    11.0: (26.3446, 28.6174, 2.8776, 3.3393),
    13.0: (26.0417, 29.1079, 2.4160, 3.3339),
    15.0: (22.7286, 30.1821, 3.3058, 3.3004),
}
DESIGN_A_NM = 40.0  # eq. 12-13: a = 40 N*m
DESIGN_B_PER_RAD = 15.0  # eq. 12-13: b = 15 1/rad
DEFAULT_SIGMA_DEG = 15.0  # softest preset: closest to the flexible shaft's ~10 N*m/rad it replaces
_ROW = TABLE_IV[DEFAULT_SIGMA_DEG]
SIGMA_TAU_S = 0.02  # estimate: the stiffness drive's lag (Param sigma_tau_s)
SETTLE_FRACTION = 0.01  # "settled": within 1 % of the range


def full_range_time_s(rate: float, tau: float = SIGMA_TAU_S) -> float:
    """Time of a full-range preset move (3 -> 15 deg) settled to 1 % of the range under
    ``dsigma/dt = clamp((cmd - sigma) / tau, +-rate)``: the rate-limited leg, then the lag's
    exponential tail, ``(R - rate tau) / rate + tau ln(rate tau / (0.01 R))``."""
    r = math.radians(max(TABLE_IV) - min(TABLE_IV))
    return (r - rate * tau) / rate + tau * math.log(rate * tau / (SETTLE_FRACTION * r))


def rate_for_adjust_time(seconds: float, tau: float = SIGMA_TAU_S) -> float:
    """The drive speed (rad/s) whose full-range move settles in ``seconds``: bisection on
    :func:`full_range_time_s`, which falls monotonically over the speeds where its two legs
    exist (``0.01 R < rate tau <= R``)."""
    r = math.radians(max(TABLE_IV) - min(TABLE_IV))
    lo, hi = SETTLE_FRACTION * r / tau * (1.0 + 1e-9), r / tau
    if not (math.isfinite(seconds) and full_range_time_s(hi, tau) < seconds):
        raise ValueError(
            f"no drive speed settles a full-range preset move in {seconds!r} s (needs > "
            f"{full_range_time_s(hi, tau):.3g} s with a {tau:g} s lag)"
        )
    return bisect(lambda rate: full_range_time_s(rate, tau) > seconds, lo, hi)


# The stiffness drive's speed (rad/s): Table III's "maximum stiffness adjustment time 0.12 s" is
# the time of a full-range move (3...15 deg) settled to 1 % of the range: with the 20 ms lag,
# rate = 2.827 rad/s (162 deg/s). (R / 0.12 s, 100 deg/s, would settle in 0.156 s: the rate limit
# alone is not the whole move.) Read from the calibration claim 002-adjust-time (one source).
SIGMA_RATE_TABLE_III = rate_for_adjust_time(claim_value("002-adjust-time"))


_PRESET_WHY = (
    "a preset is the deflection limit |phi| <= sigma (eq. 11): > 0, <= 90 deg (6x Table III's "
    "largest preset, 15 deg)"
)
_SPRING_WHY = (
    "> 0: each spring of the antagonistic pair pulls (eq. 16; 0 leaves one side without a "
    "spring); a stiffness too high for the timestep is refused at build"
)
_FRICTION_WHY = "a friction level (eq. 19): >= 0 (0 = no friction)"

# parameter block indices (order of PARAMS)
I_SIGMA_CMD = 0
I_A_S = 1
I_B_S = 2
I_A_F = 3
I_B_F = 4
I_B_EXP = 5
I_SIGMA_MIN = 6
I_SIGMA_MAX = 7
I_SIGMA_TAU = 8
I_SIGMA_RATE = 9
I_DELTA = 10
I_SCALE = 11

PARAMS: tuple[Param, ...] = (
    Param(
        "sigma_cmd",
        math.radians(DEFAULT_SIGMA_DEG),
        "rad",
        "commanded stiffness preset; 15 deg = softest preset of Table III/IV (K(0) = 15.6 N*m/rad "
        "with the Table IV row, nearest the flexible shaft it replaces)",
        positive(
            f"{_PRESET_WHY}; and from sigma_min to sigma_max, the drive's preset range",
            math.pi / 2.0,
        ),
    ),
    Param(
        "a_s",
        _ROW[0],
        "N*m",
        "eq. 16 a_S, Table IV row sigma = 15 deg (design eq. 13: 40)",
        positive(_SPRING_WHY),
    ),
    Param(
        "b_s",
        _ROW[1],
        "N*m",
        "eq. 16 b_S, Table IV row sigma = 15 deg (design eq. 13: 40)",
        positive(_SPRING_WHY),
    ),
    Param(
        "a_f",
        _ROW[2],
        "N*m",
        "eq. 19 a_F, Table IV row sigma = 15 deg",
        non_negative(_FRICTION_WHY),
    ),
    Param(
        "b_f",
        _ROW[3],
        "N*m",
        "eq. 19 b_F, Table IV row sigma = 15 deg",
        non_negative(_FRICTION_WHY),
    ),
    Param(
        "b_exp",
        DESIGN_B_PER_RAD,
        "1/rad",
        "eq. 12-13, 16, 19: exponent b = 15 rad^-1",
        positive(
            "> 0: the springs stiffen with deflection (eq. 12); 0 gives a constant torque (no "
            "spring), < 0 a law that softens outward and has no stable centre"
        ),
    ),
    Param(
        "sigma_min",
        math.radians(3.0),
        "rad",
        "Table III phi_max = 3...15 deg; Table IV",
        positive(f"{_PRESET_WHY}; and < sigma_max", math.pi / 2.0),
    ),
    Param(
        "sigma_max",
        math.radians(15.0),
        "rad",
        "Table III phi_max = 3...15 deg; Table IV",
        positive(f"{_PRESET_WHY}; and > sigma_min", math.pi / 2.0),
    ),
    Param(
        "sigma_tau_s",
        SIGMA_TAU_S,
        "s",
        "estimate: stiffness-drive lag; seed 002 gives none (Fig. 12: 'slightly too little "
        "dynamics'); 20 ms is well inside the 0.12 s full-range time (sigma_rate is set with it)",
        positive(
            "a time constant: > 0 (the drive's rate divides by it; 0 is a division by zero), "
            "<= 10 s (Table III: full range in 0.12 s)",
            10.0,
        ),
    ),
    Param(
        "sigma_rate",
        SIGMA_RATE_TABLE_III,
        "rad/s",
        "Table III: a full-range move (3...15 deg) settles to 1 % of the range in 0.12 s with the "
        "20 ms lag (SIGMA_RATE_TABLE_III: 162 deg/s)",
        positive("a rate limit: > 0 (0 freezes the preset drive, < 0 inverts the limit's clamp)"),
    ),
    Param(
        "presliding_rad",
        0.01,
        "rad",
        "estimate: Dahl presliding deflection (not in seed 002); 0.57 deg keeps the presliding "
        "stiffness tau_F/delta below the elastic stiffness at every preset and |x'| dt/delta < 1 "
        "up to 10 rad/s at 1 ms",
        positive(
            "> 0: the Dahl rate divides by it (0 is a division by zero), <= 15 deg, the "
            "joint's largest deflection (TWIST_RANGE_RAD)",
            TWIST_RANGE_RAD,
        ),
    ),
    Param(
        "scale",
        1.0,
        "-",
        "torque scale for the arm (1 = the published joint)",
        positive(
            "a torque multiplier: > 0 (0 transmits nothing, < 0 reverses the springs); a "
            "stiffness too high for the timestep is refused at build"
        ),
    ),
)


def validate(tr: FloatArray) -> None:
    """Cross-parameter checks (each parameter's own range: ``PARAMS``' bounds, base.fill_block).

    The preset range must be a range, and the commanded preset inside it: the drive cannot set a
    preset beyond its end stops, so a command outside is refused here rather than clamped
    silently (the kernels still clamp, for states that overshoot).
    """
    lo, hi, cmd = float(tr[I_SIGMA_MIN]), float(tr[I_SIGMA_MAX]), float(tr[I_SIGMA_CMD])
    if not lo < hi:
        raise TransmissionError(
            f"transmission {NAME!r}: sigma_min = {lo!r} rad must be below sigma_max = {hi!r} rad "
            f"(the drive's preset range, Table III: {math.radians(3.0):.4g} to "
            f"{math.radians(15.0):.4g} rad)"
        )
    if not lo <= cmd <= hi:
        raise TransmissionError(
            f"transmission {NAME!r}: parameter sigma_cmd = {cmd!r} rad "
            f"({math.degrees(cmd):.4g} deg) is outside the preset range sigma_min..sigma_max = "
            f"[{lo:.6g}, {hi:.6g}] rad ([{math.degrees(lo):.4g}, {math.degrees(hi):.4g}] deg): "
            "the stiffness drive cannot set a preset beyond its end stops (Table III)"
        )


# ------------------------------------------------------------------ kernels (Numba-compilable)


def _clamp(v: float, lo: float, hi: float) -> float:
    if v < lo:
        return lo
    if v > hi:
        return hi
    return v


def _sigma_cmd(tr: Any) -> float:
    """The commanded preset, clamped to the preset range."""
    return _clamp(tr[I_SIGMA_CMD], tr[I_SIGMA_MIN], tr[I_SIGMA_MAX])


def valid_twist_rad(tr: Any) -> float:
    """Deflection range of the law for the commanded preset: the end stops at +-sigma."""
    return _sigma_cmd(tr)


def elastic_torque_nm(tr: Any, x: float, sigma: float) -> float:
    """Eq. 16 (eq. 13 with a_S = b_S = 40): centering torque at deflection x and preset sigma."""
    b = tr[I_B_EXP]
    return tr[I_A_S] * math.exp(b * (x - sigma)) - tr[I_B_S] * math.exp(b * (-x - sigma))


def elastic_stiffness(tr: Any, x: float, sigma: float) -> float:
    """d(eq. 16)/dx."""
    b = tr[I_B_EXP]
    return b * (tr[I_A_S] * math.exp(b * (x - sigma)) + tr[I_B_S] * math.exp(b * (-x - sigma)))


def friction_magnitude_nm(tr: Any, x: float, sigma: float) -> float:
    """Eq. 19: Coulomb friction level at deflection x and preset sigma (>= 0 for a_F, b_F >= 0)."""
    b = tr[I_B_EXP]
    return tr[I_A_F] * math.exp(b * (x - sigma)) + tr[I_B_F] * math.exp(b * (-x - sigma))


def elastic_potential_j(tr: Any, x: float, sigma: float) -> float:
    """Integral of eq. 16 from 0 to x."""
    b = tr[I_B_EXP]
    e0 = math.exp(-b * sigma)
    return tr[I_A_S] / b * (math.exp(b * (x - sigma)) - e0) + tr[I_B_S] / b * (
        math.exp(b * (-x - sigma)) - e0
    )


def sensor_torque_nm(tr: Any, x: float, bend: float) -> float:
    return tr[I_SCALE] * elastic_torque_nm(tr, x, _sigma_cmd(tr))


def stiffness_nm_per_rad(tr: Any, x: float, bend: float) -> float:
    return tr[I_SCALE] * elastic_stiffness(tr, x, _sigma_cmd(tr))


def torque_nm(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int) -> float:
    sigma = _clamp(act[a0], tr[I_SIGMA_MIN], tr[I_SIGMA_MAX])
    z = _clamp(act[a0 + 1], -1.0, 1.0)
    return tr[I_SCALE] * (elastic_torque_nm(tr, x, sigma) + friction_magnitude_nm(tr, x, sigma) * z)


def sigma_rate(tr: Any, sigma: float) -> float:
    """Stiffness drive: first-order lag toward sigma_cmd, rate-limited (Table III: 0.12 s)."""
    v = (_sigma_cmd(tr) - sigma) / tr[I_SIGMA_TAU]
    return _clamp(v, -tr[I_SIGMA_RATE], tr[I_SIGMA_RATE])


def dahl_rate(xdot: float, z: float, delta: float) -> float:
    """Dahl presliding state: dz/dt = (x' - |x'| z) / delta; tends to sgn(x'), stays in [-1, 1]."""
    return (xdot - abs(xdot) * z) / delta


def state_rate(
    tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int, i: int, vm: float = 0.0
) -> float:
    if i == 0:
        return sigma_rate(tr, act[a0])
    if i == 1:
        return dahl_rate(xdot, _clamp(act[a0 + 1], -1.0, 1.0), tr[I_DELTA])
    return 0.0


def bend_torque_nm(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    """-dV/dphi_B: 0, the law does not read the bend (not routed over joint 2)."""
    return 0.0


def potential_j(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    sigma = _clamp(act[a0], tr[I_SIGMA_MIN], tr[I_SIGMA_MAX])
    return tr[I_SCALE] * elastic_potential_j(tr, x, sigma)


# ------------------------------------------------------------------ Python side


def state_limits(tr: Any) -> list[tuple[float, float] | None]:
    """sigma within the preset range (Table III); the Dahl state within [-1, 1]."""
    return [(float(tr[I_SIGMA_MIN]), float(tr[I_SIGMA_MAX])), (-1.0, 1.0)]


def initial_states(tr: Any, x: float, bend: float) -> list[float]:
    """Preset settled at its command, friction element relaxed."""
    return [float(_sigma_cmd(tr)), 0.0]


def table_iv_overrides(sigma_deg: float) -> dict[str, float]:
    """Parameter overrides for one identified row of Table IV (preset and its four coefficients)."""
    if sigma_deg not in TABLE_IV:
        raise TransmissionError(
            f"Table IV of seed 002 has rows for sigma = {sorted(TABLE_IV)} deg, got {sigma_deg!r}"
        )
    a_s, b_s, a_f, b_f = TABLE_IV[sigma_deg]
    return {"sigma_cmd": math.radians(sigma_deg), "a_s": a_s, "b_s": b_s, "a_f": a_f, "b_f": b_f}


def design_overrides() -> dict[str, float]:
    """The design law eq. 13 (a_S = b_S = 40 N*m), friction kept."""
    return {"a_s": DESIGN_A_NM, "b_s": DESIGN_A_NM}


def rating_nm(tr: Any) -> float:
    """Torque the springs hold at the end stop of the commanded preset (x = sigma), scaled."""
    sigma = _sigma_cmd(tr)
    return float(tr[I_SCALE] * elastic_torque_nm(tr, sigma, sigma))
