"""The one typed schema of a record's sidecar: ``NAME.json`` beside ``NAME.csv`` / ``NAME.parquet``.

Every writer and reader of a sidecar goes through :class:`Sidecar`:

=====================================  ==========================================================
writer                                 what it writes
=====================================  ==========================================================
:mod:`fsarm_sim.records.timeseries`            ``fsarm run``: setup ``arm``, the whole replayable setup
:mod:`fsarm_sim.discrepancy.synth`                 ``fsarm synth``: bench datasets (SYNTHETIC, ``synthetic``)
:mod:`fsarm_sim.discrepancy.arm_synth` ``fsarm synth --setup arm`` (SYNTHETIC, ``synthetic``)
:func:`fsarm_sim.records.measured.write_dataset`  checks any sidecar before it writes it
=====================================  ==========================================================

Readers: :func:`fsarm_sim.records.measured.load_dataset` (``Dataset.record``) and
:func:`fsarm_sim.discrepancy.arm.arm_run`. The format of measured data is
``../shared/specs/measured-data.md``; ``docs/records.md`` describes what a run record adds.

Reading is strict: a key the schema does not know is :class:`SidecarKeyError`, a value of the
wrong type :class:`SidecarTypeError`; both name the file and the key (``gains.wn_rad_s``).
Free text belongs in ``notes``. Accepted legacy shapes: ``transmission`` as a plain name (the
form of the measured-data sidecars), the version-0.2.0 run sidecars (no ``schema``, ``null`` for
defaults, no ``columns``), the synthetic sidecars of ``examples/data``. Range and meaning checks
(a payload within 0..15 kg, a known shaft) are the readers' business, not the schema's.

Columns: :data:`REQUIRED` and :data:`OPTIONAL` per setup (the spec), :data:`RUN_COLUMNS` (what
``fsarm run`` writes), :data:`UNITS` (SI unit of every column the project names). A sidecar
*declares* columns with ``extra_columns`` (names) or ``columns`` (name -> unit, what the
project's writers write); a record written by ``fsarm run`` (``writer``, or the 0.2.0 shape)
declares all of :data:`RUN_COLUMNS`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from fsarm_sim import typed_tables
from fsarm_sim.errors import FsarmError
from fsarm_sim.paths import bounded_json, checked_path, regular_file
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.shaft import ShaftParams

SCHEMA = "fsarm-record/1"  # value of the ``schema`` key this version writes
WRITER_RUN = "fsarm run"
WRITER_SYNTH = "fsarm synth"

SETUPS = ("series_bench", "parallel_bench", "arm")
REQUIRED: dict[str, tuple[str, ...]] = {
    "series_bench": ("t", "theta_m", "theta_s", "phi_b", "tau_s"),
    "parallel_bench": ("t", "phi_b", "m_b"),
    "arm": ("t", "q1", "q2", "q3", "theta_m", "q1_ref", "q2_ref", "q3_ref"),
}
_REF_RATES = tuple(f"qd{j}_ref" for j in (1, 2, 3)) + tuple(f"qdd{j}_ref" for j in (1, 2, 3))
OPTIONAL: dict[str, tuple[str, ...]] = {
    "series_bench": (),
    "parallel_bench": (),
    "arm": (*_REF_RATES, "tau_m"),
}
# the columns the diagnosis of each setup reads (the rest of a table is listed, not used)
READ: dict[str, tuple[str, ...]] = {
    "series_bench": REQUIRED["series_bench"],
    "parallel_bench": REQUIRED["parallel_bench"],
    "arm": REQUIRED["arm"] + _REF_RATES,
}
# what ``fsarm run`` writes, in its order (fsarm_sim.sim.simulation.Simulation._columns; a test
# keeps the two equal)
RUN_COLUMNS: tuple[str, ...] = (
    "t",
    *(f"q{j}" for j in (1, 2, 3)),
    *(f"q{j}_ref" for j in (1, 2, 3)),
    *(f"qd{j}" for j in (1, 2, 3)),
    *(f"qd{j}_ref" for j in (1, 2, 3)),
    *(f"qdd{j}_ref" for j in (1, 2, 3)),
    "theta_m",
    "theta_s",
    "twist",
    "phi_b",
    "omega_m",
    "omega_d",
    "tau_shaft",
    "tau_model",
    "tau_d_shaft",
    "tau_d_joint3",
    "tau_bend",
    "tau_conduit",
    "pid_p",
    "pid_i",
    "pid_d",
    "tau1",
    "tau2",
    "tau_motor",
)
UNITS: dict[str, str] = {
    "t": "s",
    **{f"q{j}": "rad" for j in (1, 2, 3)},
    **{f"q{j}_ref": "rad" for j in (1, 2, 3)},
    **{f"qd{j}": "rad/s" for j in (1, 2, 3)},
    **{f"qd{j}_ref": "rad/s" for j in (1, 2, 3)},
    **{f"qdd{j}_ref": "rad/s^2" for j in (1, 2, 3)},
    "theta_m": "rad",
    "theta_s": "rad",
    "twist": "rad",
    "phi_b": "rad",
    "tau_s": "N*m",
    "m_b": "N*m",
    "tau_m": "N*m",
    "omega_m": "rad/s",  # shaft input speed
    "omega_d": "rad/s",  # desired shaft input speed (torque PID output)
    "tau_shaft": "N*m",
    "tau_model": "N*m",
    "tau_d_shaft": "N*m",
    "tau_d_joint3": "N*m",
    "tau_bend": "N*m",
    "tau_conduit": "N*m",
    "pid_p": "rad/s",  # the torque PID's terms of omega_d
    "pid_i": "rad/s",
    "pid_d": "rad/s",
    "tau1": "N*m",
    "tau2": "N*m",
    "tau_motor": "N*m",  # rotor side
}
# the registry laws' own states, recorded while a law is on (``<effect>.<state>``)
UNITS.update(
    {
        f"{e.name}.{d.name}": d.unit
        for e in registry.arm_laws()
        if e.law is not None
        for d in e.law.STATES
    }
)


class MeasuredDataError(FsarmError, ValueError):
    """Base of every problem with a measured dataset or a record."""


class SidecarError(MeasuredDataError):
    """The JSON sidecar is missing, not JSON, or has a malformed key."""


class SidecarKeyError(SidecarError):
    """A sidecar key the schema does not define (the message names the file and the key)."""


class SidecarTypeError(SidecarError):
    """A sidecar value of the wrong type (the message names the file, the key and the type)."""


class SetupError(MeasuredDataError):
    """Unknown setup, or a table whose columns belong to another setup."""


GainValue = float | bool | str | tuple[float, ...]


@dataclass(frozen=True)
class ShaftRef:
    """The stated shaft: D and L (mm) or a catalogue ``name``; optionally a coefficient file
    (relative to the sidecar) and ``extrapolate`` (D/L outside its validity range)."""

    diameter_mm: float | None = None
    length_mm: float | None = None
    name: str | None = None
    coefficient_file: str | None = None
    extrapolate: bool | None = None


@dataclass(frozen=True)
class LoadRef:
    """Series bench output: ``{"type": "blocked"}`` or ``{"type": "inertia", "inertia_kgm2": J}``."""

    type: str
    inertia_kgm2: float | None = None


@dataclass(frozen=True)
class TransmissionRef:
    """Joint 3's transmission: its name, and as ``fsarm run`` writes them its source and the
    plant's and the controller's parameter values (empty: the transmission's defaults)."""

    name: str
    source: str | None = None
    params: dict[str, float] = field(default_factory=dict)
    controller_params: dict[str, float] = field(default_factory=dict)


@dataclass(kw_only=True)
class Sidecar:
    """A record's sidecar. ``None`` = absent (written as no key); the key names are the JSON's.

    Setup keys: ``setup``, ``shaft``, ``notes``, ``extra_columns``/``columns``; series bench:
    ``load``; arm: ``payload_kg``, ``payload_tolerance_kg``, ``ctrl_dt_s``, ``gains``
    (:class:`fsarm_sim.engine.model.Gains` fields), ``transmission``, ``timestep_s``, ``integrator``.
    A run adds ``scenario``, ``duration_s``, ``interrupted``, ``shaft_params``
    (:class:`fsarm_sim.plant.shaft.ShaftParams` fields: the exact shaft of the run), ``effects``
    (:class:`fsarm_sim.engine.model.Effects` fields: what acted on the simulated plant) and
    ``fsarm_sim_version``; synthetic data ``synthetic`` (the hidden truth, never read by the
    diagnosis).
    """

    schema: str | None = None  # SCHEMA for sidecars of this version; absent in older ones
    writer: str | None = None  # WRITER_RUN, WRITER_SYNTH; absent: written by hand (or older)
    setup: str
    shaft: ShaftRef | None = None
    scenario: str | None = None
    duration_s: float | None = None
    interrupted: bool | None = None
    notes: str | None = None
    load: LoadRef | None = None
    payload_kg: float | None = None
    payload_tolerance_kg: float | None = None
    ctrl_dt_s: float | None = None
    gains: dict[str, GainValue] | None = None
    transmission: TransmissionRef | None = None
    shaft_params: dict[str, float | str | tuple[float, ...]] | None = None
    effects: dict[str, float | bool | dict[str, dict[str, float]]] | None = None
    timestep_s: float | None = None
    integrator: str | None = None
    fsarm_sim_version: str | None = None
    columns: dict[str, str] | None = None
    extra_columns: tuple[str, ...] = ()
    synthetic: dict[str, Any] | None = None

    # ------------------------------------------------------------------ JSON

    def to_json(self) -> dict[str, Any]:
        """The JSON object (absent keys for ``None``; tuples as lists; non-finite floats as
        ``null``)."""
        out = _to_json(self)
        if not self.extra_columns:
            out.pop("extra_columns", None)
        return {k: v for k, v in out.items() if v is not None}

    @classmethod
    def from_json(cls, data: Any, where: str | Path = "sidecar") -> Sidecar:
        """Parse a sidecar's JSON object; :class:`SidecarKeyError` / :class:`SidecarTypeError`
        name ``where`` and the key; :class:`SetupError` for a setup not in :data:`SETUPS`."""
        w = str(where)
        if not isinstance(data, Mapping):
            raise SidecarError(f"{w}: the sidecar must be a JSON object, got {type(data).__name__}")
        setup = data.get("setup")
        if setup not in SETUPS:
            raise SetupError(f"{w}: 'setup' must be one of {', '.join(SETUPS)}, got {setup!r}")
        raw = dict(data)
        if isinstance(raw.get("transmission"), str):  # legacy: the name alone
            raw["transmission"] = {"name": raw["transmission"]}
        _check_fields(raw, w)  # first: its messages are the more precise
        return _parse(cls, raw, w, "")

    # ------------------------------------------------------------------ meaning

    @property
    def is_run(self) -> bool:
        """Written by ``fsarm run`` (``writer``; or the version-0.2.0 run sidecar's shape)."""
        if self.writer is not None:
            return self.writer == WRITER_RUN
        return (
            self.schema is None
            and self.setup == "arm"
            and self.fsarm_sim_version is not None
            and self.shaft_params is not None
            and self.transmission is not None
        )

    def declared_columns(self) -> tuple[str, ...]:
        """Columns the sidecar declares beyond its setup's: ``extra_columns``, the keys of
        ``columns`` and, for a record of ``fsarm run``, :data:`RUN_COLUMNS`."""
        out = list(self.extra_columns) + list(self.columns or {})
        if self.is_run:
            out += RUN_COLUMNS
        return tuple(dict.fromkeys(out))


def read_sidecar(path: str | Path) -> tuple[Sidecar, dict[str, Any]]:
    """(typed record, raw JSON object) of a sidecar file; named errors for a missing file,
    bad JSON, an unknown key or a wrong type."""
    p = Path(path)
    checked_path(p, "sidecar", SidecarError)  # loops, long names ...
    if os.path.lexists(p):  # a folder, a device or a pipe: named
        regular_file(p, "sidecar", SidecarError)
    if not p.is_file():
        raise SidecarError(
            f"sidecar {p} not found: every table needs NAME.json beside it "
            '(at least {"setup": ..., "shaft": {"diameter_mm": ..., "length_mm": ...}})'
        )
    try:
        data = bounded_json(p.read_text("utf-8"), str(p), SidecarError)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SidecarError(f"{p}: not a readable JSON file ({exc})") from exc
    if not isinstance(data, dict):
        raise SidecarError(f"{p}: the sidecar must be a JSON object, got {type(data).__name__}")
    return Sidecar.from_json(data, p), data


def write_sidecar(path: str | Path, record: Sidecar) -> Path:
    p = Path(path)
    p.write_text(json.dumps(record.to_json(), indent=2) + "\n", "utf-8")
    return p


def as_record(sidecar: Sidecar | Mapping[str, Any], where: str | Path = "sidecar") -> Sidecar:
    """A :class:`Sidecar` from either form (a mapping is parsed, strictly)."""
    return sidecar if isinstance(sidecar, Sidecar) else Sidecar.from_json(sidecar, where)


# ----------------------------------------------------------------------------- entries


def gains_entry(gains: Any) -> dict[str, GainValue]:
    """The ``gains`` entry of a :class:`fsarm_sim.engine.model.Gains`."""
    return {f.name: _plain(getattr(gains, f.name)) for f in dataclasses.fields(gains)}


def effects_entry(effects: Any) -> dict[str, float | bool | dict[str, dict[str, float]]]:
    """The ``effects`` entry of a :class:`fsarm_sim.engine.model.Effects`; its arm laws (when
    any are on) as ``"laws": {effect: {parameter: value}}``."""
    out: dict[str, float | bool | dict[str, dict[str, float]]] = {
        f.name: _plain(getattr(effects, f.name))
        for f in dataclasses.fields(effects)
        if f.name != "laws"
    }
    laws = getattr(effects, "laws", ())
    if laws:
        out["laws"] = {name: {k: float(v) for k, v in values} for name, values in laws}
    return out


def shaft_params_entry(shaft: Any) -> dict[str, float | str | tuple[float, ...]]:
    """The ``shaft_params`` entry of a :class:`fsarm_sim.plant.shaft.ShaftParams`."""
    return {f.name: _plain(getattr(shaft, f.name)) for f in dataclasses.fields(shaft)}


def shaft_params_of(record: Sidecar, where: str | Path = "sidecar") -> ShaftParams | None:
    """The :class:`fsarm_sim.plant.shaft.ShaftParams` of ``shaft_params`` (None when absent);
    :class:`SidecarError` when a field is missing or D/L disagree with ``shaft``."""
    if record.shaft_params is None:
        return None
    fields = {f.name: f for f in dataclasses.fields(ShaftParams)}
    need = [
        n
        for n, f in fields.items()
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    missing = [n for n in need if n not in record.shaft_params]
    if missing:
        raise SidecarError(f"{where}: 'shaft_params' lacks {', '.join(repr(m) for m in missing)}")
    sh = ShaftParams(**record.shaft_params)  # type: ignore[arg-type]
    ref = record.shaft
    if ref is not None:
        for key in ("diameter_mm", "length_mm"):
            stated = getattr(ref, key)
            if stated is not None and abs(float(stated) - float(getattr(sh, key))) > 1e-9:
                raise SidecarError(
                    f"{where}: 'shaft.{key}' = {stated!r} but 'shaft_params.{key}' = "
                    f"{getattr(sh, key)!r}: they must describe the same shaft"
                )
    return sh


def effects_of(record: Sidecar, where: str | Path = "sidecar") -> Any:
    """The :class:`fsarm_sim.engine.model.Effects` of ``effects`` (None when absent): the
    switches and laws as written, and the keys older records used for some laws mapped onto
    those laws (:func:`fsarm_sim.plant.effects.registry.legacy_laws`); :class:`SidecarError`
    naming the file when they do not make a valid set of effects."""
    if record.effects is None:
        return None
    from fsarm_sim.engine.model import Effects
    from fsarm_sim.errors import InvalidParameterError

    try:
        return Effects.from_entry(record.effects)
    except InvalidParameterError as exc:
        raise SidecarError(f"{where}: {exc}") from None


# ----------------------------------------------------------------------------- machinery

_T = TypeVar("_T")
_FLOAT_TUPLE = tuple[float, ...]


def _plain(v: Any) -> Any:
    if isinstance(v, list | tuple):
        return tuple(_plain(a) for a in v)
    if hasattr(v, "item") and not isinstance(v, str | bytes):  # numpy scalars
        return v.item()
    return v


def jsonable(x: Any) -> Any:
    """``x`` as plain JSON values (dataclasses as objects without their ``None`` fields, tuples
    as lists, numpy scalars as Python numbers, non-finite floats as ``None``)."""
    return _to_json(x)


def _to_json(x: Any) -> Any:
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {
            f.name: _to_json(getattr(x, f.name))
            for f in dataclasses.fields(x)
            if getattr(x, f.name) is not None
        }
    if isinstance(x, Mapping):
        return {str(k): _to_json(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_to_json(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return _plain(x)


def _bad(where: str, key: str, tp: Any, v: Any) -> SidecarTypeError:
    return SidecarTypeError(f"{where}: '{key}' must be {typed_tables.describe(tp)}, got {v!r}")


def _parse(cls: type[_T], data: Mapping[str, Any], where: str, prefix: str) -> _T:
    """``cls`` read from ``data`` by the shared typed reader, its errors as the sidecar's."""
    try:
        return cls(**typed_tables.typed_kwargs(cls, data, prefix=prefix))
    except typed_tables.UnknownKeys as e:
        inner = e.prefix[:-1]
        raise SidecarKeyError(
            f"{where}: unknown key {', '.join(repr(e.prefix + k) for k in e.keys)}; "
            f"allowed{' in ' + repr(inner) if inner else ''}: {', '.join(e.allowed)}"
            + ("" if inner else " (free text belongs in 'notes')")
        ) from None
    except typed_tables.MissingKey as e:
        raise SidecarError(f"{where}: the sidecar needs '{e.key}'") from None
    except typed_tables.Mismatch as e:
        raise _bad(where, e.key, e.hint, e.value) from None


def _typed_keys(
    entry: Mapping[str, Any] | None,
    owner: type,
    what: str,
    where: str,
    numbers: tuple[str, ...] = (),
) -> None:
    """Keys and value kinds of a mapping entry against the dataclass it mirrors; ``numbers``:
    further keys it may hold, each a number."""
    if not isinstance(entry, Mapping):
        return  # absent, or not an object: the schema's own check names it
    fields = {f.name: f for f in dataclasses.fields(owner)}
    unknown = [k for k in entry if k not in fields and k not in numbers]
    if unknown:
        raise SidecarKeyError(
            f"{where}: unknown key {', '.join(repr(f'{what}.{k}') for k in unknown)}; "
            f"allowed in '{what}' ({owner.__name__} fields): {', '.join(fields)}"
        )
    for k, v in entry.items():
        if k not in fields:  # one of ``numbers``
            if not _is(float, v):
                raise _bad(where, f"{what}.{k}", float, v)
            continue
        f = fields[k]
        if isinstance(v, Mapping) and str(f.type).startswith("tuple[tuple[str"):
            continue  # a nested entry (Effects.laws, name -> values): checked where it is built
        default = (
            f.default
            if f.default is not dataclasses.MISSING
            else (f.default_factory() if f.default_factory is not dataclasses.MISSING else None)
        )
        hint = str(f.type)
        want: Any
        if isinstance(default, bool) or hint == "bool":
            want = bool
        elif isinstance(default, tuple) or hint.startswith("tuple"):
            want = _FLOAT_TUPLE
        elif isinstance(default, str) or hint == "str":
            want = str
        else:
            want = float
        if not _is(want, v):
            raise _bad(where, f"{what}.{k}", want, v)


def _is(want: Any, v: Any) -> bool:
    if want is bool:
        return isinstance(v, bool)
    if want is str:
        return isinstance(v, str)
    if want is float:
        return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
    return isinstance(v, list | tuple) and all(_is(float, a) for a in v)


def _check_fields(raw: Mapping[str, Any], where: str) -> None:
    """The mirrored entries (``gains``, ``effects``, ``shaft_params``, as written) against the
    dataclasses they mirror: keys and value kinds."""
    if raw.get("gains") is not None or raw.get("effects") is not None:
        from fsarm_sim.engine.model import Effects, Gains

        _typed_keys(raw.get("gains"), Gains, "gains", where)
        # (older records hold some laws as keys of their own: registry.legacy_fields)
        legacy = tuple(registry.legacy_fields())
        _typed_keys(raw.get("effects"), Effects, "effects", where, legacy)
    _typed_keys(raw.get("shaft_params"), ShaftParams, "shaft_params", where)


__all__ = [
    "OPTIONAL",
    "READ",
    "REQUIRED",
    "RUN_COLUMNS",
    "SCHEMA",
    "SETUPS",
    "UNITS",
    "LoadRef",
    "MeasuredDataError",
    "SetupError",
    "ShaftRef",
    "Sidecar",
    "SidecarError",
    "SidecarKeyError",
    "SidecarTypeError",
    "TransmissionRef",
    "as_record",
    "effects_entry",
    "effects_of",
    "gains_entry",
    "jsonable",
    "read_sidecar",
    "shaft_params_entry",
    "shaft_params_of",
    "write_sidecar",
]
