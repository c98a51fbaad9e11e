"""RTCA: a flexible shaft modelled as in seed 001 (Rodriguez-Cianca et al., Mechatronics 2019).

Source: /work/shared/seeds/001_874b1e7feae8d04a.txt, Sec. 3.3 eq. 1-4, Table 1, Sec. 5 eq. 5.
The measured shaft is a MasterFlex08 (S.S. White), 8 mm x 865 mm (Table 1; Sec. 2.2 says 0.80 m,
Table 1 says L = 865 mm - the model belongs to Table 1's shaft, kept as published), nominal
torque 6 N*m (Sec. 2.2).

Torque-twist law per twist sign (eq. 1, Table 1; Fourier series of order 1 for x >= 0 and 3 for
x < 0, the paper's ``Δθ`` in degrees converted to rad here: ``omega_SI = omega_deg * 180/pi``)::

    F(x) = a0 + sum_n a_n cos(n omega x) + b_n sin(n omega x)          (static part of eq. 1)
    tau  = scale * mu(phi_B, sign x) * (F(x) - F_sign(0) + c x')       (eq. 1 with eq. 3 / eq. 5)

* ``F_sign(0)``: the paper forced both branches through the origin; the printed, rounded
  coefficients miss it by 1.0 and 2.0 mN*m, so each branch is shifted by its own value at zero
  (as :mod:`fsarm_sim.plant.effects.nonlinear_stiffness` does).
* Dead zone: after that shift the printed x < 0 branch still runs the wrong way for
  |x| < 0.0253 rad (1.45 deg): up to +2.4 mN*m (the size of the rounding miss) with a stiffness
  down to -0.43 N*m/rad at 0. There the torque is held at 0 - a 1.45 deg dead zone, which the
  paper reports on its shaft (Sec. 4.1.1, 6.2: play between core and end connectors) - so the
  law never has negative stiffness. The x >= 0 branch is monotonic from 0 and needs none.
* Fitted range: the characterisation kept the output torque within +-5 N*m (Sec. 3.2), so the
  data behind Table 1 end where each branch reaches 5 N*m: x = +0.9055 rad (51.9 deg) and
  -1.3259 rad (-76.0 deg). Outside, the law is continued **linearly with the end slope** (a
  Fourier series turns over outside its data: the positive branch would peak at 93 deg).
* ``c x'``: Table 1's dissipative term, c = 0.00003 N*m per deg/s for both signs (SI:
  1.719e-3 N*m*s/rad). Eq. 3 multiplies the whole of eq. 1, so mu scales it too. (Eq. 2 prints
  ``+ c Δθ'`` inside the stiffness as well - a misprint: it is not part of dF/dx.)
* Sign: x >= 0 is the stiffer branch (up to 8.0 N*m/rad against 4.33 N*m/rad for x < 0), i.e.
  the tighten-outer-layer (TOL) direction of Sec. 3.1 ("will provide the highest stiffness").

Bend scaling mu (eq. 3 for bend radius R, eq. 5 for bend angle phi with ``L_bend = phi R``).
The text gives mu = 1 straight and, at the bend of largest loss (R = 250 mm), mu = 0.705 for
TOL and 0.82 for LOL ("torque loss of 29.5 % and 18 %", Sec. 6.1); the other mu values of
Fig. 7 and the mu(phi) look-up table of Sec. 5.1 are only in figures, not in the text. Here:

* the bend angle the kernel receives is joint 2's angle ``phi_B = q2`` (the shaft is routed over
  joint 2, seed 000); it maps to the paper's bend radius through ``R = L_bend / |phi_B|`` with
  the bend length ``L_bend = 255 mm`` of seed 001's knee set-up (Sec. 5.1, the shaft bent over a
  hinge joint, symmetric about it) - **an estimate of the routing geometry on the arm**;
* mu falls linearly with curvature ``1/R`` (= linearly with bend angle, as seed 000 eq. 3/8 and
  seed 001's linear-interpolation look-up table) from 1 (straight) to the R = 250 mm values,
  reached at ``|phi_B| = L_bend / 0.25 m = 1.02 rad``; at tighter bends it is **held** at those
  values (the paper's R = 150 mm showed less loss than 250 mm but was its least accurate fit,
  so the largest published loss is kept).

Stiffness (eq. 4): ``K = scale * mu * dF/dx``. ``scale`` (default 1 = the published shaft)
multiplies the torque: n identical shafts in parallel; the published shaft's nominal torque is
6 N*m.

Internal friction that grows with the bend (one state, ``slip``): what eq. 3 leaves unexplained
(Sec. 3.3: NRMSE 0.32 % straight, rising to 2.3 % at R = 150 mm, over the +-5 N*m span; the
paper puts it down to "a friction increase within the internal layers", Sec. 3.1, 6.1) is carried
as one elasto-slip (Maxwell-slip) element in parallel with the law
(:mod:`fsarm_sim.plant.effects.maxwell_slip`), whose slip torque grows with the route's wrap like
a rope on a capstan (:mod:`fsarm_sim.plant.effects.bend_friction`, the flexible shaft's factor)::

    tau_f = scale k z,   |z| <= g(phi_B) f_0 / k,   g = exp(mu_b |phi_B|),   k = f_0 / z_0

* ``f_0 = slip_f`` = 0.0032 * 10 N*m = 0.032 N*m: an elasto-slip loop of half-width f leaves a
  residual of RMS ~f about the centre line a static fit finds, so the straight NRMSE (0.32 % of
  the 10 N*m span) sizes it - an upper bound (the fit's own shape error is in it too); **estimate**.
* ``mu_b`` = ln(2.3 / 0.32) / phi(150 mm) = 1.97 / 1.70 = 1.16 /rad, with phi = L_bend / R and
  L_bend = 255 mm (Sec. 5.1): the growth that takes 0.032 N*m to 0.23 N*m at R = 150 mm;
  **estimate** (Sec. 3.2's X-Y rig bent an unknown length of the 865 mm shaft: were all of it bent,
  phi(150 mm) = 5.8 rad and mu_b = 0.34 /rad). Beyond the tightest measured bend (R = 150 mm,
  phi = 1.7 rad: BEND_MAX_RAD) the band is held, not extrapolated.
* ``z_0`` = 5 deg: the twist over which the friction sticks straight (**estimate**, pre-sliding:
  the stuck element's stiffness, 0.37 N*m/rad, stays well below the law's slope past its 1.45 deg
  dead zone, >= 1 N*m/rad beyond 3 deg - eq. 4 fits the measured stiffness with NRMSE 0.32 %,
  no visible friction stiffening; with 1 deg, 1.8 N*m/rad, the arm's small-signal loop ran on
  the element, not on Table 1). k stays fixed and the band grows with the bend (as the
  flexible shaft's elements), so the element's stored energy does not read the bend and
  ``bend_torque_nm`` is the law's alone.
* The virtual torque sensor (eq. 3) does not see it; ``slip_f = 0`` switches it off
  (``HYSTERESIS_OFF``, ``CONSERVATIVE``).
"""

from __future__ import annotations

import math

import numpy as np

from fsarm_sim.plant.effects import bend_friction, maxwell_slip
from fsarm_sim.plant.roots import bisect
from fsarm_sim.plant.transmissions.base import (
    Bounds,
    FloatArray,
    Param,
    TransmissionError,
    any_finite,
    check_bounds,
    fill_block,
    non_negative,
    positive,
)

NAME = "rtca"
TITLE = "RTCA flexible shaft (MasterFlex08, Fourier torque-twist law, bend scaling mu)"
SOURCE = (
    "seed 001 (Rodriguez-Cianca et al. 2019, RTCA): eq. 1 (Fourier series per twist sign with "
    "dissipative term c), eq. 3-5 (bend scaling mu(R or phi, sign)), Table 1 (MasterFlex08, "
    "8 mm x 865 mm), Sec. 3.2 (+-5 N*m characterisation range), Sec. 6.1 (mu at R = 250 mm); "
    "Sec. 3.3 NRMSE 0.32 -> 2.3 % sizes a bend-dependent friction element (estimate)"
)
STATES: tuple[str, ...] = ("slip",)  # the friction element's deflection z, rad (module doc)
# parameter values that switch every dissipation of the law off (energy checks)
CONSERVATIVE: dict[str, float] = {"c": 0.0, "slip_f": 0.0}
# Effects(slip=False) / hysteresis off: the values that switch the friction element off
HYSTERESIS_OFF: dict[str, float] = {"slip_f": 0.0}
ROUTED_OVER_JOINT2 = True

DEG_PER_RAD = 180.0 / math.pi
FIT_TORQUE_NM = 5.0  # Sec. 3.2: the characterisation kept |T_s| <= 5 N*m
R_MU_M = 0.250  # Sec. 6.1: the bend radius of the published mu values (largest loss)
NOMINAL_TORQUE_NM = 6.0  # Sec. 2.2: MasterFlex08 nominal torque
SHAFT_LENGTH_M = 0.865  # Table 1: MasterFlex08, 8 mm x 865 mm
# The law covers the shaft's 6 N*m nominal torque (Sec. 2.2) on both sides at the largest bend
# loss (x = -1.87 rad on the soft side), beyond Table 1's data only by its linear extension.
TWIST_RANGE_RAD = 2.0

# Table 1 as printed (Δθ in degrees, torque in N*m): a0, a1, a2, a3, b1, b2, b3, omega [1/deg]
TABLE1_POS = (4.20200, -4.20100, 0.0, 0.0, 0.16220, 0.0, 0.0, 0.03322)
TABLE1_NEG = (-3.10700, 2.33500, 0.74840, 0.02559, -1.48700, 0.36180, 0.19760, 0.04357)
TABLE1_C_NM_PER_DEG_S = 0.00003

# parameter-block indices
I_POS = 0  # 8 coefficients of the x >= 0 branch (a0..a3, b1..b3, omega [1/rad])
I_NEG = 8  # 8 coefficients of the x < 0 branch
I_C = 16
I_MU_POS = 17
I_MU_NEG = 18
I_L_BEND = 19
I_XFIT_POS = 20
I_XFIT_NEG = 21
I_XDEAD_NEG = 22
I_SCALE = 23
I_EXTEND = 24  # 1: beyond the fitted range, continue linearly with the end slope; 0: the series
I_SLIP_F = 25  # straight slip torque of the friction element (0: off)

# the friction element (module docstring): all estimates from Sec. 3.3's NRMSE
SLIP_F_NM = 0.0032 * 10.0  # NRMSE 0.32 % (straight) of the +-5 N*m span
NRMSE_R150 = 0.023  # Sec. 3.3: NRMSE at R = 150 mm
BEND_LENGTH_M = 0.255  # Sec. 5.1: bend length L = 255 mm
BEND_FRICTION_PER_RAD = math.log(NRMSE_R150 / 0.0032) / (BEND_LENGTH_M / 0.150)  # 1.16 /rad
PRESLIDING_RAD = math.radians(5.0)  # estimate (module doc): twist over which it sticks
BEND_MAX_RAD = BEND_LENGTH_M / 0.150  # 1.7 rad: the tightest measured bend, R = 150 mm


class RtcaParamError(TransmissionError):
    """An RTCA parameter or argument outside what the seed-001 law allows."""


# ------------------------------------------------------------------ kernels (scalar math only)


def _series(tr: FloatArray, o: int, x: float) -> float:
    """Static part of eq. 1 for the branch at block offset ``o`` (x in rad)."""
    w = tr[o + 7]
    return (
        tr[o]
        + tr[o + 1] * math.cos(w * x)
        + tr[o + 2] * math.cos(2.0 * w * x)
        + tr[o + 3] * math.cos(3.0 * w * x)
        + tr[o + 4] * math.sin(w * x)
        + tr[o + 5] * math.sin(2.0 * w * x)
        + tr[o + 6] * math.sin(3.0 * w * x)
    )


def _series_slope(tr: FloatArray, o: int, x: float) -> float:
    """d/dx of :func:`_series` (eq. 2 without the misprinted c term), N*m/rad."""
    w = tr[o + 7]
    return w * (
        -tr[o + 1] * math.sin(w * x)
        - 2.0 * tr[o + 2] * math.sin(2.0 * w * x)
        - 3.0 * tr[o + 3] * math.sin(3.0 * w * x)
        + tr[o + 4] * math.cos(w * x)
        + 2.0 * tr[o + 5] * math.cos(2.0 * w * x)
        + 3.0 * tr[o + 6] * math.cos(3.0 * w * x)
    )


def _series_energy(tr: FloatArray, o: int, x: float) -> float:
    """Integral of ``_series(s) - _series(0)`` over s from 0 to x, J."""
    w = tr[o + 7]
    f0 = _series(tr, o, 0.0)
    return (
        (tr[o] - f0) * x
        + tr[o + 1] * math.sin(w * x) / w
        + tr[o + 2] * math.sin(2.0 * w * x) / (2.0 * w)
        + tr[o + 3] * math.sin(3.0 * w * x) / (3.0 * w)
        + tr[o + 4] * (1.0 - math.cos(w * x)) / w
        + tr[o + 5] * (1.0 - math.cos(2.0 * w * x)) / (2.0 * w)
        + tr[o + 6] * (1.0 - math.cos(3.0 * w * x)) / (3.0 * w)
    )


def _offset(x: float) -> int:
    return I_POS if x >= 0.0 else I_NEG


def _end(tr: FloatArray, x: float) -> float:
    """The end of the fitted range on the side of ``x`` (signed, rad)."""
    return tr[I_XFIT_POS] if x >= 0.0 else -tr[I_XFIT_NEG]


def _in_dead_zone(tr: FloatArray, x: float) -> bool:
    """True where the printed x < 0 series runs the wrong way (held at zero torque)."""
    return x < 0.0 and -x <= tr[I_XDEAD_NEG]


def _beyond(tr: FloatArray, x: float, xe: float) -> bool:
    """Past the fitted range on this side, with the linear continuation switched on."""
    return tr[I_EXTEND] > 0.5 and abs(x) > abs(xe)


def straight_elastic_nm(tr: FloatArray, x: float) -> float:
    """Straight-shaft static torque ``F(x) - F(0)`` (beyond the fit: ``extend_linear``).

    The one implementation of seed 001's Table 1 curve: the ``nonlinear_stiffness`` effect's
    MasterFlex08 law evaluates this function on the published block."""
    if _in_dead_zone(tr, x):
        return 0.0
    o = _offset(x)
    xe = _end(tr, x)
    f0 = _series(tr, o, 0.0)
    if not _beyond(tr, x, xe):
        return _series(tr, o, x) - f0
    return _series(tr, o, xe) - f0 + _series_slope(tr, o, xe) * (x - xe)


def straight_stiffness(tr: FloatArray, x: float) -> float:
    """d(straight_elastic_nm)/dx, N*m/rad (the end slope beyond the fitted range)."""
    if _in_dead_zone(tr, x):
        return 0.0
    o = _offset(x)
    xe = _end(tr, x)
    if not _beyond(tr, x, xe):
        return _series_slope(tr, o, x)
    return _series_slope(tr, o, xe)


def straight_energy_j(tr: FloatArray, x: float) -> float:
    """Integral of :func:`straight_elastic_nm` from 0 to x, J."""
    if _in_dead_zone(tr, x):
        return 0.0
    o = _offset(x)
    xe = _end(tr, x)
    e_dead = 0.0
    if x < 0.0:
        e_dead = _series_energy(tr, o, -tr[I_XDEAD_NEG])  # the wrong-way area left out
    if not _beyond(tr, x, xe):
        return _series_energy(tr, o, x) - e_dead
    dx = x - xe
    f_end = _series(tr, o, xe) - _series(tr, o, 0.0)
    return (
        _series_energy(tr, o, xe) - e_dead + f_end * dx + 0.5 * _series_slope(tr, o, xe) * dx * dx
    )


def mu_factor(tr: FloatArray, x: float, bend: float) -> float:
    """Bend scaling mu(phi_B, sign x) of eq. 3/5: linear in curvature, held beyond R = R_mu."""
    mu_bent = tr[I_MU_POS] if x >= 0.0 else tr[I_MU_NEG]
    frac = abs(bend) * R_MU_M / tr[I_L_BEND]  # = (1/R) / (1/R_mu) with R = L_bend/|phi_B|
    if frac > 1.0:
        frac = 1.0
    return 1.0 - (1.0 - mu_bent) * frac


def bend_torque_nm(tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int) -> float:
    """-dV/dphi_B of :func:`potential_j`: mu falls linearly with the curvature up to R_mu."""
    if bend == 0.0 or abs(bend) * R_MU_M / tr[I_L_BEND] >= 1.0:
        return 0.0  # straight (the two sides' slopes cancel) or the loss already saturated
    mu_bent = tr[I_MU_POS] if x >= 0.0 else tr[I_MU_NEG]
    dmu_db = -(1.0 - mu_bent) * R_MU_M / tr[I_L_BEND] * math.copysign(1.0, bend)
    return -tr[I_SCALE] * dmu_db * straight_energy_j(tr, x)


def slip_k(tr: FloatArray) -> float:
    """The friction element's stiffness ``f_0 / z_0`` (0: off), N*m/rad per unit ``scale``."""
    return tr[I_SLIP_F] / PRESLIDING_RAD


def slip_band_rad(tr: FloatArray, bend: float) -> tuple[float, float]:
    """(lower, upper) deflection of the friction element at this bend (``maxwell_slip``)."""
    b = abs(bend)
    if b > BEND_MAX_RAD:
        b = BEND_MAX_RAD
    g = bend_friction.factor(b, BEND_FRICTION_PER_RAD)
    return maxwell_slip.band_rad(slip_k(tr), tr[I_SLIP_F], 1.0, g)


def torque_nm(
    tr: FloatArray, x: float, xdot: float, bend: float, act: FloatArray, a0: int
) -> float:
    """Transmitted torque: ``scale mu (F(x) - F(0) + c x')`` (eq. 1 and 3/5) plus the friction
    element ``scale k z`` (module docstring)."""
    tau = tr[I_SCALE] * mu_factor(tr, x, bend) * (straight_elastic_nm(tr, x) + tr[I_C] * xdot)
    if tr[I_SLIP_F] > 0.0:
        tau += tr[I_SCALE] * maxwell_slip.element_torque_nm(act[a0], slip_k(tr))
    return tau


def sensor_torque_nm(tr: FloatArray, x: float, bend: float) -> float:
    """The virtual torque sensor of seed 001 Fig. 8: eq. 3/5 from the twist and the bend."""
    return tr[I_SCALE] * mu_factor(tr, x, bend) * straight_elastic_nm(tr, x)


def stiffness_nm_per_rad(tr: FloatArray, x: float, bend: float) -> float:
    """Eq. 4: ``scale mu dF/dx``."""
    return tr[I_SCALE] * mu_factor(tr, x, bend) * straight_stiffness(tr, x)


def state_rate(
    tr: FloatArray,
    x: float,
    xdot: float,
    bend: float,
    act: FloatArray,
    a0: int,
    i: int,
    vm: float = 0.0,
) -> float:
    """dz/dt of the friction element (slot 0): stick inside its band at this bend, slide at its
    edge (``maxwell_slip.banded_rate``); 0 for unused slots or with the element off."""
    if i != 0 or tr[I_SLIP_F] <= 0.0:
        return 0.0
    lo, hi = slip_band_rad(tr, bend)
    return maxwell_slip.banded_rate(act[a0], xdot, lo, hi)


def potential_j(tr: FloatArray, x: float, bend: float, act: FloatArray, a0: int) -> float:
    """Elastic energy at fixed bend: ``scale mu * integral of (F - F(0))`` plus the friction
    element's spring (which does not read the bend)."""
    v = tr[I_SCALE] * mu_factor(tr, x, bend) * straight_energy_j(tr, x)
    if tr[I_SLIP_F] > 0.0:
        v += tr[I_SCALE] * maxwell_slip.element_potential_j(act[a0], slip_k(tr))
    return v


# ------------------------------------------------------------------ Python side: data and helpers


def _table1_si(c: tuple[float, ...]) -> tuple[float, ...]:
    """Table 1 coefficients with omega converted from 1/deg to 1/rad."""
    return (*c[:7], c[7] * DEG_PER_RAD)


def curve(twist_rad: float, sign: float) -> float:
    """Eq. 1's static part with Table 1's coefficients of branch ``sign`` (+1: x >= 0, -1: x < 0).

    Exactly as printed: no shift to the origin, no extension beyond the fitted range.
    """
    if sign not in (1.0, -1.0):
        raise RtcaParamError(f"sign must be +1 or -1 (the Table 1 branch), got {sign!r}")
    c = _table1_si(TABLE1_POS if sign > 0 else TABLE1_NEG)
    w = c[7]
    return c[0] + sum(
        c[n] * math.cos(n * w * twist_rad) + c[n + 3] * math.sin(n * w * twist_rad)
        for n in (1, 2, 3)
    )


def _fit_end_rad(sign: float) -> float:
    """|twist| where the shifted Table 1 branch reaches FIT_TORQUE_NM (bisection, monotonic)."""
    f0 = curve(0.0, sign)
    # both branches pass 5 N*m well below 2 rad and are monotonic up to it
    return bisect(lambda m: not abs(curve(sign * m, sign) - f0) >= FIT_TORQUE_NM, 0.0, 2.0)


def _dead_end_rad(sign: float) -> float:
    """|twist| of the last sign error of the shifted Table 1 branch near zero (0 if none)."""
    f0 = curve(0.0, sign)

    def wrong(m: float) -> bool:
        return sign * (curve(sign * m, sign) - f0) < 0.0

    last = 0.0
    for i in range(1, 201):  # scan 0..0.2 rad (11.5 deg) in 1 mrad steps
        if wrong(i * 1e-3):
            last = i * 1e-3
    if last == 0.0:
        return 0.0
    return bisect(wrong, last, last + 1e-3)


_T1 = "seed 001 Table 1 (MasterFlex08 8 mm x 865 mm)"
_POS = _table1_si(TABLE1_POS)
_NEG = _table1_si(TABLE1_NEG)
_NAMES = ("a0", "a1", "a2", "a3", "b1", "b2", "b3", "omega")


_COEF_WHY = (
    "a coefficient of Table 1's Fourier fit: either sign, as fitted; the law it gives must rise "
    "through the fitted range (checked across parameters)"
)
_MU_WHY = (
    "(0, 1]: bending only loses torque (eq. 3/5: mu = 1 straight, 0.705 / 0.82 at R = 250 mm); "
    "0 would transmit nothing"
)
_XFIT_WHY = (
    "the end of the fitted range: > 0, <= the law's twist range TWIST_RANGE_RAD = 2 rad "
    "(Sec. 3.2: the data end at 5 N*m)"
)
_POSITIVE_SCALE_WHY = (
    "a torque multiplier (shafts in parallel): > 0 (0 transmits nothing, < 0 reverses the "
    "spring); a stiffness too high for the timestep is refused at build"
)


def _coefficient_params(side: str, c: tuple[float, ...], label: str) -> tuple[Param, ...]:
    out = []
    for name, value in zip(_NAMES, c, strict=True):
        if name == "omega":
            out.append(
                Param(
                    f"omega_{side}",
                    value,
                    "1/rad",
                    f"{_T1}, {label}: omega printed per degree, times 180/pi",
                    positive(
                        "the Fourier series' base frequency: > 0 (its sign is carried by the "
                        "b_n; 0 makes the series a constant, no spring)"
                    ),
                )
            )
        else:
            out.append(
                Param(
                    f"{name}_{side}",
                    value,
                    "N*m",
                    f"{_T1}, {label} ('-' read as 0)",
                    any_finite(_COEF_WHY),
                )
            )
    return tuple(out)


PARAMS: tuple[Param, ...] = (
    *_coefficient_params("pos", _POS, "column Δθ >= 0"),
    *_coefficient_params("neg", _NEG, "column Δθ < 0"),
    Param(
        "c",
        TABLE1_C_NM_PER_DEG_S * DEG_PER_RAD,
        "N*m*s/rad",
        f"{_T1}: c = 0.00003 N*m per deg/s (both signs), times 180/pi",
        non_negative("eq. 1's c x' must be dissipative: c >= 0 (< 0 would feed energy in)"),
    ),
    Param(
        "mu_pos",
        0.705,
        "-",
        "seed 001 Sec. 6.1: mu of TOL (x >= 0) at R = 250 mm",
        Bounds(0.0, 1.0, _MU_WHY, lo_open=True),
    ),
    Param(
        "mu_neg",
        0.82,
        "-",
        "seed 001 Sec. 6.1: mu of LOL (x < 0) at R = 250 mm",
        Bounds(0.0, 1.0, _MU_WHY, lo_open=True),
    ),
    Param(
        "bend_length",
        0.255,
        "m",
        "seed 001 Sec. 5.1 bend length L = 255 mm over a hinge joint; estimate of the routing "
        "over joint 2 (R = L / |phi_B|)",
        positive(
            "a length: > 0 (R = L / |phi_B|), <= 0.865 m, the shaft's length (Table 1): the bent "
            "part cannot be longer than the shaft",
            SHAFT_LENGTH_M,
        ),
    ),
    Param(
        "x_fit_pos",
        _fit_end_rad(1.0),
        "rad",
        "twist where Table 1's x >= 0 branch reaches 5 N*m, the characterisation limit of "
        "seed 001 Sec. 3.2; linear with the end slope beyond",
        positive(_XFIT_WHY, TWIST_RANGE_RAD),
    ),
    Param(
        "x_fit_neg",
        _fit_end_rad(-1.0),
        "rad",
        "|twist| where Table 1's x < 0 branch reaches -5 N*m (seed 001 Sec. 3.2)",
        positive(_XFIT_WHY, TWIST_RANGE_RAD),
    ),
    Param(
        "x_dead_neg",
        _dead_end_rad(-1.0),
        "rad",
        "|twist| below which Table 1's x < 0 branch has the wrong sign (printed coefficients); "
        "torque held at 0 there: a dead zone, as reported in seed 001 Sec. 4.1.1 / 6.2",
        non_negative(
            "a dead-zone width: >= 0 (0 = none), and below x_fit_neg (inside the fitted range)",
            TWIST_RANGE_RAD,
            hi_open=True,
        ),
    ),
    Param(
        "scale",
        1.0,
        "-",
        "torque multiplier: 1 = the published shaft (n shafts in parallel)",
        positive(_POSITIVE_SCALE_WHY),
    ),
    Param(
        "extend_linear",
        1.0,
        "-",
        "beyond the fitted range (Sec. 3.2: the characterisation kept |T_s| <= 5 N*m): 1 = continue "
        "linearly with the end slope (default: a Fourier series turns over outside its data), "
        "0 = keep the printed series (it reaches 8.4 N*m at +90 deg)",
        Bounds(0.0, 1.0, "a switch: 0 (printed series) or 1 (linear continuation)"),
    ),
    Param(
        "slip_f",
        SLIP_F_NM,
        "N*m",
        "friction element's slip torque straight: Sec. 3.3 NRMSE 0.32 % of the +-5 N*m span "
        "(estimate: the fit's unexplained residual taken as internal friction); grows with the "
        "bend as exp(1.16 |phi_B|) (effects.bend_friction, 2.3 % at R = 150 mm); 0 = off",
        non_negative("a slip torque: >= 0 (0 switches the bend-dependent friction off)"),
    ),
)


def state_limits(tr: FloatArray) -> list[tuple[float, float] | None]:
    """A fixed outer range for MuJoCo's clamp: the element's widest band (held from
    BEND_MAX_RAD on); the band itself moves with the bend inside the rate law."""
    return [slip_band_rad(tr, BEND_MAX_RAD)]


def max_stiffness(tr: FloatArray) -> float:
    """Largest stiffness over the law's twist range and bends, plus the stuck element (N*m/rad)."""
    xs = np.linspace(-TWIST_RANGE_RAD, TWIST_RANGE_RAD, 401)
    k_law = max(stiffness_nm_per_rad(tr, float(x), 0.0) for x in xs)  # mu <= 1: straight is max
    return float(k_law + tr[I_SCALE] * slip_k(tr))


def default_block(overrides: dict[str, float] | None = None) -> FloatArray:
    """The parameter block (length N_TR) with the published values and ``overrides``."""
    return fill_block(NAME, PARAMS, overrides, validate=validate, error=RtcaParamError)


def validate(tr: FloatArray) -> None:
    """Raise :class:`RtcaParamError` for a block the kernels cannot evaluate meaningfully.

    Each parameter's own range is checked from ``PARAMS``' bounds (base.fill_block); here the
    checks across parameters (run again in full, so a block built by hand is checked too).
    """
    check_bounds(NAME, PARAMS, tr, RtcaParamError)
    if tr[I_XDEAD_NEG] >= tr[I_XFIT_NEG]:
        raise RtcaParamError(
            f"transmission {NAME!r}: x_dead_neg = {float(tr[I_XDEAD_NEG])!r} rad must be below "
            f"x_fit_neg = {float(tr[I_XFIT_NEG])!r} rad (the dead zone lies inside the fitted "
            "range)"
        )
    # the static law must rise through the fitted range on both sides (a spring): a falling
    # stretch would have negative stiffness where the controller and twist_for_torque need > 0
    for sign, end in ((1.0, float(tr[I_XFIT_POS])), (-1.0, float(tr[I_XFIT_NEG]))):
        for x in np.linspace(0.0, end, 201)[1:]:
            k = straight_stiffness(tr, sign * float(x))
            if k < 0.0:
                side = "pos" if sign > 0 else "neg"
                raise RtcaParamError(
                    f"transmission {NAME!r}: the Fourier coefficients of the x "
                    f"{'>=' if sign > 0 else '<'} 0 branch (a0_{side}..b3_{side}, omega_{side}) "
                    f"give a falling torque (stiffness {k:.3g} N*m/rad) at twist "
                    f"{sign * float(x):.4g} rad inside the fitted range: the law must rise "
                    "there (a spring)"
                    + (
                        f"; on this side the dead zone x_dead_neg = {float(tr[I_XDEAD_NEG])!r} "
                        "rad holds the torque at 0 where the printed series runs the wrong way"
                        if sign < 0
                        else ""
                    )
                )


def bend_radius_m(bend_rad: float, tr: FloatArray | None = None) -> float:
    """The paper's bend radius for joint-2 angle ``bend_rad``: ``L_bend / |phi_B|`` (inf if 0)."""
    tr = default_block() if tr is None else tr
    if not math.isfinite(bend_rad):
        raise RtcaParamError(f"bend angle must be finite, got {bend_rad!r}")
    return math.inf if bend_rad == 0.0 else float(tr[I_L_BEND] / abs(bend_rad))


def bend_held_from_rad(tr: FloatArray | None = None) -> float:
    """The bend beyond which the law no longer reads it: mu reaches the R = R_mu values at
    ``|phi_B| = L_bend / R_mu`` (1.02 rad = 58.4 deg by default) and is held there."""
    tr = default_block() if tr is None else tr
    return float(tr[I_L_BEND] / R_MU_M)


def mu(bend_rad: float, sign: float, tr: FloatArray | None = None) -> float:
    """mu(phi_B, sign) of eq. 5 as implemented (see the module docstring)."""
    if sign not in (1.0, -1.0):
        raise RtcaParamError(f"sign must be +1 or -1, got {sign!r}")
    tr = default_block() if tr is None else tr
    return float(mu_factor(tr, 0.5 * sign, bend_rad))


def fitted_range_rad(tr: FloatArray | None = None) -> tuple[float, float]:
    """(most negative, most positive) twist covered by Table 1's data."""
    tr = default_block() if tr is None else tr
    return float(-tr[I_XFIT_NEG]), float(tr[I_XFIT_POS])


def rating_nm(tr: FloatArray) -> float:
    """Nominal torque of the published shaft (Sec. 2.2, 6 N*m) times ``scale``."""
    return NOMINAL_TORQUE_NM * float(tr[I_SCALE])
