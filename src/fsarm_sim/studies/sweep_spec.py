"""A sweep's spec: the fields it may vary, values as written on the command line or in a file, the
spec built from them.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.engine.model import Gains
from fsarm_sim.errors import FsarmError
from fsarm_sim.paths import bounded_toml, checked_path, regular_file

POINT_SCHEMA = 1  # bump when the meaning of a point's inputs or outputs changes
MAX_POINTS = 100_000
OUTPUTS: tuple[str, ...] = ("bench", "tracking", "bandwidth", "relief")
DEFAULT_OUTPUTS = OUTPUTS
BENCH_DEFAULTS: dict[str, Any] = {"chirp_s": 4.0, "bend_period_s": 4.0}  # shorter than a campaign
BANDWIDTH_KEYS = ("chirp_s", "settle_s", "f_start_hz", "f_stop_hz", "q3_deg")
TOP_KEYS = {
    "name",
    "outputs",
    "shaft_file",
    "extrapolate",
    "backend",
    "grid",
    "fixed",
    "bench",
    "bandwidth",
}


class SweepSpecError(FsarmError, ValueError):
    """A sweep specification is malformed or asks for points that cannot be computed."""


# ----------------------------------------------------------------------------------------------
# fields


@dataclass(frozen=True)
class FieldInfo:
    name: str
    kind: str  # "float", "str", "bool"
    unit: str
    help: str
    default: Any
    minimum: float | None = None
    maximum: float | None = None


GAIN_TUPLES = {"wn": "wn_rad_s", "zeta": "zeta"}
_GAIN_SKIP = {"ctrl_dt_s"}  # must stay a whole multiple of the timestep: not a sweep axis


def _gain_fields() -> dict[str, FieldInfo]:
    out: dict[str, FieldInfo] = {}
    defaults = Gains()
    for f in dataclasses.fields(Gains):
        if f.name in _GAIN_SKIP:
            continue
        value = getattr(defaults, f.name)
        if isinstance(value, bool):
            out[f"gains.{f.name}"] = FieldInfo(f"gains.{f.name}", "bool", "", "switch", value)
        elif isinstance(value, int | float):
            out[f"gains.{f.name}"] = FieldInfo(
                f"gains.{f.name}", "float", "", "controller gain (model.Gains)", float(value), 0.0
            )
        elif isinstance(value, tuple):
            short = next((k for k, v in GAIN_TUPLES.items() if v == f.name), None)
            if short is None:
                continue
            for i, v in enumerate(value):
                name = f"gains.{short}{i + 1}"
                out[name] = FieldInfo(
                    name, "float", "", f"{f.name}[{i}] (joint {i + 1})", float(v), 0.0
                )
    return out


def _base_fields() -> dict[str, FieldInfo]:
    return {
        "diameter_mm": FieldInfo("diameter_mm", "float", "mm", "shaft diameter D", 9.0),
        "length_mm": FieldInfo("length_mm", "float", "mm", "shaft length L", 450.0),
        "bend_deg": FieldInfo(
            "bend_deg", "float", "deg", "bend angle phi_B (bench; arm joint-2 hold)", 45.0
        ),
        "payload_kg": FieldInfo(
            "payload_kg", "float", "kg", "payload (default: scenario's)", None, 0.0, 15.0
        ),
        "scenario": FieldInfo("scenario", "str", "", "arm scenario", "fig14-sine"),
        "duration_s": FieldInfo(
            "duration_s", "float", "s", "arm run length (default: scenario's)", None, 0.0, 3600.0
        ),
    }


def fields() -> dict[str, FieldInfo]:
    """Every field a sweep may set, by name."""
    return {**_base_fields(), **_gain_fields()}


# ----------------------------------------------------------------------------------------------
# the spec


@dataclass(frozen=True)
class SweepSpec:
    name: str
    grid: dict[str, tuple[Any, ...]]
    fixed: dict[str, Any] = field(default_factory=dict)
    outputs: tuple[str, ...] = DEFAULT_OUTPUTS
    shaft_file: str | None = None
    extrapolate: bool = False
    backend: str = "native"
    bench: dict[str, Any] = field(default_factory=dict)
    bandwidth: dict[str, Any] = field(default_factory=dict)

    @property
    def n_points(self) -> int:
        return math.prod(len(v) for v in self.grid.values()) if self.grid else 1


def parse_number(field_name: str, raw: Any) -> float:
    if isinstance(raw, bool):
        raise SweepSpecError(f"{field_name}: expected a number, got {raw!r}")
    if isinstance(raw, int | float):
        v = float(raw)
    elif isinstance(raw, str):
        try:
            v = float(raw.strip())
        except ValueError:
            raise SweepSpecError(f"{field_name}: {raw!r} is not a number") from None
    else:
        raise SweepSpecError(f"{field_name}: expected a number, got {raw!r}")
    if not math.isfinite(v):
        raise SweepSpecError(f"{field_name}: {raw!r} is not a finite number (NaN/inf not allowed)")
    return v


def _bool(field_name: str, raw: Any) -> bool:
    if isinstance(raw, bool):
        return raw
    if isinstance(raw, str) and raw.strip().lower() in ("true", "false", "1", "0", "on", "off"):
        return raw.strip().lower() in ("true", "1", "on")
    raise SweepSpecError(f"{field_name}: expected true or false, got {raw!r}")


def scalar_value(info: FieldInfo, raw: Any) -> Any:
    if info.kind == "float":
        return parse_number(info.name, raw)
    if info.kind == "bool":
        return _bool(info.name, raw)
    if not isinstance(raw, str) or not raw.strip():
        raise SweepSpecError(f"{info.name}: expected a non-empty name, got {raw!r}")
    return raw.strip()


def _linspace(name: str, start: Any, stop: Any, num: Any) -> tuple[float, ...]:
    a, b = parse_number(name, start), parse_number(name, stop)
    n = parse_number(name, num)
    if n != int(n) or n < 1:
        raise SweepSpecError(
            f"{name}: the count of a range must be a whole number >= 1, got {num!r}"
        )
    if n > MAX_POINTS:  # refused before numpy makes the values
        raise SweepSpecError(
            f"{name}: a range of {num!r} values; one spec may have at most {MAX_POINTS} points"
        )
    n_i = int(n)
    if a > b:
        raise SweepSpecError(
            f"{name}: reversed range {a:g}:{b:g} (start must be <= stop; write {b:g}:{a:g}:{n_i})"
        )
    if n_i == 1 and a != b:
        raise SweepSpecError(
            f"{name}: a range {a:g}:{b:g} with count 1 is ambiguous; give a single value or count >= 2"
        )
    if n_i > 1 and a == b:
        raise SweepSpecError(f"{name}: empty range {a:g}:{b:g} with count {n_i} (start == stop)")
    return tuple(float(v) for v in np.linspace(a, b, n_i))


def parse_values(info: FieldInfo, raw: Any) -> tuple[Any, ...]:
    """Grid values of one field from a CLI string, a TOML list, or a TOML range table."""
    name = info.name
    if isinstance(raw, Mapping):
        unknown = set(raw) - {"start", "stop", "num"}
        if unknown or not {"start", "stop", "num"} <= set(raw):
            raise SweepSpecError(
                f"{name}: a range table needs exactly start, stop, num; got {sorted(raw)}"
            )
        if info.kind != "float":
            raise SweepSpecError(f"{name}: ranges need a numeric field")
        values: tuple[Any, ...] = _linspace(name, raw["start"], raw["stop"], raw["num"])
    elif isinstance(raw, list | tuple):
        if not raw:
            raise SweepSpecError(f"{name}: empty list of values")
        values = tuple(scalar_value(info, v) for v in raw)
    elif isinstance(raw, str):
        text = raw.strip()
        if not text:
            raise SweepSpecError(f"{name}: no values given (expected e.g. 4:13:4 or 4,6,8)")
        if ":" in text and info.kind == "float":
            parts = text.split(":")
            if len(parts) != 3 or not all(p.strip() for p in parts):
                raise SweepSpecError(
                    f"{name}: a range is start:stop:count (e.g. 4:13:4), got {text!r}"
                )
            values = _linspace(name, *parts)
        else:
            items = [p.strip() for p in text.split(",")]
            if any(not p for p in items):
                raise SweepSpecError(f"{name}: empty item in the list {text!r}")
            values = tuple(scalar_value(info, p) for p in items)
    else:
        values = (scalar_value(info, raw),)
    if len(set(values)) != len(values):
        dup = next(v for v in values if values.count(v) > 1)
        raise SweepSpecError(f"{name}: value {dup!r} is repeated")
    return values


def field_info(name: str) -> FieldInfo:
    known = fields()
    if name not in known:
        raise SweepSpecError(
            f"unknown sweep field {name!r}; allowed fields: {', '.join(sorted(known))}"
        )
    return known[name]


def parse_assignment(text: str) -> tuple[str, str]:
    """``FIELD=VALUES`` -> (field, values text)."""
    if "=" not in text:
        raise SweepSpecError(f"expected FIELD=VALUES, got {text!r}")
    name, _, values = text.partition("=")
    return name.strip(), values


def load_spec_file(path: str | Path) -> dict[str, Any]:
    p = Path(path)
    checked_path(p, "sweep spec file", SweepSpecError)  # loops, long names ...
    if os.path.lexists(p):  # a folder, a device or a pipe: named
        regular_file(p, "sweep spec file", SweepSpecError)
    if not p.is_file():
        raise SweepSpecError(f"sweep spec file not found: {p}")
    try:
        data = bounded_toml(p.read_text("utf-8"), str(p), SweepSpecError)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, OSError) as exc:
        raise SweepSpecError(f"{p}: not a readable TOML sweep spec ({exc})") from exc
    unknown = set(data) - TOP_KEYS
    if unknown:
        raise SweepSpecError(
            f"{p}: unknown keys {sorted(unknown)}; allowed: {', '.join(sorted(TOP_KEYS))}"
        )
    if isinstance(data.get("shaft_file"), str) and not Path(data["shaft_file"]).is_absolute():
        data["shaft_file"] = str(
            checked_path(p.parent / data["shaft_file"], f"{p}: shaft_file", SweepSpecError)
        )
    return data
