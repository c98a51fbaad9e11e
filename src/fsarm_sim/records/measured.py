"""Measured datasets (``specs/measured-data.md``): load, validate and write.

A dataset is a table (``NAME.csv`` or ``NAME.parquet``, one row per sample, SI units) plus a JSON
sidecar ``NAME.json`` that describes the setup. Every problem is a named error that says which
file, which column and which row, and what is allowed:

============================  ==========================================================
:class:`SidecarError`         sidecar missing, not JSON, or a key malformed
:class:`SetupError`           unknown ``setup``, or the columns belong to another setup
:class:`MissingColumnError`   a required column is absent
:class:`ExtraColumnError`     only from :func:`write_dataset`: a column neither the setup
                              nor the sidecar defines (reading lists such columns in
                              ``Dataset.undeclared_columns`` instead of refusing them)
:class:`NonNumericError`      a cell that is not a number
:class:`NonFiniteError`       NaN or inf
:class:`TimeAxisError`        time not strictly increasing, or not evenly sampled
:class:`TooFewSamplesError`   fewer than :data:`MIN_SAMPLES` rows
:class:`UnknownShaftError`    shaft not in the catalogue / outside its validity range
============================  ==========================================================

The sidecar's schema (keys, types, legacy shapes, the columns each setup defines) is
:mod:`fsarm_sim.records.sidecar`; reading is strict (unknown keys and wrong types are named errors).
Columns beyond the setup's are not refused: ``Dataset.unused_columns`` lists what the diagnosis
does not read, ``Dataset.undeclared_columns`` what neither the setup nor the sidecar
(``extra_columns``, ``columns``, a record of ``fsarm run``) defines.

Setup ``arm`` (this project's definition, in the same spirit as the benches): columns ``t, q1,
q2, q3, theta_m, q1_ref, q2_ref, q3_ref`` (rad), optional ``qd1_ref..qd3_ref`` (rad/s),
``qdd1_ref..qdd3_ref`` (rad/s^2) and ``tau_m`` (the controller's modelled shaft torque, N*m);
sidecar ``{"setup": "arm", "shaft": {...}, "payload_kg": 0.0, "ctrl_dt_s": 0.001,
"scenario": "...", "gains": {...}}`` - enough to rebuild the run with :mod:`fsarm_sim.engine.model`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError, ShaftRangeError
from fsarm_sim.paths import checked_path, named_os_errors, regular_file
from fsarm_sim.plant.shaft import Catalogue, ShaftParams, load_catalogue
from fsarm_sim.records.sidecar import (
    OPTIONAL,
    READ,
    REQUIRED,
    UNITS,
    MeasuredDataError,
    SetupError,
    ShaftRef,
    Sidecar,
    SidecarError,
    as_record,
    read_sidecar,
    shaft_params_of,
)
from fsarm_sim.records.sidecar import (
    SETUPS as SETUPS,
)

FloatArray = npt.NDArray[np.float64]

INPUT_COLUMN = {"series_bench": "theta_m", "parallel_bench": "phi_b", "arm": "q3_ref"}
OUTPUT_COLUMN = {"series_bench": "tau_s", "parallel_bench": "m_b", "arm": "q3"}
MIN_SAMPLES = 200  # a few hundred samples: enough for one teaching/verifying split of 12 blocks
TIME_JITTER = 0.01  # allowed deviation of one sample interval from the median, as a fraction
# slowest sampling the fits can use (10 Hz); time in ms at 1 kHz (interval 1) is caught by it
MAX_SAMPLE_INTERVAL_S = 0.1


class MissingColumnError(MeasuredDataError):
    """A column the setup requires is not in the table."""


class ExtraColumnError(MeasuredDataError):
    """A column the setup does not define and the sidecar does not declare (raised by writers:
    :func:`write_dataset`; readers list such columns instead)."""


class NonNumericError(MeasuredDataError):
    """A cell that is not a number."""


class NonFiniteError(MeasuredDataError):
    """NaN or inf in a column."""


class TimeAxisError(MeasuredDataError):
    """Time not strictly increasing or not at a constant sample rate."""


class TooFewSamplesError(MeasuredDataError):
    """Too few rows to replay and hold out samples."""


class UnknownShaftError(MeasuredDataError):
    """The sidecar's shaft is not in the catalogue or outside its validity range."""


@dataclass
class Dataset:
    """A validated dataset. ``columns`` holds float arrays of equal length, time in ``t``."""

    path: Path
    setup: str
    columns: dict[str, FloatArray]
    sidecar: dict[str, Any]
    shaft: ShaftParams
    load_inertia_kgm2: float | None = None  # series bench: None = blocked output
    extra_columns: tuple[str, ...] = field(default=())
    record: Sidecar | None = None  # the typed sidecar (fsarm_sim.records.sidecar)
    declared_columns: tuple[str, ...] = field(default=())  # beyond the setup's

    @property
    def unused_columns(self) -> tuple[str, ...]:
        """Columns of the table the diagnosis does not read (:data:`fsarm_sim.records.sidecar.READ`)."""
        read = set(READ.get(self.setup, ()))
        return tuple(c for c in self.columns if c not in read)

    @property
    def undeclared_columns(self) -> tuple[str, ...]:
        """Columns neither the setup nor the sidecar defines (a misspelt name shows here)."""
        known = set(REQUIRED.get(self.setup, ())) | set(OPTIONAL.get(self.setup, ()))
        known |= set(self.declared_columns) | set(self.extra_columns)
        return tuple(c for c in self.columns if c not in known)

    def column_notes(self) -> list[str]:
        """Report lines on the columns the diagnosis leaves alone (none when it reads all)."""
        out = []
        if self.unused_columns:
            out.append(
                f"columns not used by the diagnosis ({len(self.unused_columns)}): "
                + ", ".join(self.unused_columns)
            )
        if self.undeclared_columns:
            out.append(
                f"columns neither setup '{self.setup}' nor the sidecar defines "
                f"({len(self.undeclared_columns)}): "
                + ", ".join(repr(c) for c in self.undeclared_columns)
                + ' - check their spelling, or list them in the sidecar\'s "extra_columns"'
            )
        return out

    @property
    def t(self) -> FloatArray:
        return self.columns["t"]

    @property
    def n(self) -> int:
        return int(self.columns["t"].size)

    @property
    def dt(self) -> float:
        return float(np.median(np.diff(self.columns["t"])))

    @property
    def input_column(self) -> str:
        return INPUT_COLUMN[self.setup]

    @property
    def output_column(self) -> str:
        return OUTPUT_COLUMN[self.setup]

    @property
    def notes(self) -> str:
        return str(self.sidecar.get("notes", ""))


# ----------------------------------------------------------------------------------- paths


def dataset_files(path: str | Path) -> tuple[Path, Path]:
    """(table, sidecar) that :func:`load_dataset` reads for NAME, NAME.csv, NAME.parquet or
    NAME.json; :class:`MeasuredDataError` when there is no table."""
    return _paths(path)


def output_files(path: str | Path) -> tuple[Path, Path]:
    """(table, sidecar) that :func:`write_dataset` writes for ``path`` (no suffix: CSV)."""
    p = Path(path)
    if p.suffix.lower() not in (".csv", ".parquet"):
        p = p.with_name(p.name + ".csv")
    return p, p.with_suffix(".json")


def _paths(path: str | Path) -> tuple[Path, Path]:
    """(table, sidecar) for NAME, NAME.csv, NAME.parquet or NAME.json."""
    p = Path(path)
    checked_path(p, "dataset", MeasuredDataError)  # loops, long names ...
    if p.suffix.lower() in (".csv", ".parquet"):
        return p, p.with_suffix(".json")
    stem = p.with_suffix("") if p.suffix.lower() == ".json" else p
    for ext in (".csv", ".parquet"):
        cand = stem.with_name(stem.name + ext)
        if cand.is_file():
            return cand, stem.with_name(stem.name + ".json")
    raise MeasuredDataError(
        f"no table for dataset {p}: expected {stem.name}.csv or {stem.name}.parquet in "
        f"{stem.parent or Path('.')}"
    )


# ----------------------------------------------------------------------------------- sidecar


def _number(value: Any, key: str, where: Path, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SidecarError(f"{where}: '{key}' must be a finite number, got {value!r}")
    if positive and value <= 0:
        raise SidecarError(f"{where}: '{key}' must be > 0, got {value!r}")
    return float(value)


def stated_shaft(
    diameter_mm: float = 9.0,
    length_mm: float = 450.0,
    *,
    catalogue: Catalogue | None = None,
    extrapolate: bool = False,
) -> ShaftParams:
    """The shaft a record states, as the diagnosis and the synthetic records take it: the
    catalogue's eq. 3/4 law without series hysteresis, which is an effect the diagnosis names
    (and a synthetic truth lists), never part of the stated nominal."""
    cat = catalogue or load_catalogue()
    return cat.shaft(diameter_mm, length_mm, extrapolate=extrapolate, series_hysteresis=False)


def resolve_shaft(sidecar: Mapping[str, Any] | Sidecar, where: Path) -> ShaftParams:
    """The shaft the sidecar names: ``{"name": ...}`` from the catalogue, or D and L (mm).

    Optional keys: ``"coefficient_file"`` (TOML like the default catalogue, relative to the
    sidecar), ``"extrapolate": true`` (allow D/L outside the catalogue's validity range).
    A record of ``fsarm run`` carries the run's exact shaft in ``shaft_params``: that is used
    (its D and L must agree with ``shaft``).
    """
    if isinstance(sidecar, Sidecar):
        ref = sidecar.shaft
        exact = shaft_params_of(sidecar, where)
        if exact is not None:
            return exact
    else:
        raw = sidecar.get("shaft")
        if not isinstance(raw, dict):
            raise UnknownShaftError(
                f"{where}: 'shaft' must be an object with 'diameter_mm' and 'length_mm' (or "
                f"'name'), got {raw!r}"
            )
        ref = as_record({"setup": "arm", "shaft": raw}, where).shaft
    if ref is None:
        raise UnknownShaftError(
            f"{where}: the sidecar needs 'shaft', an object with 'diameter_mm' and 'length_mm' "
            "(or 'name')"
        )
    return _catalogue_shaft(ref, where)


def _catalogue_shaft(shaft: ShaftRef, where: Path) -> ShaftParams:
    cat: Catalogue
    coef = shaft.coefficient_file
    try:
        if coef is not None:
            cpath = Path(str(coef))
            cat = load_catalogue(cpath if cpath.is_absolute() else where.parent / cpath)
        else:
            cat = load_catalogue()
    except FsarmError as exc:
        raise UnknownShaftError(f"{where}: shaft coefficient file: {exc}") from exc
    if shaft.name is not None and shaft.diameter_mm is None:
        names = {s.name: s for s in cat.shafts}
        entry = names.get(shaft.name)
        if entry is None:
            raise UnknownShaftError(
                f"{where}: shaft name {shaft.name!r} is not in {cat.source}; known: "
                f"{', '.join(sorted(names))} (or give diameter_mm and length_mm)"
            )
        d_mm, l_mm = entry.diameter_mm, entry.length_mm
    else:
        if shaft.diameter_mm is None or shaft.length_mm is None:
            raise UnknownShaftError(
                f"{where}: 'shaft' needs 'diameter_mm' and 'length_mm' (or a catalogue 'name')"
            )
        d_mm = _number(shaft.diameter_mm, "shaft.diameter_mm", where, positive=True)
        l_mm = _number(shaft.length_mm, "shaft.length_mm", where, positive=True)
    try:
        return stated_shaft(d_mm, l_mm, catalogue=cat, extrapolate=bool(shaft.extrapolate))
    except ShaftRangeError as exc:
        raise UnknownShaftError(f"{where}: {exc}") from exc


def _load_inertia(record: Sidecar, where: Path) -> float | None:
    load = record.load
    if load is None or load.type == "blocked":
        return None
    if load.type != "inertia":
        raise SidecarError(
            f'{where}: \'load\' must be {{"type": "blocked"}} or '
            f'{{"type": "inertia", "inertia_kgm2": J}}, got type {load.type!r}'
        )
    if load.inertia_kgm2 is None:
        raise SidecarError(f"{where}: an inertia load needs 'inertia_kgm2' (kg*m^2)")
    return _number(load.inertia_kgm2, "load.inertia_kgm2", where, positive=True)


# ----------------------------------------------------------------------------------- table


def read_table(path: Path) -> tuple[list[str], dict[str, Any]]:
    """Column names and raw column arrays (object arrays for CSV cells that failed to parse) of a
    CSV or Parquet table; a repeated column name or an unreadable file is a named error."""
    import pandas as pd

    if os.path.lexists(path):  # a device or a pipe would never end or never answer
        regular_file(path, "table", MeasuredDataError)
    try:
        if path.suffix.lower() == ".parquet":
            frame = pd.read_parquet(path)
        else:
            frame = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except FileNotFoundError as exc:
        raise MeasuredDataError(f"table {path} not found") from exc
    except Exception as exc:  # pandas/pyarrow raise many types; all mean "unreadable"
        raise MeasuredDataError(f"{path}: cannot read the table ({str(exc).strip()})") from exc
    names = [str(c).strip() for c in frame.columns]
    # pandas renames a repeated CSV header (tau_s, tau_s.1): the header as written decides
    _refuse_repeated(_csv_header(path) if path.suffix.lower() != ".parquet" else names, path)
    cols = {n: frame.iloc[:, i].to_numpy() for i, n in enumerate(names)}
    return names, cols


def _csv_header(path: Path) -> list[str]:
    """The first row of a CSV file as written (names stripped)."""
    import csv

    with (
        named_os_errors("table", path, MeasuredDataError),
        path.open(newline="", encoding="utf-8-sig") as f,
    ):
        return [c.strip() for c in next(csv.reader(f), [])]


def _refuse_repeated(names: list[str], path: Path) -> None:
    """MeasuredDataError for a column name given twice (which one is meant cannot be known)."""
    seen: dict[str, int] = {}
    for i, n in enumerate(names):
        if n in seen:
            raise MeasuredDataError(
                f"{path}: the column name {n!r} is given twice (columns {seen[n] + 1} and "
                f"{i + 1}); every column needs its own name"
            )
        seen[n] = i


def to_float(raw: Any, name: str, path: Path) -> FloatArray:
    """A column as floats; a cell that is not a number is a NonNumericError (an empty one, NaN)."""
    arr = np.asarray(raw)
    if arr.dtype.kind in "fiu":
        return arr.astype(np.float64)
    out = np.empty(arr.size)
    for i, cell in enumerate(arr):
        text = str(cell).strip()
        if text == "":  # an empty CSV cell is a missing value: reported as non-finite
            out[i] = math.nan
            continue
        try:
            out[i] = float(text)
        except ValueError:
            raise NonNumericError(
                f"{path}: column '{name}', row {i} (0-based data row; CSV line {i + 2}): "
                f"{cell!r} is not a number"
            ) from None
    return out


def _guess_setup(names: set[str]) -> str | None:
    for setup, req in REQUIRED.items():
        if set(req) <= names:
            return setup
    return None


def validate_columns(
    setup: str,
    columns: Mapping[str, FloatArray],
    path: Path,
    extra_allowed: tuple[str, ...] = (),
    *,
    strict: bool = False,
) -> None:
    """Check one setup's columns: presence, finiteness, time axis, length. Raises named errors.

    A column neither the setup defines nor ``extra_allowed`` names is accepted (and listed by
    :class:`Dataset`) unless ``strict`` (writers): then :class:`ExtraColumnError`."""
    names = list(columns)
    missing = [c for c in REQUIRED[setup] if c not in columns]
    if missing:
        guess = _guess_setup(set(names))
        hint = f"; the columns look like a '{guess}' dataset" if guess and guess != setup else ""
        err = SetupError if hint else MissingColumnError
        raise err(
            f"{path}: setup '{setup}' needs column(s) {', '.join(repr(c) for c in missing)}"
            f" (required: {', '.join(REQUIRED[setup])}){hint}"
        )
    known = set(REQUIRED[setup]) | set(OPTIONAL[setup]) | set(extra_allowed)
    extra = [c for c in names if c not in known]
    if extra and strict:
        raise ExtraColumnError(
            f"{path}: column(s) {', '.join(repr(c) for c in extra)} are not defined for setup "
            f"'{setup}' (allowed: {', '.join(REQUIRED[setup] + OPTIONAL[setup])}); remove them "
            'or list them in the sidecar as "extra_columns"'
        )
    n = len(columns["t"])
    if n < MIN_SAMPLES:
        raise TooFewSamplesError(
            f"{path}: {n} samples; at least {MIN_SAMPLES} are needed to replay and hold out data"
        )
    for c in names:
        arr = columns[c]
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise NonFiniteError(
                f"{path}: column '{c}', row {int(bad[0])} (0-based data row): "
                f"{float(arr[bad[0]])!r} (NaN also stands for an empty cell); "
                f"{bad.size} non-finite value(s) in all - every value must be a finite number"
            )
    t = columns["t"]
    dt = np.diff(t)
    nonpos = np.flatnonzero(dt <= 0.0)
    if nonpos.size:
        i = int(nonpos[0]) + 1
        raise TimeAxisError(
            f"{path}: column 't' is not strictly increasing at row {i} "
            f"(t[{i - 1}] = {t[i - 1]!r}, t[{i}] = {t[i]!r}); rows must be in time order"
        )
    med = float(np.median(dt))
    if med > MAX_SAMPLE_INTERVAL_S * (1.0 + TIME_JITTER):
        raise TimeAxisError(
            f"{path}: column 't' has a median sample interval of {med:.6g} s (t from {t[0]:.6g} "
            f"to {t[-1]:.6g}); at most {MAX_SAMPLE_INTERVAL_S:g} s is allowed (sample rate >= "
            f"{1 / MAX_SAMPLE_INTERVAL_S:g} Hz). 't' must be in seconds: if it is in "
            "milliseconds, divide it by 1000"
        )
    uneven = np.flatnonzero(np.abs(dt - med) > TIME_JITTER * med)
    if uneven.size:
        i = int(uneven[0]) + 1
        raise TimeAxisError(
            f"{path}: column 't' is not evenly sampled at row {i}: interval "
            f"{dt[i - 1]:.6g} s vs median {med:.6g} s (allowed deviation "
            f"{100 * TIME_JITTER:g} %); resample to a constant rate"
        )


def load_dataset(path: str | Path, *, expect_setup: str | None = None) -> Dataset:
    """Load and validate ``NAME.csv``/``NAME.parquet`` + ``NAME.json``."""
    table, side = _paths(path)
    if os.path.lexists(table):  # a folder, a device or a pipe: named as what it is
        regular_file(table, "table", MeasuredDataError)
    if not table.is_file():
        raise MeasuredDataError(f"table {table} not found")
    record, sidecar = read_sidecar(side)
    setup = record.setup
    if expect_setup is not None and setup != expect_setup:
        raise SetupError(f"{side}: expected a '{expect_setup}' dataset, got setup '{setup}'")
    names, raw = read_table(table)
    if len(set(names)) != len(names):
        dup = sorted({c for c in names if names.count(c) > 1})
        raise SetupError(f"{table}: duplicate column name(s) {dup}")
    columns = {name: to_float(raw[name], name, table) for name in names}
    declared = record.declared_columns()
    validate_columns(setup, columns, table, declared)
    _check_units(record, side)
    shaft = resolve_shaft(record, side)
    inertia = _load_inertia(record, side) if setup == "series_bench" else None
    return Dataset(
        path=table,
        setup=setup,
        columns=columns,
        sidecar=sidecar,
        shaft=shaft,
        load_inertia_kgm2=inertia,
        extra_columns=record.extra_columns,
        record=record,
        declared_columns=declared,
    )


def _check_units(record: Sidecar, where: Path) -> None:
    """A unit the sidecar's ``columns`` states for a column the project names must be the
    project's (SI) unit."""
    for name, unit in (record.columns or {}).items():
        want = UNITS.get(name)
        if want is not None and unit != want:
            raise SidecarError(
                f"{where}: 'columns.{name}' says {unit!r}; column '{name}' is in {want} "
                "(measured data are in SI units: convert the column)"
            )


def write_dataset(
    path: str | Path, columns: Mapping[str, Any], sidecar: Mapping[str, Any] | Sidecar
) -> tuple[Path, Path]:
    """Write ``NAME.csv`` or ``NAME.parquet`` (by suffix; none: CSV) and ``NAME.json``.

    The sidecar is checked against the schema (:mod:`fsarm_sim.records.sidecar`) and the columns
    against its setup (strictly: every column defined or declared) before anything is written.
    """
    p, side = output_files(path)
    record = as_record(sidecar, "sidecar to write for " + str(p))
    cols = {k: np.asarray(v, dtype=np.float64) for k, v in columns.items()}
    validate_columns(record.setup, cols, p, record.declared_columns(), strict=True)
    p.parent.mkdir(parents=True, exist_ok=True)
    import pandas as pd

    frame = pd.DataFrame(cols)
    if p.suffix.lower() == ".parquet":
        frame.to_parquet(p, index=False)
    else:
        frame.to_csv(p, index=False, float_format="%.10g")
    side.write_text(json.dumps(record.to_json(), indent=2) + "\n", "utf-8")
    return p, side
