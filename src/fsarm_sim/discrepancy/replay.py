"""Fast replay of the bench setups: the nominal model plus effects, driven by the recorded input.

The same constitutive kernels as the simulator (:mod:`fsarm_sim.plant.effects` - eq. 3/8 series
stiffness, Maxwell-slip elements, visco-elastic branches, and the new friction, damping, backlash,
nonlinear-stiffness, delay and offset modules) compiled with Numba into two loops:

* :func:`replay_static` - blocked series bench and parallel bench. The output is a function of the
  recorded input's history only (operators with internal states), evaluated sample by sample.
* :func:`replay_inertia` - series bench with a load inertia: the load angle is integrated
  (semi-implicit Euler, implicit Coulomb friction, substeps so that ``h * omega_n <= 0.05``) with
  the input interpolated linearly between samples.

How the recorded columns are used: series bench ``u = theta_m`` (input), ``s = theta_s``
(blocked: the measured constant), bend ``phi_b`` per sample; parallel bench ``u = phi_b``. Rates
and accelerations of the input come from Savitzky-Golay derivatives (15 ms / 31 ms windows,
cubic, :mod:`.replay_inputs`), so that encoder quantisation does not turn into velocity spikes.

Internal states start relaxed (slip elements and branches unloaded at the first sample), which is
also what ``fsarm_sim.studies.bench`` does for MuJoCo replays. :class:`FeatureBank` exposes the same
operators column by column for the linear least-squares fits (seed 002 eq. 17-18).

Compiled code is cached in ``$FSARM_CACHE_DIR`` (default ``~/.cache/fsarm-sim``) under a name that
hashes this file and the effect modules, so an edit of either recompiles.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import math
import os
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numba
import numpy as np
import numpy.typing as npt
from numba.core import config as numba_config
from numba.extending import register_jitable

from fsarm_sim.discrepancy.benchmodel import MAX_ELEMENTS, BenchModel
from fsarm_sim.discrepancy.replay_inputs import ReplayInputs, derivative
from fsarm_sim.paramblocks import Decl, Layout
from fsarm_sim.plant.effects import (
    backlash,
    conduit_viscoelastic,
    coulomb_friction,
    delay,
    maxwell_slip,
    nonlinear_stiffness,
    sensor_offset,
    series_stiffness,
    viscous_damping,
)
from fsarm_sim.plant.transmissions import rtca

FloatArray = npt.NDArray[np.float64]

_KERNEL_MODULES: tuple[ModuleType, ...] = (
    rtca,  # seed 001 Table 1 (nonlinear_stiffness' MasterFlex08 law evaluates its curve)
    backlash,
    coulomb_friction,
    conduit_viscoelastic,
    delay,
    maxwell_slip,
    nonlinear_stiffness,
    sensor_offset,
    series_stiffness,
    viscous_damping,
)


def _register(mods: tuple[ModuleType, ...]) -> None:
    """Make the effect functions callable from compiled code (same flag as fsarm_sim.engine.native)."""
    for mod in mods:
        for _, fn in inspect.getmembers(mod, inspect.isfunction):
            if fn.__module__ == mod.__name__ and not getattr(fn, "_fsarm_jitable", False):
                register_jitable(error_model="numpy")(fn)
                fn._fsarm_jitable = True  # type: ignore[attr-defined]


_register(_KERNEL_MODULES)


def _cache_path() -> Path:
    env = os.environ.get("FSARM_CACHE_DIR")
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(env) if env else (Path(xdg) if xdg else Path.home() / ".cache") / "fsarm-sim"
    h = hashlib.sha256()
    for mod in (*_KERNEL_MODULES, inspect.getmodule(_register)):
        assert mod is not None
        h.update(Path(inspect.getfile(mod)).read_bytes())
    h.update(numba.__version__.encode())
    return base / f"discrepancy-{h.hexdigest()[:16]}"


@contextlib.contextmanager
def _numba_cache_in(path: Path) -> Iterator[None]:
    old = getattr(numba_config, "CACHE_DIR")  # noqa: B009  (not in numba's type stubs)
    setattr(numba_config, "CACHE_DIR", str(path))  # noqa: B010
    try:
        yield
    finally:
        setattr(numba_config, "CACHE_DIR", old)  # noqa: B010


# ------------------------------------------------------------------------- parameter vector
# Declared block by block (fsarm_sim.paramblocks, as the simulator's kernel vector in
# fsarm_sim.kernels.layout): offsets are computed from the declarations, never typed by hand.
REPLAY_LAYOUT = Layout()
_r = REPLAY_LAYOUT.block(
    "spring",
    (
        Decl("k_pos", "N*m/rad", 0.0, "eq. 3/8 winding side (parallel bench: K_b)"),
        Decl("s_pos", "N*m/rad^2", 0.0, "its slope in |phi_B| (parallel bench: 0)"),
        Decl("k_neg", "N*m/rad", 0.0, "eq. 3/8 unwinding side (parallel bench: K_b)"),
        Decl("s_neg", "N*m/rad^2", 0.0, "its slope in |phi_B|"),
        Decl("c2_pos", "N*m", 0.0, "nonlinear stiffness, quadratic term, x >= 0"),
        Decl("c3_pos", "N*m", 0.0, "nonlinear stiffness, cubic term, x >= 0"),
        Decl("c2_neg", "N*m", 0.0, "nonlinear stiffness, quadratic term, x < 0"),
        Decl("c3_neg", "N*m", 0.0, "nonlinear stiffness, cubic term, x < 0"),
        Decl("x_ref", "rad", 1.0, "reference deflection of the nonlinear terms"),
    ),
)
R_KP, R_SP, R_KN, R_SN = _r["k_pos"], _r["s_pos"], _r["k_neg"], _r["s_neg"]
R_A2P, R_A3P, R_A2N, R_A3N = _r["c2_pos"], _r["c3_pos"], _r["c2_neg"], _r["c3_neg"]
R_XREF = _r["x_ref"]
_r = REPLAY_LAYOUT.block("backlash", backlash.KERNEL_PARAMS)
R_BL_W, R_BL_C = _r["width_rad"], _r["center_rad"]
_r = REPLAY_LAYOUT.block(
    "shaft_friction",
    (
        Decl("b", "N*m*s/rad", 0.0, "viscous damping in parallel with the spring"),
        Decl("f_c", "N*m", 0.0, "Coulomb friction in parallel with the spring"),
        Decl("delta_c", "rad", 1e-3, "its presliding deflection"),
    ),
)
R_B_SH, R_F_SH, R_DELTA_C = _r["b"], _r["f_c"], _r["delta_c"]
R_OFF_OUT = REPLAY_LAYOUT.one("output_offset", "offset", "N*m", "output sensor offset")
_r = REPLAY_LAYOUT.block(
    "load",
    (
        Decl("j", "kg*m^2", 0.0, "load (series bench) or link (parallel bench) inertia"),
        Decl("b_load", "N*m*s/rad", 0.0, "load viscous damping"),
        Decl("f_load", "N*m", 0.0, "load Coulomb friction"),
    ),
)
R_J, R_B_LOAD, R_F_LOAD = _r["j"], _r["b_load"], _r["f_load"]
R_N_SLIP = REPLAY_LAYOUT.one("slip_count", "n", "count", "Maxwell-slip elements in use")
R_SLIP_K = REPLAY_LAYOUT.array("slip_k", MAX_ELEMENTS, "N*m/rad", "element stiffnesses")
R_SLIP_D = REPLAY_LAYOUT.array("slip_d", MAX_ELEMENTS, "rad", "element slip deflections")
R_N_VE = REPLAY_LAYOUT.one("ve_count", "n", "count", "visco-elastic branches in use")
R_VE_K = REPLAY_LAYOUT.array("ve_k", MAX_ELEMENTS, "N*m/rad", "branch stiffnesses")
R_VE_TAU = REPLAY_LAYOUT.array("ve_tau", MAX_ELEMENTS, "s", "branch relaxation times")
R_USE_ACC = REPLAY_LAYOUT.one(
    "use_acc", "use", "on/off", "1: add J x input acceleration (parallel bench link)"
)
R_MF = REPLAY_LAYOUT.one(
    "masterflex08", "twist_scale", "-", "> 0: spring = seed 001 MasterFlex08 at twist x it"
)
N_R = REPLAY_LAYOUT.size
del _r

# Presliding deflection of a Coulomb element when a model does not state one: a few micrometres
# of contact presliding (Dahl-type) at the ~4.5 mm radius of a 9 mm shaft core -> ~1 mrad
# (estimate; the workflow fits its own value).
DEFAULT_DELTA_C = 1e-3
MAX_H_OMEGA = 0.05  # substep so that h * omega_n stays below this (semi-implicit Euler accuracy)


def presliding_delta(x_noise_rad: float) -> float:
    """Smallest presliding deflection worth fitting: twice the input's noise (finer would only
    follow encoder noise), at least 20 urad."""
    return max(2e-5, 2.0 * x_noise_rad)


with _numba_cache_in(_cache_path()):

    @numba.njit(cache=True, error_model="numpy")
    def _spring_torque(r: FloatArray, x: float, phi: float) -> float:
        if r[R_MF] > 0.0:
            return nonlinear_stiffness.masterflex08_torque_nm(x, r[R_MF])
        k = series_stiffness.stiffness_nm_per_rad(x, phi, r[R_KP], r[R_SP], r[R_KN], r[R_SN])
        if x >= 0.0:
            return nonlinear_stiffness.polynomial_torque_nm(x, k, r[R_A2P], r[R_A3P], r[R_XREF])
        return nonlinear_stiffness.polynomial_torque_nm(x, k, r[R_A2N], r[R_A3N], r[R_XREF])

    @numba.njit(cache=True, error_model="numpy")
    def _element_torque(
        r: FloatArray,
        x: float,
        dx: float,
        xdot: float,
        phi: float,
        h: float,
        z_slip: FloatArray,
        w_ve: FloatArray,
        z_c: FloatArray,
    ) -> float:
        """Shaft torque at deflection ``x`` after the increment ``dx`` over ``h`` (states updated)."""
        tau = _spring_torque(r, x, phi)
        for j in range(int(r[R_N_SLIP])):
            z_slip[j] = coulomb_friction.presliding_state(z_slip[j], dx, r[R_SLIP_D + j])
            tau += maxwell_slip.element_torque_nm(z_slip[j], r[R_SLIP_K + j])
        v = dx / h if h > 0.0 else 0.0
        for j in range(int(r[R_N_VE])):
            tj = r[R_VE_TAU + j]
            e = math.exp(-h / tj) if h > 0.0 else 1.0
            w_ve[j] = v * tj * (1.0 - e) + w_ve[j] * e  # exact for x linear over the step
            tau += conduit_viscoelastic.branch_moment_nm(x, x - w_ve[j], r[R_VE_K + j])
        if r[R_F_SH] > 0.0:
            z_c[0] = coulomb_friction.presliding_state(z_c[0], dx, r[R_DELTA_C])
            tau += coulomb_friction.presliding_torque_nm(z_c[0], r[R_DELTA_C], r[R_F_SH])
        tau += viscous_damping.damper_torque_nm(xdot, r[R_B_SH])
        return tau

    @numba.njit(cache=True, error_model="numpy")
    def replay_static(
        r: FloatArray,
        u: FloatArray,
        udot: FloatArray,
        uacc: FloatArray,
        s: FloatArray,
        sdot: FloatArray,
        phi: FloatArray,
        h: float,
    ) -> FloatArray:
        """Output (torque / moment) of a blocked series bench or a parallel bench."""
        n = u.shape[0]
        y = np.empty(n)
        z_slip = np.zeros(MAX_ELEMENTS)
        w_ve = np.zeros(MAX_ELEMENTS)
        z_c = np.zeros(1)
        x_prev = backlash.transmitted_deflection_rad(u[0] - s[0], r[R_BL_W], r[R_BL_C])
        for i in range(n):
            xr = u[i] - s[i]
            x = backlash.transmitted_deflection_rad(xr, r[R_BL_W], r[R_BL_C])
            xd = backlash.transmitted_rate(xr, udot[i] - sdot[i], r[R_BL_W], r[R_BL_C])
            tau = _element_torque(
                r, x, x - x_prev, xd, phi[i], h if i > 0 else 0.0, z_slip, w_ve, z_c
            )
            x_prev = x
            if r[R_USE_ACC] > 0.5:
                tau += r[R_J] * uacc[i]
            y[i] = sensor_offset.reading(tau, r[R_OFF_OUT])
        return y

    @numba.njit(cache=True, error_model="numpy")
    def replay_inertia(
        r: FloatArray,
        u: FloatArray,
        phi: FloatArray,
        h: float,
        n_sub: int,
        theta0: FloatArray,
        omega0: FloatArray,
        restart: npt.NDArray[np.bool_],
    ) -> tuple[FloatArray, FloatArray]:
        """(tau_s, theta_s) of the series bench driving a load inertia ``r[R_J]``.

        The torque sensor sits between shaft and load: it reads the shaft torque. The load obeys
        ``J theta_s'' = tau_shaft - b_load theta_s' - F_load sgn(theta_s')`` (stick included).
        At samples with ``restart[i]`` the load state is set to ``(theta0[i], omega0[i])``
        (sample 0 always starts there); internal shaft states carry on.
        """
        n = u.shape[0]
        tau_out = np.empty(n)
        th_out = np.empty(n)
        z_slip = np.zeros(MAX_ELEMENTS)
        w_ve = np.zeros(MAX_ELEMENTS)
        z_c = np.zeros(1)
        hs = h / n_sub
        j = r[R_J]
        th = theta0[0]
        om = omega0[0]
        x_prev = backlash.transmitted_deflection_rad(u[0] - th, r[R_BL_W], r[R_BL_C])
        first = True
        for i in range(n):
            if restart[i]:
                th = theta0[i]
                om = omega0[i]
            ud = (u[i + 1] - u[i]) / h if i + 1 < n else (u[i] - u[i - 1]) / h
            for k in range(n_sub):
                uk = u[i] + (ud * hs * k if i + 1 < n else 0.0)
                xr = uk - th
                x = backlash.transmitted_deflection_rad(xr, r[R_BL_W], r[R_BL_C])
                xd = backlash.transmitted_rate(xr, ud - om, r[R_BL_W], r[R_BL_C])
                tau = _element_torque(
                    r, x, x - x_prev, xd, phi[i], 0.0 if first else hs, z_slip, w_ve, z_c
                )
                first = False
                x_prev = x
                if k == 0:
                    tau_out[i] = sensor_offset.reading(tau, r[R_OFF_OUT])
                    th_out[i] = th
                if i + 1 == n:
                    break
                # load: implicit viscous term, then implicit Coulomb (stick-slip) friction
                v_free = (om + hs * tau / j) / (1.0 + hs * r[R_B_LOAD] / j)
                om = coulomb_friction.stick_slip_velocity(v_free, hs * r[R_F_LOAD] / j)
                th += hs * om
        return tau_out, th_out

    @numba.njit(cache=True, error_model="numpy")
    def stop_columns(x: FloatArray, deltas: FloatArray) -> FloatArray:
        """Maxwell-slip element deflections z_j(t) (stop operators of threshold delta_j), rad."""
        n = x.shape[0]
        m = deltas.shape[0]
        out = np.empty((n, m))
        z = np.zeros(m)
        for i in range(n):
            dx = x[i] - x[i - 1] if i > 0 else 0.0
            for j in range(m):
                z[j] = coulomb_friction.presliding_state(z[j], dx, deltas[j])
                out[i, j] = z[j]
        return out

    @numba.njit(cache=True, error_model="numpy")
    def branch_columns(x: FloatArray, taus: FloatArray, h: float) -> FloatArray:
        """Visco-elastic branch deflections w_j = x - z_j(t), rad (exact update, x linear per step)."""
        n = x.shape[0]
        m = taus.shape[0]
        out = np.empty((n, m))
        w = np.zeros(m)
        for j in range(m):
            out[0, j] = 0.0
        for i in range(1, n):
            v = (x[i] - x[i - 1]) / h
            for j in range(m):
                e = math.exp(-h / taus[j])
                w[j] = v * taus[j] * (1.0 - e) + w[j] * e
                out[i, j] = w[j]
        return out

    @numba.njit(cache=True, error_model="numpy")
    def dead_zone(
        xr: FloatArray, xr_dot: FloatArray, width: float, center: float
    ) -> tuple[FloatArray, FloatArray]:
        """Transmitted deflection and its rate through a backlash of ``width`` at ``center``."""
        n = xr.shape[0]
        x = np.empty(n)
        xd = np.empty(n)
        for i in range(n):
            x[i] = backlash.transmitted_deflection_rad(xr[i], width, center)
            xd[i] = backlash.transmitted_rate(xr[i], xr_dot[i], width, center)
        return x, xd

    @numba.njit(cache=True, error_model="numpy")
    def shifted(y: FloatArray, delay_samples: float) -> FloatArray:
        """``y`` delayed by a (fractional, signed) number of samples."""
        return delay.delayed_signal(y, delay_samples)


# ------------------------------------------------------------------------- model -> kernels


def param_vector(model: BenchModel) -> FloatArray:
    """Flatten a bench model into the kernels' parameter vector (layout R_* above)."""
    r = np.zeros(N_R)
    nom = model.nominal
    if model.setup == "series_bench":
        r[R_KP], r[R_SP] = nom["k_pos"], nom.get("s_pos", 0.0)
        r[R_KN], r[R_SN] = nom["k_neg"], nom.get("s_neg", 0.0)
        r[R_J] = nom.get("j_load", model.load_inertia_kgm2 or 0.0)
    else:
        r[R_KP] = r[R_KN] = nom["kb"]
        r[R_J] = nom.get("j_link", 0.0)
        r[R_USE_ACC] = 1.0
    r[R_XREF] = 1.0
    r[R_DELTA_C] = DEFAULT_DELTA_C
    n_slip = n_ve = 0
    for e in model.effects:
        p = e.params
        if e.name == "coulomb_friction":
            if e.variant == "shaft":
                r[R_F_SH] += p["f_c_nm"]
                r[R_DELTA_C] = p.get("delta_rad", DEFAULT_DELTA_C)
            else:
                r[R_F_LOAD] += p["f_c_nm"]
        elif e.name == "viscous_damping":
            r[R_B_SH if e.variant == "shaft" else R_B_LOAD] += p["b_nms"]
        elif e.name == "backlash":
            r[R_BL_W], r[R_BL_C] = p["width_rad"], p["center_rad"]
        elif e.name == "nonlinear_stiffness":
            if e.variant == "masterflex08":
                r[R_MF] = p["twist_scale"]
                continue
            r[R_XREF] = p["x_ref_rad"]
            if e.variant == "poly":
                r[R_A2P] = r[R_A2N] = p["c2_nm"]
                r[R_A3P] = r[R_A3N] = p["c3_nm"]
            else:
                r[R_A2P], r[R_A3P] = p["c2_pos_nm"], p["c3_pos_nm"]
                r[R_A2N], r[R_A3N] = p["c2_neg_nm"], p["c3_neg_nm"]
        elif e.name == "sensor_offset" and e.variant == "output":
            r[R_OFF_OUT] += p["offset_nm"]
        elif e.name == "hysteresis" and e.variant == "maxwell_slip":
            for k, d in zip(p["k_nm_per_rad"], p["delta_rad"], strict=True):
                if n_slip < MAX_ELEMENTS:
                    r[R_SLIP_K + n_slip], r[R_SLIP_D + n_slip] = k, d
                    n_slip += 1
        elif e.name == "hysteresis" and e.variant == "viscoelastic":
            for k, tau in zip(p["k_nm_per_rad"], p["tau_s"], strict=True):
                if n_ve < MAX_ELEMENTS:
                    r[R_VE_K + n_ve], r[R_VE_TAU + n_ve] = k, tau
                    n_ve += 1
    r[R_N_SLIP], r[R_N_VE] = n_slip, n_ve
    return r


def input_transform(model: BenchModel) -> tuple[float, float]:
    """(delay in s, input sensor bias in rad) of a model: reading = true input + bias."""
    d = off = 0.0
    for e in model.effects:
        if e.name == "delay":
            d += e.params["delay_s"]
        elif e.name == "sensor_offset" and e.variant == "input":
            off += e.params["offset_rad"]
    return d, off


MAX_H_OMEGA_STIFF = 0.1  # with presliding / slip elements stuck (their stick-slip dynamics)
MAX_SUBSTEPS = 50


def substeps(r: FloatArray, h: float) -> int:
    """Substeps per sample: h_sub * omega <= MAX_H_OMEGA for the spring law (taken at twice x_ref
    for a nonlinear spring) and <= MAX_H_OMEGA_STIFF with the stiff presliding and slip elements
    stuck, at most MAX_SUBSTEPS (semi-implicit Euler stays stable for h omega < 2)."""
    if r[R_J] <= 0.0:
        return 1
    c = max(abs(r[R_A2P]), abs(r[R_A2N])) * 4.0 + max(abs(r[R_A3P]), abs(r[R_A3N])) * 12.0
    k = max(r[R_KP], r[R_KN]) + c / max(r[R_XREF], 1e-9)
    if r[R_MF] > 0:
        k = max(k, 10.0 * r[R_MF] / nonlinear_stiffness.DEG)  # MasterFlex08 slope < 0.15 N*m/deg
    k_stiff = float(np.sum(r[R_SLIP_K : R_SLIP_K + int(r[R_N_SLIP])]))
    k_stiff += float(np.sum(r[R_VE_K : R_VE_K + int(r[R_N_VE])]))
    if r[R_F_SH] > 0:
        k_stiff += r[R_F_SH] / r[R_DELTA_C]
    n1 = math.ceil(h * math.sqrt(max(k, 0.0) / r[R_J]) / MAX_H_OMEGA)
    n2 = math.ceil(h * math.sqrt(max(k + k_stiff, 0.0) / r[R_J]) / MAX_H_OMEGA_STIFF)
    return max(1, min(MAX_SUBSTEPS, max(n1, n2)))


def shifted_inputs(inp: ReplayInputs, delay_s: float, offset_rad: float) -> ReplayInputs:
    """The inputs shifted in time and value: u(t - d) + offset_rad (rates, accelerations too)."""
    if delay_s == 0.0 and offset_rad == 0.0:
        return inp
    ds = delay_s / inp.h
    u = shifted(inp.u, ds) + offset_rad if ds != 0.0 else inp.u + offset_rad
    udot = shifted(inp.udot, ds) if ds != 0.0 else inp.udot
    uacc = shifted(inp.uacc, ds) if ds != 0.0 else inp.uacc
    return ReplayInputs(
        inp.setup,
        inp.t,
        inp.h,
        u,
        udot,
        uacc,
        inp.s,
        inp.sdot,
        inp.phi,
        inp.y,
        inp.theta_s,
        inp.inertia_load,
        inp.omega_s,
        inp.theta_s_smooth,
        inp.alpha_s,
    )


SEGMENT_S = 0.5  # inertia load: the load state is re-initialised from the measurement this often


def restarts(n: int, h: float, segment_s: float | None) -> npt.NDArray[np.bool_]:
    """Samples where a segmented (multiple-shooting) replay restarts the load state."""
    flags = np.zeros(n, dtype=bool)
    flags[0] = True
    if segment_s is not None and segment_s > 0:
        step = max(1, round(segment_s / h))
        flags[::step] = True
    return flags


def replay(
    model: BenchModel, inp: ReplayInputs, segment_s: float | None = SEGMENT_S
) -> dict[str, FloatArray]:
    """Replay a bench model on prepared inputs: ``{"y": main output, "theta_s": ... (inertia)}``.

    Inertia load: the load starts from the measured angle and speed (Savitzky-Golay; the speed
    taken half a substep back, where semi-implicit Euler's velocity state lives) and, with
    ``segment_s``, is re-initialised from them every ``segment_s`` seconds (multiple shooting:
    an undamped load resonance amplifies any input or parameter error in proportion to time -
    a 1 % inertia error becomes a phase drift without bound over a long record).
    ``segment_s=None``: one continuous run.
    """
    r = param_vector(model)
    d, bias = input_transform(model)
    x = shifted_inputs(inp, d, -bias)  # the model sees the true input: reading - bias
    if model.inertia_load:
        assert inp.theta_s is not None
        th0 = inp.theta_s_smooth if inp.theta_s_smooth is not None else inp.theta_s
        om = inp.omega_s if inp.omega_s is not None else derivative(th0, inp.h, 1, 0.031)
        acc = inp.alpha_s if inp.alpha_s is not None else derivative(th0, inp.h, 2)
        n_sub = substeps(r, inp.h)
        # semi-implicit Euler's velocity state lags the derivative by half a (sub)step
        om = om - 0.5 * (inp.h / n_sub) * acc
        flags = restarts(inp.n, inp.h, segment_s)
        tau, th = replay_inertia(r, x.u, x.phi, inp.h, n_sub, th0, om, flags)
        return {"y": tau, "theta_s": th}
    return {"y": replay_static(r, x.u, x.udot, x.uacc, x.s, x.sdot, x.phi, inp.h)}
