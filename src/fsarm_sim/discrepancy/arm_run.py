"""The arm record's run as the replay needs it: the stated setup (shaft, payload, controller
gains, control period, timestep, integrator, joint 3's transmission) read from the sidecar, and
the reference table the recorded references ``q*_ref`` give (``qd*_ref``/``qdd*_ref`` if
recorded, else central differences, see :func:`reference_table`). The replay itself is
:mod:`.arm_fit`'s.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import PAYLOAD_MAX_KG, Gains
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.records.measured import (
    Dataset,
    MeasuredDataError,
    SidecarError,
)
from fsarm_sim.records.sidecar import Sidecar, as_record

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


REF_STEP_RATE = 10.0  # rad/s: a reference moving faster between two samples is a step (above
# any joint's speed: joint 3's motor limit 523.6 rad/s / 16 / 10 = 3.3 rad/s, models/fsarm)


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


def _recorded_or_derived(
    c: Mapping[str, FloatArray],
    name: str,
    of: list[FloatArray],
    of_name: str,
    h: float,
    notes: list[str],
) -> list[FloatArray]:
    """The three joints' ``{name}{j}_ref`` columns if all are recorded, else the derivatives
    (zero across steps) of ``of``, the ``{of_name}_ref`` columns; what was done goes to
    ``notes``."""
    if all(f"{name}{j}_ref" in c for j in (1, 2, 3)):
        notes.append(f"{name}_ref recorded")
        return [c[f"{name}{j}_ref"] for j in (1, 2, 3)]
    notes.append(f"{name}_ref = central differences of {of_name}_ref (zero across steps)")
    return [_derivative_with_steps(v, h) for v in of]


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
    notes: list[str] = []
    cols: list[FloatArray] = []
    q = [c[f"q{j}_ref"] for j in (1, 2, 3)]
    qd = _recorded_or_derived(c, "qd", q, "q", h, notes)
    qdd = _recorded_or_derived(c, "qdd", qd, "qd", h, notes)
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
