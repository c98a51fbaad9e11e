"""The arm's closed-loop replay and fits: rebuild a recorded run, simulate a model of it, fit the
nominal refit and the candidate effects (the arm's :class:`~.core.Setup` is :mod:`.arm`).

**Replay.** An ``arm`` record (:mod:`fsarm_sim.records.measured`; sidecar schema :mod:`fsarm_sim.records.sidecar`)
is rebuilt from its sidecar - shaft (a run's exact ``shaft_params`` when recorded), stated
payload, controller gains, control period, timestep, integrator and joint 3's transmission with
its plant and controller parameters - into a :class:`~fsarm_sim.engine.model.SimConfig`,
and the run is simulated by the project's own simulator (MuJoCo + the native callbacks) with the
*recorded* references ``q*_ref`` (``qd*_ref``/``qdd*_ref`` if recorded, else central differences,
see :func:`reference_table`) driving the *run's* controller. The controller always keeps the
stated shaft and payload (what the real controller knew); refits and effects act on the plant
only (``SimConfig.controller_shaft``; the plant-only switches of :class:`~fsarm_sim.engine.model.Effects`).

**Channels.** The recorded ``q3``, ``theta_m`` and ``q2`` are compared in the basis
``q3``, ``twist = theta_m - i_G2 q3`` (the shaft twist, proportional to the shaft torque by eq. 8)
and ``q2`` (joint 2 feels the payload and the bending moment of eq. 2). Each channel's noise floor
``sigma_c`` comes from the data (:func:`.residuals.noise_floor`, at least the quantisation error
q / sqrt(12) of its encoder, :func:`channel_noise`); residuals are divided by it.

**Nominal refit first.** The plant's series stiffness - one scale on eq. 3's ``k`` and ``s``
for both twist signs, or one per sign when the record visits both (each >= 5 % of the samples) -
fitted as a compliance scale (the twist that carries a torque is linear in it), the bending
stiffness ``K_b`` (a scale, fitted when joint 2 bends the shaft by more than 5 deg) and, when the
sidecar states the payload loosely (``payload_tolerance_kg > 0``), the payload within that
tolerance (``payload_error`` is then no candidate). Scales stay within 4x of the catalogue. An
effect is missing only when no such refit removes the disagreement. With a transmission other
than the flexible shaft the series-stiffness scales (eq. 8's) and ``hysteresis[maxwell_slip]``
(the shaft's slip elements) do not apply and are left out.

**Candidates** (grey-box: every parameter acts inside the re-simulated closed loop):

=========================  =============================================================  ====
effect[variant]            acts as                                                        k
=========================  =============================================================  ====
payload_error[mass]        unstated payload mass (``Effects.payload_error_kg``)           1
coulomb_friction[q3]       Coulomb friction at joint 3 (``Effects.q3_friction_nm``)       1
viscous_damping[q3]        extra viscous damping at joint 3 (``Effects.q3_damping_nms``)  1
backlash[twist]            dead band on the shaft twist (width; centre too when the       1-2
                           twist crosses zero, both signs >= 0.2 % of the samples)
hysteresis[maxwell_slip]   elasto-slip elements on the shaft (``ShaftParams.slip_k/f``):  2/el.
                           stiffnesses on a grid of 3 slip deflections, elements below
                           1 % of K dropped, then stiffness and deflection refined
sensor_offset[CH]          constant bias on the recorded channel CH (q3, theta_m, q2)     1
delay[CH]                  the recorded channel CH lags the others by d                   1
=========================  =============================================================  ====

The last two are measurement effects: applied to the simulated channel
(:func:`apply_measurement`), not to the plant. Bounds: :mod:`fsarm_sim.plant.effects.registry`.

**Fitting** (few simulations: a 10 s record costs ~0.15 s per closed-loop run). Each step
linearises the weighted teaching residual once: secant columns (one simulation per plant
parameter; offsets and delays analytic: a constant and ``-dy/dt``) for every parameter already
in the model and every candidate parameter. Every candidate is solved jointly with the present
parameters by bounded linear least squares (:mod:`.lsq`) and *re-simulated* there; when
the nominal refit moved away from the catalogue, also from the catalogue's values (a refit can
mimic an effect - a softer shaft looks like a heavier payload - and the two valleys are not
joined by a straight line), keeping the better. The two most promising effects are then refined
on the simulation itself (Gauss-Newton with fresh secant Jacobians, bounded steps, at most
``REFINE_ITER`` iterations) and all are scored.

Runs are kept by their simulator input (:class:`ArmContext`: two models that build the same
simulator configuration - most effects present at zero - are one run) and the runs a step
needs are simulated side by side (:meth:`ArmContext.prefetch`; the refinements of a step in
lockstep, :func:`refine_many`): the same runs and fits as one after the other (issue 15).

The choice among the fitted candidates is the diagnosis core's (:mod:`.core`, the arm as a
:class:`~.core.Setup` in :mod:`.arm`).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Generator, Iterator, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import lsq
from fsarm_sim.discrepancy import replay as R
from fsarm_sim.discrepancy import variants as V
from fsarm_sim.discrepancy.benchmodel import EffectInstance
from fsarm_sim.discrepancy.residuals import noise_floor, split_masks
from fsarm_sim.engine.model import PAYLOAD_MAX_KG, Effects, Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError, SimulationWarningError
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import sensor_offset
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.records.measured import (
    Dataset,
    MeasuredDataError,
    SidecarError,
)
from fsarm_sim.records.sidecar import Sidecar, as_record
from fsarm_sim.sim.simulation import Simulation

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

RAW = V.ARM_CHANNELS  # recorded channels the replay compares
BASIS = ("q3", "twist", "q2")  # fitting / scoring basis: twist = theta_m - i_G2 q3
MAIN = "q3"
MODEL_FORMAT = "fsarm-arm-model"
MODEL_VERSION = 1
SIGMA_MIN = 1e-9  # rad: the CSV's 10 significant digits on angles of a few rad
SIDE_MIN_FRACTION = 0.05  # both twist signs this often: one stiffness scale per sign, else one
BACKLASH_CROSS_FRACTION = 0.002  # both signs this often: the backlash centre is identifiable
KB_MIN_BEND_RAD = math.radians(5.0)  # K_b is refit when joint 2 bends the shaft further
SCALE_BOUNDS = (0.25, 4.0)  # stiffness scales: within 4x of the catalogue (as candidates.py)
REF_STEP_RATE = 10.0  # rad/s: a reference moving faster between two samples is a step (above
# any joint's speed: joint 3's motor limit 523.6 rad/s / 16 / 10 = 3.3 rad/s, models/fsarm)
N_SLIP_GRID = 3  # hysteresis: slip deflections tried (ShaftParams has three element slots)


# simulations run side by side where a step needs several (ArmContext.prefetch): the cores this
# process may use, at most 4; FSARM_DIAGNOSE_THREADS overrides (1: one after the other)
def sim_threads() -> int:
    """Simulation threads for a diagnosis step (FSARM_DIAGNOSE_THREADS, else the usable cores,
    at most 4)."""
    given = os.environ.get("FSARM_DIAGNOSE_THREADS", "").strip()
    if given:
        if not given.isdigit() or int(given) < 1:
            raise InvalidParameterError(
                f"FSARM_DIAGNOSE_THREADS must be a whole number >= 1, got {given!r}"
            )
        return int(given)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return min(4, cores or 1)


SIM_THREADS = sim_threads()
# set inside simulation_threads(): the limit for that block, in the thread that entered it
_THREADS: ContextVar[int | None] = ContextVar("fsarm_arm_sim_threads", default=None)


@contextmanager
def simulation_threads(n: int) -> Iterator[None]:
    """For the block, a diagnosis step runs at most ``n`` simulations side by side (1: one after
    the other; ``scripts/bench_diagnose.py`` compares the two). Scoped by a context variable: it
    holds in the thread that entered it, where :meth:`ArmContext.prefetch` reads it; the previous
    limit comes back on exit."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InvalidParameterError(f"simulation threads must be a whole number >= 1, got {n!r}")
    token = _THREADS.set(n)
    try:
        yield
    finally:
        _THREADS.reset(token)


def threads_now() -> int:
    """Simulations a diagnosis step may run side by side here (:func:`simulation_threads`, else
    :data:`SIM_THREADS`)."""
    n = _THREADS.get()
    return SIM_THREADS if n is None else n


REFINE_ITER = 3  # Gauss-Newton iterations of a refinement (each: free parameters + 1 runs)
NOMINAL_ITER = 5
REFINE_SECANT = 0.1  # secant step of the refinement, in units of each parameter's magnitude
REFINE_RTOL = 1e-3  # stop when an iteration lowers the teaching cost by less than this
N_REFINE = 2  # effects refined on the simulation per step (the leader and its runner-up)


class ArmSidecarError(SidecarError):
    """An arm sidecar key the replay needs is missing or out of range."""


class ArmReplayError(MeasuredDataError):
    """The run cannot be rebuilt or its nominal replay fails (diverges, MuJoCo warns)."""


# ----------------------------------------------------------------------------- the run


@dataclass(frozen=True)
class ArmRun:
    """What the replay needs from an arm record: the stated setup and the reference table."""

    shaft: ShaftParams  # stated (catalogue) shaft: the controller's model
    payload_kg: float  # stated payload: the controller's model
    payload_tolerance_kg: float  # > 0: the payload is stated loosely and refit within it
    gains: Gains
    timestep_s: float | None
    ref_table: FloatArray  # (n_ticks, 9): q_ref[3], qd_ref[3], qdd_ref[3] per control tick
    t: FloatArray  # record times relative to the first sample, s
    h: float  # record sample interval, s
    ref_note: str
    # joint 3's transmission (SimConfig's fields); the flexible shaft takes ``shaft``
    transmission: str = transmissions.DEFAULT
    transmission_params: tuple[tuple[str, float], ...] = ()
    controller_transmission_params: tuple[tuple[str, float], ...] | None = None
    integrator: str | None = None  # None: the MJCF's
    # ``shaft`` is the run's exact shaft (a record of ``fsarm run``: ``shaft_params``): its slip
    # elements are part of the stated plant; otherwise series hysteresis is for the diagnosis
    exact_shaft: bool = False

    @property
    def ctrl_dt(self) -> float:
        return self.gains.ctrl_dt_s

    @property
    def flexible_shaft(self) -> bool:
        """Joint 3 is driven by the flexible shaft (eq. 8 stiffness refit, slip hysteresis)."""
        return self.transmission == transmissions.DEFAULT


def _num(side: Mapping[str, Any], key: str, where: Path, default: float | None = None) -> float:
    v = side.get(key, default)
    if v is None:
        raise ArmSidecarError(f"{where}: an arm sidecar needs '{key}'")
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ArmSidecarError(f"{where}: '{key}' must be a finite number, got {v!r}")
    return float(v)


def parse_gains(side: Mapping[str, Any], where: Path) -> Gains:
    """The controller settings of the run: sidecar ``gains`` (Gains fields) and ``ctrl_dt_s``."""
    raw = side.get("gains", {})
    if raw is None:
        raw = {}
    if not isinstance(raw, Mapping):
        raise ArmSidecarError(f"{where}: 'gains' must be an object of Gains fields, got {raw!r}")
    fields = {f.name: f for f in dataclasses.fields(Gains)}
    unknown = sorted(set(raw) - set(fields))
    if unknown:
        raise ArmSidecarError(
            f"{where}: unknown gain(s) {unknown}; allowed: {', '.join(sorted(fields))}"
        )
    kw: dict[str, Any] = {}
    for k, v in raw.items():
        default = getattr(Gains(), k)
        if isinstance(default, bool):
            if not isinstance(v, bool):
                raise ArmSidecarError(f"{where}: gains.{k} must be true or false, got {v!r}")
            kw[k] = v
        elif isinstance(default, str):
            if not isinstance(v, str):
                raise ArmSidecarError(f"{where}: gains.{k} must be a string, got {v!r}")
            kw[k] = v
        elif isinstance(default, tuple):
            n = len(default) if default else None  # () : any length (hysteresis_model)
            ok = isinstance(v, list | tuple) and (n is None or len(v) == n)
            if not ok or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in v):
                size = f"{n} numbers" if n else "numbers"
                raise ArmSidecarError(f"{where}: gains.{k} must be a list of {size}, got {v!r}")
            kw[k] = tuple(float(a) for a in v)
        else:
            kw[k] = _num(raw, k, where)
    if side.get("ctrl_dt_s") is not None:
        dt = _num(side, "ctrl_dt_s", where)
        if "ctrl_dt_s" in kw and abs(kw["ctrl_dt_s"] - dt) > 1e-12:
            raise ArmSidecarError(f"{where}: 'ctrl_dt_s' and 'gains.ctrl_dt_s' disagree")
        kw["ctrl_dt_s"] = dt
    elif "ctrl_dt_s" not in kw:
        raise ArmSidecarError(
            f"{where}: an arm sidecar needs 'ctrl_dt_s' (the control period, s; or gains.ctrl_dt_s)"
        )
    g = Gains(**kw)
    try:
        g.validate()
    except InvalidParameterError as exc:
        raise ArmSidecarError(f"{where}: {exc}") from exc
    return g


def _derivative_with_steps(y: FloatArray, h: float) -> FloatArray:
    """Central differences; zero across reference steps (faster than REF_STEP_RATE)."""
    d = np.gradient(y, h)
    jump = np.flatnonzero(np.abs(np.diff(y)) > REF_STEP_RATE * h)
    for i in jump:
        d[max(0, i - 1) : i + 3] = 0.0
    return d


def reference_table(ds: Dataset, ctrl_dt: float) -> tuple[FloatArray, str]:
    """The controller's reference table (one row per control tick) from the recorded columns.

    Recorded ``qd*_ref``/``qdd*_ref`` are used as they are; missing ones are central differences
    of the recorded positions (velocities) and of those (accelerations), zeroed across steps
    (a reference moving faster than ``REF_STEP_RATE`` between samples), as a step reference has
    no velocity feed-forward. At a record rate equal to the control rate the rows are the
    samples; otherwise linear interpolation onto the ticks.
    """
    c = ds.columns
    t = c["t"] - c["t"][0]
    h = ds.dt
    notes = []
    cols: list[FloatArray] = []
    q = [c[f"q{j}_ref"] for j in (1, 2, 3)]
    if all(f"qd{j}_ref" in c for j in (1, 2, 3)):
        qd = [c[f"qd{j}_ref"] for j in (1, 2, 3)]
        notes.append("qd_ref recorded")
    else:
        qd = [_derivative_with_steps(v, h) for v in q]
        notes.append("qd_ref = central differences of q_ref (zero across steps)")
    if all(f"qdd{j}_ref" in c for j in (1, 2, 3)):
        qdd = [c[f"qdd{j}_ref"] for j in (1, 2, 3)]
        notes.append("qdd_ref recorded")
    else:
        qdd = [_derivative_with_steps(v, h) for v in qd]
        notes.append("qdd_ref = central differences of qd_ref (zero across steps)")
    cols = [*q, *qd, *qdd]
    n_ticks = math.floor(t[-1] / ctrl_dt + 1e-6) + 2
    ticks = np.arange(n_ticks) * ctrl_dt
    same = abs(h - ctrl_dt) <= 1e-6 * ctrl_dt and np.allclose(t, np.arange(t.size) * ctrl_dt)
    if same:
        table = np.column_stack(cols)
        table = np.vstack([table, table[-1:]])  # one row beyond the record (held)
    else:
        table = np.column_stack([np.interp(ticks, t, v) for v in cols])
        notes.append(f"references interpolated from {1 / h:g} Hz onto the {1 / ctrl_dt:g} Hz ticks")
    return np.ascontiguousarray(table, dtype=np.float64), "; ".join(notes)


def stated_transmission(
    rec: Sidecar, where: Path
) -> tuple[str, tuple[tuple[str, float], ...], tuple[tuple[str, float], ...] | None]:
    """(name, plant parameters, controller parameters or None) of the record's transmission;
    the flexible shaft takes its numbers from the shaft (its recorded block is not read)."""
    tr = rec.transmission
    if tr is None or tr.name == transmissions.DEFAULT:
        return transmissions.DEFAULT, (), None
    try:
        model = transmissions.get(tr.name)
        plant = tuple(tr.params.items())
        ctrl = tuple(tr.controller_params.items()) or None
        model.block(dict(plant))
        if ctrl is not None:
            model.block(dict(ctrl))
    except (transmissions.TransmissionError, InvalidParameterError) as exc:
        raise ArmSidecarError(f"{where}: 'transmission': {exc}") from exc
    if ctrl is not None and dict(ctrl) == dict(plant):
        ctrl = None
    return tr.name, plant, ctrl


def arm_run(ds: Dataset) -> ArmRun:
    """Rebuild the run's setup from an ``arm`` dataset (sidecar keys checked here; the schema
    of the sidecar is :mod:`fsarm_sim.records.sidecar`)."""
    where = ds.path.with_suffix(".json")
    if ds.setup != "arm":
        raise ArmSidecarError(f"{where}: expected an 'arm' dataset, got '{ds.setup}'")
    rec = ds.record if ds.record is not None else as_record(ds.sidecar, where)
    side = {
        k: v
        for k, v in (
            ("payload_kg", rec.payload_kg),
            ("payload_tolerance_kg", rec.payload_tolerance_kg),
            ("ctrl_dt_s", rec.ctrl_dt_s),
            ("gains", rec.gains),
        )
        if v is not None
    }
    tr_name, tr_params, tr_ctrl = stated_transmission(rec, where)
    payload = _num(side, "payload_kg", where)
    if not 0.0 <= payload <= PAYLOAD_MAX_KG:
        raise ArmSidecarError(
            f"{where}: 'payload_kg' must be within 0..{PAYLOAD_MAX_KG:g} kg, got {payload!r}"
        )
    tol = _num(side, "payload_tolerance_kg", where, 0.0)
    if tol < 0.0 or tol > PAYLOAD_MAX_KG:
        raise ArmSidecarError(
            f"{where}: 'payload_tolerance_kg' must be within 0..{PAYLOAD_MAX_KG:g}, got {tol!r}"
        )
    timestep = rec.timestep_s
    if timestep is not None and timestep <= 0.0:
        raise ArmSidecarError(f"{where}: 'timestep_s' must be > 0, got {timestep!r}")
    gains = parse_gains(side, where)
    table, note = reference_table(ds, gains.ctrl_dt_s)
    return ArmRun(
        shaft=ds.shaft,
        payload_kg=payload,
        payload_tolerance_kg=tol,
        gains=gains,
        timestep_s=timestep,
        ref_table=table,
        t=ds.t - ds.t[0],
        h=ds.dt,
        ref_note=note,
        transmission=tr_name,
        transmission_params=tr_params,
        controller_transmission_params=tr_ctrl,
        integrator=rec.integrator,
        exact_shaft=rec.shaft_params is not None,
    )


# ----------------------------------------------------------------------------- the model

# parameter -> (lower, upper, typical magnitude: the unit of the normalised fit variable)
# effect parameters: "<effect>.<parameter>" (plant), "<effect>.<channel>" (recording),
# "hysteresis.k<i>" / "hysteresis.d<i>" (element i); bounds from the registry (.variants.ARM)
UNITS = {  # typical magnitude per registry parameter
    "dm_kg": 0.5,
    "f_c_nm": 0.1,
    "b_nms": 0.1,
    "width_rad": 0.005,
    "center_rad": 0.005,
    "k_nm_per_rad": 2.0,
    "delta_rad": 1e-3,
    "offset_rad": 1e-3,
    "delay_s": 2e-3,
}
_HK, _HD = V.ARM[V.HYSTERESIS][0].params
BOUNDS: dict[str, tuple[float, float, float]] = {
    "c_scale": (*SCALE_BOUNDS, 0.1),
    "c_scale_pos": (*SCALE_BOUNDS, 0.1),
    "c_scale_neg": (*SCALE_BOUNDS, 0.1),
    "kb_scale": (*SCALE_BOUNDS, 0.1),
    "payload_kg_refit": (-PAYLOAD_MAX_KG, PAYLOAD_MAX_KG, 0.5),
    **{
        f"{name}.{v.key if name in V.ARM_RECORDING else p.name}": (
            p.lower,
            p.upper,
            UNITS.get(p.name, p.scale()),
        )
        for name, vs in V.ARM.items()
        if name != V.HYSTERESIS
        for v in vs
        for p in v.params
    },
    **{f"{V.HYSTERESIS}.k{i}": (_HK.lower, _HK.upper, UNITS[_HK.name]) for i in range(3)},
    **{f"{V.HYSTERESIS}.d{i}": (_HD.lower, _HD.upper, UNITS[_HD.name]) for i in range(3)},
}
# The series stiffness is fitted as a compliance scale c = 1 / (stiffness scale): the twist that
# carries a torque is linear in c, so the linearised steps below are nearly exact.
# ``c_scale`` scales both twist sides alike (a record that twists the shaft mostly one way);
# ``c_scale_pos``/``c_scale_neg`` multiply it per side (a record that visits both).
NOMINAL_KEYS = ("c_scale", "c_scale_pos", "c_scale_neg", "kb_scale", "payload_kg_refit")
NOMINAL_DEFAULTS = {"c_scale": 1.0, "c_scale_pos": 1.0, "c_scale_neg": 1.0, "kb_scale": 1.0}
MEASUREMENT_PREFIXES = tuple(f"{name}." for name in V.ARM if name in V.ARM_RECORDING)


@dataclass
class ArmModel:
    """Nominal parameters and named effects of the arm (plant) and of its recording.

    ``values`` holds every parameter present (nominal keys always, effect keys when the effect
    is); ``labels`` the effects in the order added. Hysteresis element ``i`` has the stiffness
    ``hysteresis.k{i}`` and the slip deflection ``hysteresis.d{i}`` (slip torque k d).
    """

    values: dict[str, float] = field(default_factory=lambda: dict(NOMINAL_DEFAULTS))
    labels: list[str] = field(default_factory=list)

    @property
    def slip_delta(self) -> tuple[float, ...]:
        out: list[float] = []
        while f"hysteresis.d{len(out)}" in self.values:
            out.append(self.values[f"hysteresis.d{len(out)}"])
        return tuple(out)

    def set_slip(self, ks: list[float], deltas: list[float]) -> None:
        """Replace the hysteresis elements."""
        for key in [k for k in self.values if k.startswith("hysteresis.")]:
            del self.values[key]
        for i, (k, d) in enumerate(zip(ks, deltas, strict=True)):
            self.values[f"hysteresis.k{i}"] = float(k)
            self.values[f"hysteresis.d{i}"] = float(d)

    def copy(self) -> ArmModel:
        return ArmModel(dict(self.values), list(self.labels))

    def v(self, key: str) -> float:
        return float(self.values.get(key, NOMINAL_DEFAULTS.get(key, 0.0)))

    def physical_key(self) -> tuple[Any, ...]:
        items = sorted(
            (k, round(v, 15))
            for k, v in self.values.items()
            if not k.startswith(MEASUREMENT_PREFIXES)
        )
        return tuple(items)

    def effects(self) -> list[EffectInstance]:
        """The named effects with their parameters (registry vocabulary)."""
        out = []
        for lab in self.labels:
            name, variant = lab[:-1].split("[")
            if name == V.HYSTERESIS:
                ks = [self.v(f"hysteresis.k{i}") for i in range(len(self.slip_delta))]
                p: dict[str, Any] = {"k_nm_per_rad": ks, "delta_rad": list(self.slip_delta)}
                p["slip_torque_nm"] = [k * d for k, d in zip(ks, self.slip_delta, strict=True)]
            elif name in V.ARM_RECORDING:  # one parameter, the channel's
                p = {V.ARM[name][0].params[0].name: self.v(f"{name}.{variant}")}
            else:
                p = {
                    k.split(".", 1)[1]: val
                    for k, val in self.values.items()
                    if k.startswith(name + ".")
                }
            out.append(EffectInstance(name, variant, p))
        return out

    def nominal(self) -> dict[str, float]:
        """Nominal parameters as the model file states them (stiffness scales, K_b scale,
        payload refit)."""
        return {
            "k_scale_pos": 1.0 / (self.v("c_scale") * self.v("c_scale_pos")),
            "k_scale_neg": 1.0 / (self.v("c_scale") * self.v("c_scale_neg")),
            "kb_scale": self.v("kb_scale"),
            "payload_kg_refit": self.v("payload_kg_refit"),
        }


def to_config(run: ArmRun, m: ArmModel) -> SimConfig:
    """The simulator configuration of a model: the plant refit and with its effects, the
    controller with the stated shaft and payload."""
    sh = run.shaft
    c = m.v("c_scale")
    sp, sn, kb = 1.0 / (c * m.v("c_scale_pos")), 1.0 / (c * m.v("c_scale_neg")), m.v("kb_scale")
    slip_k = [0.0, 0.0, 0.0]
    slip_f = [0.0, 0.0, 0.0]
    if run.exact_shaft and not m.slip_delta:  # the run's own slip elements
        slip_k, slip_f = list(sh.slip_k), list(sh.slip_f)
    for i, d in enumerate(m.slip_delta[:3]):
        k = m.v(f"hysteresis.k{i}")
        slip_k[i], slip_f[i] = k, k * d
    plant = replace(
        sh,
        k_pos=sh.k_pos * sp,
        s_pos=sh.s_pos * sp,
        k_neg=sh.k_neg * sn,
        s_neg=sh.s_neg * sn,
        kb=sh.kb * kb,
        slip_k=(slip_k[0], slip_k[1], slip_k[2]),
        slip_f=(slip_f[0], slip_f[1], slip_f[2]),
    )
    fx = Effects(
        payload_error_kg=m.v("payload_kg_refit") + m.v("payload_error.dm_kg"),
        backlash_width_rad=m.v("backlash.width_rad"),
        backlash_center_rad=m.v("backlash.center_rad"),
        q3_friction_nm=m.v("coulomb_friction.f_c_nm"),
        q3_damping_nms=m.v("viscous_damping.b_nms"),
        laws=tuple(
            (name, tuple((p.name, m.v(f"{name}.{p.name}")) for v in V.ARM[name] for p in v.params))
            for name in V.ARM_LAWS
            if any(k.startswith(name + ".") for k in m.values)
        ),
    )
    return SimConfig(
        shaft=plant,
        payload_kg=run.payload_kg,
        gains=run.gains,
        effects=fx,
        controller_shaft=sh,
        timestep_s=run.timestep_s,
        integrator=run.integrator,
        transmission=run.transmission,
        transmission_params=run.transmission_params,
        controller_transmission_params=run.controller_transmission_params,
    )


# ----------------------------------------------------------------------------- simulation


class _ArmSim(Simulation):
    """A Simulation that records only the channels the replay compares (fast)."""

    def _columns(
        self, t: FloatArray, qpos: FloatArray, qvel: FloatArray, act: FloatArray, ud: FloatArray
    ) -> dict[str, FloatArray]:
        st = self.structure
        return {
            "t": t,
            "q1": qpos[:, st.qadr[0]].copy(),
            "q2": qpos[:, st.qadr[1]].copy(),
            "q3": qpos[:, st.qadr[2]].copy(),
            "theta_m": st.coef_m * qpos[:, st.qadr[3]],
        }


def simulate_config(run: ArmRun, cfg: SimConfig) -> tuple[dict[str, FloatArray], float]:
    """Closed-loop run of ``cfg`` on the run's references; channels on the record's time grid,
    and the gear ratio i_G2. Raises InvalidParameterError / SimulationWarningError."""
    sim = _ArmSim(cfg, run.ref_table, "native")
    dt = run.ctrl_dt
    n_rows = math.floor(run.t[-1] / dt + 1e-6) + 2
    cols, _ = sim.run(n_rows * dt, log_every_ticks=1)
    tick_t = cols["t"]
    idx = np.rint(run.t / dt).astype(np.int64)
    on_grid = bool(np.all(np.abs(run.t - idx * dt) <= 1e-6 * dt)) and idx[-1] < tick_t.size
    out = {}
    for ch in ("q1", *RAW):
        y = cols[ch]
        out[ch] = y[idx] if on_grid else np.interp(run.t, tick_t, y)
    return out, float(sim.structure.coef_s)


def delayed(y: FloatArray, delay_samples: float) -> FloatArray:
    """``y`` delayed by a (fractional, signed) number of samples: :func:`.replay.shifted`
    (effects.delay's ``delayed_signal``: linear interpolation, ends held) with numpy's
    element-wise arithmetic - the same operations in the same order, so the same bits
    (tests/test_discrepancy_arm_speed.py) - without loading the compiled function, which took
    0.24 s of every diagnosis in a fresh process (issue 15)."""
    n = y.shape[0]
    x = np.arange(n, dtype=np.float64) - delay_samples
    out = np.empty(n)
    low = x <= 0.0
    high = ~low & (x >= n - 1)
    mid = ~(low | high)
    xm = x[mid]
    i = xm.astype(np.int64)  # int(x) of x > 0: truncation
    f = xm - i
    out[mid] = y[i] + f * (y[i + 1] - y[i])
    out[low] = y[0] if n else 0.0
    out[high] = y[n - 1] if n else 0.0
    return out


def apply_measurement(
    raw: Mapping[str, FloatArray], m: ArmModel, h: float
) -> dict[str, FloatArray]:
    """The recorded channels of a simulated run: each delayed (effects.delay: linear
    interpolation, ends held; :func:`delayed`) and biased (effects.sensor_offset) as the
    model's measurement effects say."""
    out: dict[str, FloatArray] = {}
    for ch in RAW:
        y = raw[ch]
        d = m.v(f"delay.{ch}")
        if d != 0.0:
            y = delayed(np.ascontiguousarray(y, dtype=np.float64), d / h)
        out[ch] = np.asarray(sensor_offset.reading(y, m.v(f"sensor_offset.{ch}")))  # type: ignore[arg-type]
    return out


def to_basis(raw: Mapping[str, FloatArray], coef_s: float) -> dict[str, FloatArray]:
    return {"q3": raw["q3"], "twist": raw["theta_m"] - coef_s * raw["q3"], "q2": raw["q2"]}


# ----------------------------------------------------------------------------- context


@dataclass
class ArmContext:
    """Everything the fits of one record share."""

    ds: Dataset
    run: ArmRun
    coef_s: float
    y: dict[str, FloatArray]  # measured, fitting basis
    raw: dict[str, FloatArray]  # measured q3, theta_m, q2
    teach: BoolArray
    held: BoolArray
    sigma: dict[str, float]  # noise floor per basis channel
    sides: tuple[bool, bool]  # (positive, negative) twist side visited (SIDE_MIN_FRACTION)
    fit_kb: bool
    slip_grid: FloatArray
    two_sided: bool
    cache: dict[tuple[Any, ...], dict[str, FloatArray] | None] = field(default_factory=dict)
    n_sims: int = 0
    # runs by their simulator input (``repr`` of the SimConfig: every field, floats exactly;
    # the reference table is the context's own): two models that differ only in parameters
    # that do not reach the simulator - an effect present at zero, the slip deflection of an
    # element with no stiffness - are one run (issue 15)
    config_cache: dict[str, dict[str, FloatArray] | None] = field(default_factory=dict)

    def _input(self, m: ArmModel) -> tuple[SimConfig | None, str | None]:
        """The simulator input of ``m`` and its key (None, None: the configuration cannot be
        built, so the run fails)."""
        try:
            cfg = to_config(self.run, m)
        except InvalidParameterError:
            return None, None
        return cfg, repr(cfg)

    def _run(self, m: ArmModel) -> dict[str, FloatArray] | None:
        """``m``'s run, simulated now (None: it fails)."""
        return self._run_input(self._input(m)[0])

    def _run_input(self, cfg: SimConfig | None) -> dict[str, FloatArray] | None:
        if cfg is None:
            return None
        try:
            raw, _ = simulate_config(self.run, cfg)
        except (InvalidParameterError, SimulationWarningError):
            return None
        return raw if all(np.all(np.isfinite(v)) for v in raw.values()) else None

    def _shared(self, key: tuple[Any, ...], ck: str | None) -> bool:
        """Is a run of the same simulator input ``ck`` known? Then it is filed under ``key`` too."""
        if ck is not None and ck in self.config_cache:
            self.cache[key] = self.config_cache[ck]
            return True
        return False

    def _store(
        self, key: tuple[Any, ...], ck: str | None, raw: dict[str, FloatArray] | None
    ) -> None:
        self.n_sims += 1
        self.cache[key] = raw
        if ck is not None:
            self.config_cache.setdefault(ck, raw)

    def simulate(self, m: ArmModel) -> dict[str, FloatArray] | None:
        key = m.physical_key()
        if key not in self.cache:
            cfg, ck = self._input(m)
            if not self._shared(key, ck):
                self._store(key, ck, self._run_input(cfg))
        return self.cache[key]

    def prefetch(self, models: Sequence[ArmModel | None]) -> None:
        """Run the models not simulated yet side by side (:func:`threads_now` threads: the
        compiled callbacks step in parallel, MuJoCo releases the GIL while stepping); later
        :meth:`simulate` calls find them in the cache. The same runs as one after the other."""
        todo: dict[tuple[Any, ...], tuple[SimConfig | None, str | None]] = {}
        inputs: set[str] = set()
        for m in models:
            if m is None:
                continue
            key = m.physical_key()
            if key in self.cache or key in todo:
                continue
            cfg, ck = self._input(m)
            if self._shared(key, ck) or (ck is not None and ck in inputs):
                continue  # known, or the same run asked for twice: simulate() finds the first
            todo[key] = (cfg, ck)
            if ck is not None:
                inputs.add(ck)
        threads = min(threads_now(), len(todo))
        if threads < 2:
            return  # one run (or one core): simulate() runs it when it is asked for
        with ThreadPoolExecutor(threads) as ex:
            results = list(ex.map(self._run_input, [cfg for cfg, _ in todo.values()]))
        for (key, (_, ck)), raw in zip(todo.items(), results, strict=True):
            self._store(key, ck, raw)

    def predict(self, m: ArmModel) -> tuple[dict[str, FloatArray], dict[str, FloatArray]] | None:
        """(basis, raw) recorded channels the model predicts; None if its run fails."""
        sim = self.simulate(m)
        if sim is None:
            return None
        raw = apply_measurement(sim, m, self.run.h)
        return to_basis(raw, self.coef_s), raw

    def wresid(self, pred: Mapping[str, FloatArray], mask: BoolArray) -> FloatArray:
        return np.concatenate([((self.y[c] - pred[c]) / self.sigma[c])[mask] for c in BASIS])


def quantum(y: FloatArray) -> float:
    """Quantisation step of a recorded channel (0 if it does not look quantised): the smallest
    non-zero sample-to-sample change, when at least 10 % of the changes are exactly zero."""
    d = np.abs(np.diff(y))
    if d.size == 0 or np.mean(d == 0.0) < 0.1:
        return 0.0
    nz = d[d > 1e-12 * max(1.0, float(np.max(np.abs(y))))]
    return float(nz.min()) if nz.size else 0.0


def channel_noise(y: FloatArray) -> float:
    """Noise floor of a channel: the difference-based estimate of :func:`.residuals.noise_floor`,
    at least the quantisation error's q / sqrt(12) (a slow channel of a fine encoder sits on
    one count for long stretches: its 4th differences are mostly zero, its error is not) and at
    least SIGMA_MIN."""
    return max(noise_floor(y), quantum(y) / math.sqrt(12.0), SIGMA_MIN)


def _side_fractions(twist: FloatArray, sigma: float) -> tuple[float, float]:
    thr = 3.0 * sigma
    return float(np.mean(twist > thr)), float(np.mean(twist < -thr))


def make_context(ds: Dataset, run: ArmRun) -> ArmContext:
    """Measured channels, split, noise floors and what the record can identify."""
    c = ds.columns
    raw = {ch: c[ch] for ch in RAW}
    # i_G2 from the compiled model of the stated run (a one-tick build, no stepping)
    from fsarm_sim.engine.model import build_model, read_structure

    try:
        coef_s = read_structure(build_model(to_config(run, ArmModel()), run.ref_table[:2])).coef_s
    except InvalidParameterError as exc:
        raise ArmReplayError(f"{ds.path}: cannot rebuild the run: {exc}") from exc
    y = to_basis(raw, coef_s)
    teach, held = split_masks(ds.n)
    sigma = {ch: channel_noise(y[ch]) for ch in BASIS}
    fp, fn = _side_fractions(y["twist"], sigma["twist"])
    bend = float(np.quantile(np.abs(c["q2"]), 0.9))
    tw = y["twist"]
    ptp = float(np.ptp(tw)) or 1e-3
    return ArmContext(
        ds=ds,
        run=run,
        coef_s=float(coef_s),
        y=y,
        raw=raw,
        teach=teach,
        held=held,
        sigma=sigma,
        sides=(fp >= SIDE_MIN_FRACTION, fn >= SIDE_MIN_FRACTION),
        fit_kb=bend > KB_MIN_BEND_RAD,
        slip_grid=np.geomspace(0.05 * ptp, 0.5 * ptp, N_SLIP_GRID),
        two_sided=min(fp, fn) >= BACKLASH_CROSS_FRACTION,
    )


def nominal_keys(ctx: ArmContext) -> list[str]:
    keys = []
    if not ctx.run.flexible_shaft:
        pass  # the series stiffness refit is eq. 8's: the flexible shaft's own parameters
    elif all(ctx.sides):
        keys += ["c_scale_pos", "c_scale_neg"]
    else:  # a side visited rarely follows the other (a shaft rarely errs one way only)
        keys.append("c_scale")
    if ctx.fit_kb:
        keys.append("kb_scale")
    if ctx.run.payload_tolerance_kg > 0.0:
        keys.append("payload_kg_refit")
    return keys


def bounds_of(ctx: ArmContext, key: str) -> tuple[float, float, float]:
    lo, hi, unit = BOUNDS[key]
    if key == "payload_kg_refit":
        tol = ctx.run.payload_tolerance_kg
        lo, hi = max(-tol, -ctx.run.payload_kg), tol
    elif key == "payload_error.dm_kg":
        lo = max(lo, -ctx.run.payload_kg)
        hi = min(hi, PAYLOAD_MAX_KG - ctx.run.payload_kg)
    return lo, hi, unit


# ----------------------------------------------------------------------------- fits


@dataclass
class ArmFit:
    model: ArmModel
    pred: dict[str, FloatArray]  # basis
    raw: dict[str, FloatArray]
    free: list[str]  # fitted parameters
    k: int
    mse_teach: dict[str, float]
    mse_held: dict[str, float]
    label: str = "nominal"
    effect: str | None = None
    variant: str | None = None
    note: str = ""
    cost: float = math.inf  # weighted teaching sum of squares
    predicted: float = math.inf  # the cost the linearised screening expected

    def w(self, ctx: ArmContext, held: bool = True) -> float:
        """Weighted MSE: mean over channels of MSE_c / sigma_c^2 (1 = at the noise floor)."""
        mse = self.mse_held if held else self.mse_teach
        return float(sum(mse[c] / ctx.sigma[c] ** 2 for c in BASIS)) / len(BASIS)


def n_params(free: list[str], m: ArmModel) -> int:
    """BIC's k: fitted parameters; a hysteresis element counts two (stiffness and slip
    deflection, whether the deflection is on its grid value or refined)."""
    other = [k for k in free if not k.startswith("hysteresis.")]
    return len(other) + 2 * sum(1 for k in free if k.startswith("hysteresis.k"))


def evaluate(
    ctx: ArmContext, m: ArmModel, free: list[str], label: str = "nominal"
) -> ArmFit | None:
    p = ctx.predict(m)
    if p is None:
        return None
    pred, raw = p
    mt = {c: float(np.mean((ctx.y[c] - pred[c])[ctx.teach] ** 2)) for c in BASIS}
    mh = {c: float(np.mean((ctx.y[c] - pred[c])[ctx.held] ** 2)) for c in BASIS}
    r = ctx.wresid(pred, ctx.teach)
    return ArmFit(m, pred, raw, list(free), n_params(free, m), mt, mh, label, cost=float(r @ r))


def with_values(m: ArmModel, keys: list[str], x: FloatArray) -> ArmModel:
    out = m.copy()
    for k, v in zip(keys, x, strict=True):
        out.values[k] = float(v)
    return out


def jacobian_column(
    ctx: ArmContext,
    m: ArmModel,
    base: dict[str, FloatArray],
    raw: dict[str, FloatArray],
    key: str,
    frac: float = 1.0,
) -> FloatArray | None:
    """d(weighted teaching residual) / d(parameter in units of its typical magnitude), by a
    secant over ``frac`` units (plant parameters: one simulation) or analytically (measurement)."""
    unit = bounds_of(ctx, key)[2]
    h = ctx.run.h
    if key.startswith(("sensor_offset.", "delay.")):
        ch = key.split(".", 1)[1]
        # change of the recorded channel: a constant (offset) or y(t - d) ~ y(t) - d y'(t)
        dy = unit if key.startswith("sensor_offset.") else -R.derivative(raw[ch], h) * unit
        d = {c: np.zeros_like(base[c]) for c in BASIS}
        if ch == "q3":  # q3 enters the twist basis as -i_G2 q3
            d["q3"] += dy
            d["twist"] -= ctx.coef_s * dy
        elif ch == "theta_m":
            d["twist"] += dy
        else:
            d["q2"] += dy
    else:
        step = _secant_step(ctx, m, key, frac)
        p = ctx.predict(with_values(m, [key], np.array([m.v(key) + step])))
        if p is None:
            return None
        d = {c: (p[0][c] - base[c]) * (unit / step) for c in BASIS}
    return -np.concatenate([(d[c] / ctx.sigma[c])[ctx.teach] for c in BASIS])


def _secant_step(ctx: ArmContext, m: ArmModel, key: str, frac: float) -> float:
    """The secant's step of a plant parameter: slip deflections relative (they range over
    decades), others one unit; backwards where forwards leaves the bounds."""
    _, hi, unit = bounds_of(ctx, key)
    x0 = m.v(key)
    step = (0.3 * x0 if key.startswith("hysteresis.d") and x0 > 0.0 else unit) * frac
    return step if x0 + step <= hi else -step


def secant_model(ctx: ArmContext, m: ArmModel, key: str, frac: float = 1.0) -> ArmModel | None:
    """The run :func:`jacobian_column` simulates for ``key`` (None: a measurement parameter,
    whose column is analytic)."""
    if key.startswith(("sensor_offset.", "delay.")):
        return None
    return with_values(m, [key], np.array([m.v(key) + _secant_step(ctx, m, key, frac)]))


def linear_solve(
    ctx: ArmContext, m: ArmModel, keys: list[str], jac: FloatArray, r0: FloatArray
) -> ArmModel:
    """Bounded linear least squares for the parameter changes (normalised units)."""
    v = np.array([m.v(k) for k in keys])
    a, b, unit = np.array([bounds_of(ctx, k) for k in keys], dtype=float).reshape(-1, 3).T
    # a value already outside its bounds may stay where it is
    a, b = np.minimum(a, v), np.maximum(b, v)
    dx = lsq.bounded(jac, -r0, (a - v) / unit, (b - v) / unit)
    # a step to a bound lands on it: v + ((a - v) / unit) * unit can round past it (a slip
    # stiffness of -1e-16 N*m/rad, which the transmission then refuses)
    return with_values(m, keys, np.clip(v + dx * unit, a, b))


def refine(ctx: ArmContext, fit: ArmFit, max_iter: int = REFINE_ITER) -> ArmFit:
    """Nonlinear refinement of a fit's free parameters on the simulation itself: Gauss-Newton
    with fresh secant Jacobians (steps of REFINE_SECANT units), each step a bounded linear
    least-squares problem (:mod:`.lsq`); a step that does not lower the teaching cost is
    halved once, then the search stops. Costs (free plant parameters + 1) runs per iteration
    (the secant runs of an iteration side by side: :func:`refine_many`)."""
    return refine_many(ctx, [fit], max_iter)[0]


def refine_many(
    ctx: ArmContext, fits: Sequence[ArmFit], max_iter: int = REFINE_ITER
) -> list[ArmFit]:
    """:func:`refine` of each fit, in lockstep: the runs every refinement needs next (an
    iteration's secant runs, its step, its halved step) are simulated side by side
    (:meth:`ArmContext.prefetch`) before each refinement goes on. Each refinement does what it
    does alone - the same runs, none on speculation (issue 15: the refinements were one run
    after the other)."""
    steps = [_refine_steps(ctx, f, max_iter) for f in fits]
    out: list[ArmFit | None] = [None] * len(fits)
    wants: dict[int, list[ArmModel | None]] = {}
    for i, g in enumerate(steps):
        try:
            wants[i] = next(g)
        except StopIteration as done:
            out[i] = done.value
    while wants:
        ctx.prefetch([m for i in wants for m in wants[i]])
        for i in list(wants):
            try:
                wants[i] = steps[i].send(None)
            except StopIteration as done:
                out[i] = done.value
                del wants[i]
    done_fits: list[ArmFit] = []
    for f in out:
        assert f is not None  # every refinement returned
        done_fits.append(f)
    return done_fits


def _refine_steps(
    ctx: ArmContext, fit: ArmFit, max_iter: int
) -> Generator[list[ArmModel | None], None, ArmFit]:
    """:func:`refine` of one fit as steps: yields the models whose runs it needs next (all of
    them then asked for), returns the refined fit."""
    keys = fit.free
    cur = fit
    for _ in range(max_iter):
        yield [secant_model(ctx, cur.model, k, REFINE_SECANT) for k in keys]
        cols = [jacobian_column(ctx, cur.model, cur.pred, cur.raw, k, REFINE_SECANT) for k in keys]
        if not keys or any(c is None for c in cols):
            break
        jac = np.column_stack([c for c in cols if c is not None])
        m_new = linear_solve(ctx, cur.model, keys, jac, ctx.wresid(cur.pred, ctx.teach))
        yield [m_new]
        new = evaluate(ctx, m_new, keys, fit.label)
        if new is None or new.cost >= cur.cost:
            half = {k: 0.5 * (cur.model.v(k) + m_new.v(k)) for k in keys}
            m_half = with_values(cur.model, keys, np.array([half[k] for k in keys]))
            yield [m_half]
            new = evaluate(ctx, m_half, keys, fit.label)
            if new is None or new.cost >= cur.cost:
                break
        done = new.cost > (1.0 - REFINE_RTOL) * cur.cost
        cur = new
        if done:
            break
    cur.label, cur.effect, cur.variant, cur.note = fit.label, fit.effect, fit.variant, fit.note
    return cur


# ----------------------------------------------------------------------------- candidates

PLANT_CANDIDATES = tuple(
    (name, v.key) for name, vs in V.ARM.items() if name not in V.ARM_RECORDING for v in vs
)
MEASUREMENT_CANDIDATES = tuple(
    (name, v.key) for name, vs in V.ARM.items() if name in V.ARM_RECORDING for v in vs
)


def candidate_pairs(ctx: ArmContext) -> list[tuple[str, str]]:
    skip = set()
    if ctx.run.payload_tolerance_kg > 0.0:  # the payload is already refit as a nominal parameter
        skip.add(V.PAYLOAD)
    if not ctx.run.flexible_shaft:  # slip elements are the flexible shaft's states
        skip.add(V.HYSTERESIS)
    return [(e, v) for e, v in PLANT_CANDIDATES + MEASUREMENT_CANDIDATES if e not in skip]


def candidate_keys(ctx: ArmContext, effect: str, variant: str) -> list[str]:
    if effect == V.HYSTERESIS:
        return [f"{effect}.k{i}" for i in range(N_SLIP_GRID)]
    if effect in V.ARM_RECORDING:
        return [f"{effect}.{variant}"]
    params = [p.name for p in V.ARM[effect][0].params]
    if effect == V.BACKLASH and not ctx.two_sided:
        # a one-sided twist sees only one flank: the centre is not defined
        params = params[:1]
    return [f"{effect}.{p}" for p in params]


def add_candidate(ctx: ArmContext, m: ArmModel, effect: str, variant: str) -> ArmModel:
    out = m.copy()
    out.labels.append(f"{effect}[{variant}]")
    for k in candidate_keys(ctx, effect, variant):
        out.values[k] = 0.0
    if effect == V.HYSTERESIS:
        out.set_slip([0.0] * len(ctx.slip_grid), [float(d) for d in ctx.slip_grid])
    return out


def prune_slip(ctx: ArmContext, m: ArmModel) -> tuple[ArmModel, list[int]]:
    """Drop hysteresis elements with (almost) no stiffness: below 1 % of the shaft's K.
    Returns the model and the grid indices of the elements kept (renumbered 0, 1, ...)."""
    k_ref = 0.01 * max(ctx.run.shaft.k_pos, ctx.run.shaft.k_neg)
    deltas = m.slip_delta
    keep = [i for i in range(len(deltas)) if m.v(f"hysteresis.k{i}") > k_ref]
    out = m.copy()
    out.set_slip([m.v(f"hysteresis.k{i}") for i in keep], [deltas[i] for i in keep])
    return out, keep


@dataclass
class StepJacobian:
    """One linearisation per step: columns for present and candidate parameters."""

    cols: dict[str, FloatArray]
    r0: FloatArray


def jacobian_runs(
    ctx: ArmContext, model: ArmModel, free: Sequence[str], pairs: Sequence[tuple[str, str]]
) -> list[ArmModel | None]:
    """The secant runs :func:`step_jacobian` needs at ``model`` with the free parameters
    ``free`` (to simulate several linearisations' runs side by side)."""
    runs = [secant_model(ctx, model, k) for k in free]
    for e, v in pairs:
        trial = add_candidate(ctx, model, e, v)
        runs += [secant_model(ctx, trial, k) for k in candidate_keys(ctx, e, v)]
    return runs


def step_jacobian(ctx: ArmContext, cur: ArmFit, pairs: list[tuple[str, str]]) -> StepJacobian:
    """Secant columns at the current model for its free parameters and every candidate's
    (candidates enter at zero, so the current prediction is their base point)."""
    cols: dict[str, FloatArray] = {}
    ctx.prefetch(jacobian_runs(ctx, cur.model, cur.free, pairs))
    for k in cur.free:
        col = jacobian_column(ctx, cur.model, cur.pred, cur.raw, k)
        if col is not None:
            cols[k] = col
    for e, v in pairs:
        trial = add_candidate(ctx, cur.model, e, v)
        for k in candidate_keys(ctx, e, v):
            if k not in cols:
                col = jacobian_column(ctx, trial, cur.pred, cur.raw, k)
                if col is not None:
                    cols[k] = col
    return StepJacobian(cols, ctx.wresid(cur.pred, ctx.teach))


def screen_solve(
    ctx: ArmContext, sj: StepJacobian, cur: ArmFit, effect: str, variant: str
) -> tuple[ArmModel, list[str], FloatArray] | None:
    """The linearised joint solve of the present parameters plus one candidate: (model, free
    parameters, linearised residual), not yet re-simulated."""
    new = candidate_keys(ctx, effect, variant)
    keys = list(cur.free) + new
    if any(k not in sj.cols for k in keys):
        return None
    jac = np.column_stack([sj.cols[k] for k in keys])
    m0 = add_candidate(ctx, cur.model, effect, variant)
    m = linear_solve(ctx, m0, keys, jac, sj.r0)
    units = np.array([bounds_of(ctx, k)[2] for k in keys])
    du = np.array([m.v(k) - m0.v(k) for k in keys]) / units
    r_lin = sj.r0 + jac @ du
    free = keys
    if effect == V.HYSTERESIS:
        m, keep = prune_slip(ctx, m)
        if not keep:
            return None
        free = list(cur.free) + [f"hysteresis.k{j}" for j in range(len(keep))]
    return m, free, r_lin


def screen(
    ctx: ArmContext, sj: StepJacobian, cur: ArmFit, effect: str, variant: str
) -> ArmFit | None:
    """Linearised joint solve of the present parameters plus one candidate, re-simulated."""
    solved = screen_solve(ctx, sj, cur, effect, variant)
    if solved is None:
        return None
    m, free, r_lin = solved
    f = evaluate(ctx, m, free, f"{effect}[{variant}]")
    if f is None:
        return None
    f.effect, f.variant = effect, variant
    f.predicted = float(r_lin @ r_lin)
    return f


# ----------------------------------------------------------------------------- nominal and steps


def nominal_fit(ctx: ArmContext) -> tuple[ArmFit, ArmFit]:
    """(catalogue, refit nominal): the stated model, then its own parameters refit."""
    keys = nominal_keys(ctx)
    m = ArmModel()
    for k in keys:
        m.values.setdefault(k, NOMINAL_DEFAULTS.get(k, 0.0))
    ctx.prefetch([ArmModel(), m])  # the catalogue and the refit's start (often the same run)
    cat = evaluate(ctx, ArmModel(), [], "nominal (catalogue)")
    if cat is None:
        raise ArmReplayError(
            f"{ctx.ds.path}: the nominal replay of the run fails (diverges or MuJoCo warns); "
            "check the sidecar's shaft, payload, gains and ctrl_dt_s"
        )
    if not keys:
        return cat, replace(cat, label="nominal (refit)")
    start = evaluate(ctx, m, keys, "nominal (refit)")
    assert start is not None
    ctx.prefetch([secant_model(ctx, m, k) for k in keys])
    cols = [jacobian_column(ctx, m, start.pred, start.raw, k) for k in keys]
    if any(c is None for c in cols):
        return cat, replace(cat, label="nominal (refit)")
    jac = np.column_stack([c for c in cols if c is not None])
    lin = evaluate(ctx, linear_solve(ctx, m, keys, jac, ctx.wresid(start.pred, ctx.teach)), keys)
    best = start if lin is None or lin.cost >= start.cost else lin
    best.label = "nominal (refit)"
    best = refine(ctx, best, NOMINAL_ITER)
    best.label = "nominal (refit)"
    return cat, best


def stated_nominal_model(fit: ArmFit) -> ArmModel | None:
    """The fit's model with the nominal parameters back at their stated values (None when they
    are there already, within 2 %)."""
    m = fit.model.copy()
    moved = False
    for k in NOMINAL_KEYS:
        if k in m.values:
            ref = NOMINAL_DEFAULTS.get(k, 0.0)
            unit = BOUNDS[k][2]
            moved = moved or abs(m.values[k] - ref) > 0.2 * unit
            m.values[k] = ref
    return m if moved else None


def stated_nominal(ctx: ArmContext, fit: ArmFit) -> ArmFit | None:
    """:func:`stated_nominal_model` simulated (None when the nominal parameters are at their
    stated values already, within 2 %, or the run fails)."""
    m = stated_nominal_model(fit)
    return None if m is None else evaluate(ctx, m, fit.free, fit.label)


def start_runs(
    ctx: ArmContext,
    cur: ArmFit,
    pairs: Sequence[tuple[str, str]],
    alt_pairs: Sequence[tuple[str, str]],
) -> list[ArmModel | None]:
    """The runs of the linearisations from ``cur`` (``pairs``) and from its stated nominal
    (:func:`stated_nominal_model`, ``alt_pairs``): the stated nominal itself and both
    :func:`jacobian_runs`, to be simulated side by side. (Should the stated nominal's own run
    fail, its secant runs were in vain: a failure path, not worth a step of its own.)"""
    runs = jacobian_runs(ctx, cur.model, cur.free, pairs)
    alt = stated_nominal_model(cur)
    if alt is not None:
        runs += [alt, *jacobian_runs(ctx, alt, cur.free, alt_pairs)]
    return runs


def screen_all(ctx: ArmContext, cur: ArmFit, pairs: list[tuple[str, str]]) -> list[ArmFit]:
    """Every candidate linearised and solved from the current model and - when the nominal refit
    moved away from the stated values - also from the stated nominal (a refit nominal can mimic
    an effect, e.g. a softer shaft a heavier payload: the two valleys are not joined by a
    straight line); the better start per candidate is kept."""
    plant = {e for e, _ in PLANT_CANDIDATES}
    alt_pairs = [(e, v) for e, v in pairs if e in plant]
    # both starts' runs side by side, then both starts' candidates' re-simulations
    # (stated_nominal(), step_jacobian() and screen() then find them run)
    ctx.prefetch(start_runs(ctx, cur, pairs, alt_pairs))
    starts = [cur]
    alt = stated_nominal(ctx, cur)
    if alt is not None:
        starts.append(alt)
    subs = [pairs, alt_pairs][: len(starts)]
    sjs = [step_jacobian(ctx, st, sub) for st, sub in zip(starts, subs, strict=True)]
    ctx.prefetch(
        [
            s[0]
            for st, sub, sj in zip(starts, subs, sjs, strict=True)
            for s in (screen_solve(ctx, sj, st, e, v) for e, v in sub)
            if s is not None
        ]
    )
    best: dict[tuple[str, str], ArmFit] = {}
    for start, sub, sj in zip(starts, subs, sjs, strict=True):
        for e, v in sub:
            s = screen(ctx, sj, start, e, v)
            if s is not None and ((e, v) not in best or s.cost < best[(e, v)].cost):
                best[(e, v)] = s
    return list(best.values())


def step_candidates(ctx: ArmContext, cur: ArmFit, named: Sequence[str]) -> list[ArmFit]:
    """Every candidate effect not in ``named`` fitted on top of ``cur`` (:func:`screen_all`);
    the best variant of the N_REFINE most promising effects then refined on the simulation
    itself (promise: the lower of the re-simulated and the linearly predicted cost - a
    candidate that the linearisation rates well but the re-simulation not is a nonlinear one)."""
    pairs = [(e, v) for e, v in candidate_pairs(ctx) if e not in named]
    screened = screen_all(ctx, cur, pairs)

    def promise(f: ArmFit) -> float:
        return min(f.cost, f.predicted)

    best_of: dict[str, ArmFit] = {}
    for f in screened:
        if f.effect not in best_of or promise(f) < promise(best_of[f.effect or ""]):
            best_of[f.effect or ""] = f
    lead = sorted(best_of.values(), key=promise)[:N_REFINE]
    fits = list(screened)
    starts = []
    for f in lead:
        g = f
        if f.effect == V.HYSTERESIS:  # the slip deflections leave their grid values
            n_el = len(f.model.slip_delta)
            g = replace(f, free=f.free + [f"hysteresis.d{i}" for i in range(n_el)])
        starts.append(g)
    for f, r in zip(lead, refine_many(ctx, starts), strict=True):
        fits = [r if x is f else x for x in fits]
    return fits
