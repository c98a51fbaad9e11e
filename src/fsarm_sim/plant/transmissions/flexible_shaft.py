"""The flexible shaft (seed 000): the default joint-3 transmission, a transmission like the others.

eq. 3/8 asymmetric series stiffness per twist sign, falling with |phi_B|
(:mod:`fsarm_sim.plant.effects.series_stiffness`), eq. 1 damping, and the Maxwell-slip series
hysteresis (:mod:`fsarm_sim.plant.effects.maxwell_slip`): three elasto-slip elements in parallel with
the spring, whose deflections are this transmission's states (``data.act``, limited to +-f/k so
that they slip). ``model.write_params`` fills the block from the run's
:class:`fsarm_sim.plant.shaft.ShaftParams` (the coefficient file), so the kernels, the analyses and the
controller's virtual torque sensor all read the shaft through this interface. The shaft is routed
over joint 2: its stored energy depends on the bend, and the kernels apply the matching
-dV/dphi_B on joint 2 from :func:`potential_j`, as for every routed transmission.

Eq. 3 is what seed 000's series test identifies: the slope of a line fitted to the measured
loops (Sec. III-B1), and the slip elements add to that slope (while stuck they are springs). So
the plant's spring carries eq. 3 *minus* the elements' apparent stiffness in that test
(``slip_app_*``, straight value and slope in |phi_B| per side; coefficient file
``series.maxwell_slip.apparent_stiffness_*``), and the paper's procedure on the simulated bench
returns eq. 3 (``fsarm reproduce``: 000-series-roundtrip). With every element off (k = 0) the
spring is eq. 3 itself. The controller's virtual torque sensor (:func:`sensor_torque_nm`) is eq. 8
with eq. 3, as on the robot.
"""

from __future__ import annotations

from typing import Any

from fsarm_sim.plant.effects import bend_friction, maxwell_slip, series_stiffness
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.plant.transmissions.base import (
    FloatArray,
    Param,
    TransmissionError,
    any_finite,
    non_negative,
    positive,
)

NAME = "flexible-shaft"
TITLE = "Flexible shaft, asymmetric series stiffness (seed 000)"
SOURCE = "seed 000 eq. 1, 3, 8 (coefficients: src/fsarm_sim/data/shafts.toml, estimates)"
ROUTED_OVER_JOINT2 = True
TWIST_RANGE_RAD = 1.0  # estimate: about 1.5x the twist at rated torque of the default shaft
STATES: tuple[str, ...] = ("slip1", "slip2", "slip3")  # Maxwell-slip element deflections, rad
# parameter values that switch every dissipation of the law off (energy checks)
CONSERVATIVE: dict[str, float] = {
    "b_pos": 0.0,
    "b_neg": 0.0,
    "slip_k1": 0.0,
    "slip_k2": 0.0,
    "slip_k3": 0.0,
}
N_SLIP = 3
I_SLIP_K = 7  # block index of the first element stiffness (then the three slip torques)
I_SLIP_F = I_SLIP_K + N_SLIP  # straight, winding-side slip torques
I_SLIP_RN = I_SLIP_F + N_SLIP  # unwinding-side slip torque / winding-side
I_BEND_MU = I_SLIP_RN + 1  # bend-friction coefficient mu_b of the route (effects.bend_friction)
I_APP = I_BEND_MU + 1  # elements' apparent stiffness: k_pos, s_pos, k_neg, s_neg (module doc)


_K_WHY = (
    "eq. 3's straight stiffness: > 0 (a spring); a stiffness too high for the timestep is "
    "refused at build"
)
_S_WHY = (
    "eq. 3's slope in |phi_B|: either sign as fitted; the stiffness at the largest bend of the "
    "validity range must stay > 0 (checked across parameters)"
)
_B_WHY = "eq. 1 damping must be >= 0 (dissipative; < 0 would feed energy in)"
_APP_WHY = (
    "either sign as calibrated; eq. 3 minus it (the plant's spring) must stay > 0 up to the "
    "largest valid bend (checked across parameters)"
)


def _spring_params(sh: ShaftParams, src: str) -> tuple[Param, ...]:
    """Eq. 1/3's spring and damping, and the rating."""
    return (
        Param(
            "k_pos", sh.k_pos, "N*m/rad", f"eq. 3 winding side, straight; {src}", positive(_K_WHY)
        ),
        Param(
            "s_pos",
            sh.s_pos,
            "N*m/rad^2",
            f"eq. 3 winding side slope in |phi_B|; {src}",
            any_finite(_S_WHY),
        ),
        Param(
            "k_neg", sh.k_neg, "N*m/rad", f"eq. 3 unwinding side, straight; {src}", positive(_K_WHY)
        ),
        Param(
            "s_neg", sh.s_neg, "N*m/rad^2", f"eq. 3 unwinding side slope; {src}", any_finite(_S_WHY)
        ),
        Param("b_pos", sh.damping_pos, "N*m*s/rad", f"eq. 1 B_p; {src}", non_negative(_B_WHY)),
        Param("b_neg", sh.damping_neg, "N*m*s/rad", f"eq. 1 B_n; {src}", non_negative(_B_WHY)),
        Param(
            "rating_nm",
            sh.rating_nm,
            "N*m",
            f"nominal torque of the shaft; {src}",
            positive("a torque rating: > 0 (it sizes test signals and flags overloads)"),
        ),
    )


def _slip_params(sh: ShaftParams, src: str) -> tuple[Param, ...]:
    """The Maxwell-slip elements, their bend and side scaling, and their apparent stiffness in
    seed 000's series test."""
    return (
        *(
            Param(
                f"slip_k{i + 1}",
                sh.slip_k[i],
                "N*m/rad",
                f"Maxwell-slip element {i + 1} stiffness (0: element off); {src}",
                non_negative("an element stiffness: >= 0 (0 switches the element off)"),
            )
            for i in range(N_SLIP)
        ),
        *(
            Param(
                f"slip_f{i + 1}",
                sh.slip_f[i],
                "N*m",
                f"Maxwell-slip element {i + 1} slip torque, straight, winding side; {src}",
                non_negative("a slip torque: >= 0; > 0 wherever the element's k > 0"),
            )
            for i in range(N_SLIP)
        ),
        Param(
            "slip_unwinding_ratio",
            sh.slip_unwinding_ratio,
            "-",
            f"unwinding-side / winding-side slip torque (seed 000: more internal friction on the "
            f"winding side); {src}",
            positive("a ratio of two slip torques: > 0"),
        ),
        Param(
            "bend_friction_per_rad",
            sh.bend_friction_per_rad,
            "1/rad",
            f"capstan-like growth of the slip torques with |phi_B| (effects.bend_friction); {src}",
            non_negative("a friction coefficient: >= 0 (0: no growth with the bend)"),
        ),
        *(
            Param(
                f"slip_app_{name}",
                sh.slip_apparent[i],
                unit,
                f"slip elements' apparent stiffness in seed 000's series test ({what}), taken "
                f"off eq. 3's spring while an element is on; {src}",
                any_finite(_APP_WHY),
            )
            for i, (name, unit, what) in enumerate(
                (
                    ("k_pos", "N*m/rad", "winding side, straight"),
                    ("s_pos", "N*m/rad^2", "winding side, slope in |phi_B|"),
                    ("k_neg", "N*m/rad", "unwinding side, straight"),
                    ("s_neg", "N*m/rad^2", "unwinding side, slope in |phi_B|"),
                )
            )
        ),
    )


def _params() -> tuple[Param, ...]:
    sh = load_catalogue().shaft()
    src = f"catalogue default shaft {sh.diameter_mm:g} x {sh.length_mm:g} mm (estimates)"
    return (*_spring_params(sh, src), *_slip_params(sh, src))


PARAMS = _params()
# Effects(slip=False): the values that switch its hysteresis (the slip elements) off
HYSTERESIS_OFF: dict[str, float] = {f"slip_k{i + 1}": 0.0 for i in range(N_SLIP)}


def params_from_shaft(sh: ShaftParams) -> dict[str, float]:
    """Its parameters from the run's catalogue shaft (``SimConfig.shaft``: diameter, length and
    bend read through the coefficient file), by :data:`PARAMS` name."""
    out = {
        "k_pos": sh.k_pos,
        "s_pos": sh.s_pos,
        "k_neg": sh.k_neg,
        "s_neg": sh.s_neg,
        "b_pos": sh.damping_pos,
        "b_neg": sh.damping_neg,
        "rating_nm": sh.rating_nm,
        "slip_unwinding_ratio": sh.slip_unwinding_ratio,
        "bend_friction_per_rad": sh.bend_friction_per_rad,
    }
    for i in range(N_SLIP):
        out[f"slip_k{i + 1}"] = sh.slip_k[i]
        out[f"slip_f{i + 1}"] = sh.slip_f[i]
    for name, value in zip(("k_pos", "s_pos", "k_neg", "s_neg"), sh.slip_apparent, strict=True):
        out[f"slip_app_{name}"] = value
    return {k: float(v) for k, v in out.items()}


BEND_LIMIT_RAD = load_catalogue().bend_limit_rad  # the default file's validity.bend_rad


def validate(tr: FloatArray) -> None:
    """Cross-parameter checks: eq. 3 stays > 0 on both sides up to the largest valid bend; a slip
    element with stiffness has a slip torque."""
    validate_slip(tr)
    for side, k, slope in (("pos", tr[0], tr[1]), ("neg", tr[2], tr[3])):
        k_bent = float(k + min(float(slope), 0.0) * BEND_LIMIT_RAD)
        if k_bent <= 0.0:
            raise TransmissionError(
                f"transmission {NAME!r}: k_{side} = {float(k)!r} N*m/rad with s_{side} = "
                f"{float(slope)!r} N*m/rad^2 gives stiffness {k_bent:.4g} N*m/rad <= 0 at the "
                f"largest valid bend {BEND_LIMIT_RAD:.4g} rad: eq. 3 must stay > 0 there"
            )
    kp, sp, kn, sn = spring(tr)
    for side, k, slope in (("pos", kp, sp), ("neg", kn, sn)):
        for bend in (0.0, BEND_LIMIT_RAD):
            if k + slope * bend <= 0.0:
                raise TransmissionError(
                    f"transmission {NAME!r}: eq. 3 minus the slip elements' apparent stiffness "
                    f"(slip_app_*) leaves the {side} spring at {float(k + slope * bend):.4g} "
                    f"N*m/rad <= 0 at bend {bend:.4g} rad: the apparent stiffness must stay "
                    "below eq. 3"
                )


def validate_slip(tr: FloatArray) -> None:
    for i in range(N_SLIP):
        if tr[I_SLIP_K + i] > 0.0 and tr[I_SLIP_F + i] <= 0.0:
            raise TransmissionError(
                f"transmission {NAME!r}: slip element {i + 1} has stiffness "
                f"{float(tr[I_SLIP_K + i])!r} N*m/rad but slip torque {float(tr[I_SLIP_F + i])!r} "
                "N*m: an element with k > 0 needs a slip torque > 0"
            )


def elements_on(tr: Any) -> bool:
    """Whether any slip element has a stiffness (is on)."""
    for i in range(N_SLIP):  # noqa: SIM110 - a plain loop: Numba compiles this law
        if tr[I_SLIP_K + i] > 0.0:
            return True
    return False


def spring(tr: Any) -> tuple[float, float, float, float]:
    """The plant's spring (k_pos, s_pos, k_neg, s_neg): eq. 3 less the elements' apparent
    stiffness while an element is on (module docstring), eq. 3 otherwise."""
    if elements_on(tr):
        return (
            tr[0] - tr[I_APP],
            tr[1] - tr[I_APP + 1],
            tr[2] - tr[I_APP + 2],
            tr[3] - tr[I_APP + 3],
        )
    return (tr[0], tr[1], tr[2], tr[3])


def sensor_torque_nm(tr: Any, x: float, bend: float) -> float:
    return series_stiffness.elastic_torque_nm(x, bend, tr[0], tr[1], tr[2], tr[3])


def stiffness_nm_per_rad(tr: Any, x: float, bend: float) -> float:
    return series_stiffness.stiffness_nm_per_rad(x, bend, tr[0], tr[1], tr[2], tr[3])


def torque_nm(tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int) -> float:
    kp, sp, kn, sn = spring(tr)
    tau = series_stiffness.elastic_torque_nm(
        x, bend, kp, sp, kn, sn
    ) + series_stiffness.damping_torque_nm(x, xdot, tr[4], tr[5])
    for i in range(N_SLIP):
        if tr[I_SLIP_K + i] > 0.0:
            tau += maxwell_slip.element_torque_nm(act[a0 + i], tr[I_SLIP_K + i])
    return tau


def state_rate(
    tr: Any, x: float, xdot: float, bend: float, act: Any, a0: int, i: int, vm: float = 0.0
) -> float:
    """dz_i/dt: stick inside the element's band at this bend, slide at its edge (maxwell_slip)."""
    k = tr[I_SLIP_K + i]
    if k <= 0.0:
        return 0.0
    lo, hi = maxwell_slip.band_rad(
        k, tr[I_SLIP_F + i], tr[I_SLIP_RN], bend_friction.factor(bend, tr[I_BEND_MU])
    )
    return maxwell_slip.banded_rate(act[a0 + i], xdot, lo, hi)


def state_limits(tr: Any) -> list[tuple[float, float] | None]:
    """A fixed outer range for MuJoCo's clamp: the widest band, at just beyond the largest valid
    bend (the band itself moves with the bend inside the rate law)."""
    g = bend_friction.factor(1.01 * BEND_LIMIT_RAD, tr[I_BEND_MU])
    return [
        maxwell_slip.band_rad(tr[I_SLIP_K + i], tr[I_SLIP_F + i], tr[I_SLIP_RN], g)
        for i in range(N_SLIP)
    ]


def initial_states(tr: Any, x: float, bend: float) -> list[float]:
    """Element deflections at the start, at twist ``x``: loaded (within their bands at this bend,
    in order) so that spring + elements hold eq. 8's torque there - the share of eq. 3 that the
    spring does not carry (module docstring). All zero with the elements off or x = 0."""
    kp, sp, kn, sn = spring(tr)
    k_spring = kp + sp * abs(bend) if x >= 0.0 else kn + sn * abs(bend)
    need = (stiffness_nm_per_rad(tr, x, bend) - k_spring) * x
    g = bend_friction.factor(bend, tr[I_BEND_MU])
    out = []
    for i in range(N_SLIP):
        k = tr[I_SLIP_K + i]
        if k <= 0.0:
            out.append(0.0)
            continue
        lo, hi = maxwell_slip.band_rad(k, tr[I_SLIP_F + i], tr[I_SLIP_RN], g)
        z = min(hi, max(lo, need / k))
        need -= k * z
        out.append(float(z))
    return out


def twist_for_torque(tr: Any, tau: float, bend: float) -> float:
    """eq. 8 inverted (linear per side): the twist whose elastic torque is ``tau``."""
    k = (
        tr[0] + tr[1] * abs(bend) if tau >= 0.0 else tr[2] + tr[3] * abs(bend)
    )  # eq. 3 stiffness of the loaded side at this bend
    if k <= 0.0:
        raise TransmissionError(
            f"transmission {NAME!r} has no stiffness left at bend {bend:.3g} rad "
            f"(K = {float(k):.3g} N*m/rad), so it cannot hold {tau:.3g} N*m"
        )
    return float(tau / k)


def bend_torque_nm(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    """-dV/dphi_B: the spring's stiffness falls with |phi_B| (the elements' energy does not read
    it)."""
    _, sp, _, sn = spring(tr)
    return series_stiffness.bend_coupling_torque_nm(x, bend, sp, sn)


def max_stiffness(tr: Any) -> float:
    """The stiffer eq. 3 side straight plus the stuck slip elements (N*m/rad)."""
    return float(max(tr[0], tr[2]) + sum(tr[I_SLIP_K + i] for i in range(N_SLIP)))


def rating_nm(tr: Any) -> float:
    return float(tr[6])


def potential_j(tr: Any, x: float, bend: float, act: Any, a0: int) -> float:
    kp, sp, kn, sn = spring(tr)
    v = series_stiffness.potential_j(x, bend, kp, sp, kn, sn)
    for i in range(N_SLIP):
        if tr[I_SLIP_K + i] > 0.0:
            v += maxwell_slip.element_potential_j(act[a0 + i], tr[I_SLIP_K + i])
    return v
