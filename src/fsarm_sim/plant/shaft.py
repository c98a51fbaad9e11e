"""Shaft catalogue: coefficient files (seed 000 eq. 3/4) and the evaluated shaft parameters.

A coefficient file is TOML with the keys of ``data/shafts.toml`` (the default catalogue).
``load_catalogue(path)`` validates it; ``Catalogue.shaft(D, L)`` evaluates eq. 3 and eq. 4 for one
shaft and refuses D or L outside the validity range unless ``extrapolate=True``.

Parsing is strict (a setting is never silently ignored or misread):

* only the sections and keys of :data:`SCHEMA` are allowed: a misspelt section or key is a
  :class:`CoefficientFileError` naming the file, the section and the key, and listing the allowed
  ones;
* numbers must be TOML numbers (finite), booleans TOML booleans (``enabled = "false"`` - a
  string - is refused, not read as true), names strings;
* ``[meta].units`` (optional; when absent the file is read in the units below) must declare
  exactly the units the coefficients are written in, :data:`UNITS`: diameter and length in mm,
  bend in rad, stiffness in N*m/rad. A file declaring, e.g., ``diameter = "m"`` is refused: the
  polynomials of eq. 3/4 are fitted in mm and would silently give wrong stiffnesses;
* ``[series.maxwell_slip].enabled`` is the file's default for series hysteresis: it takes
  effect wherever the caller leaves ``series_hysteresis`` as None (``Catalogue.shaft``; the CLI
  when neither ``--series-hysteresis`` nor ``--no-series-hysteresis`` is given); an explicit
  True/False from the caller wins. Switching it on with no element of non-zero stiffness is an
  error (it would do nothing);
* ``[validity].bend_rad`` bounds the bend angle |phi_B| everywhere it is used - bench, sweep and
  arm runs (joint 2's reference, ``model.build_model``) - through one check,
  :func:`check_bend_rad`;
* ``[series].length_law`` ("affine": eq. 3 as printed, the default when absent; "inverse": eq. 3
  at ``reference_length_mm`` scaled by L_ref / L, with p4 = 0) - the length law of eq. 3
  (:mod:`fsarm_sim.plant.effects.series_stiffness`);
* eq. 3 and eq. 4 are what the paper's own identification returns (Sec. III-B): eq. 4 is the
  slope of eq. 2's linear fit over the test declared by ``[bending].eq2_test_amplitude_rad`` and
  ``eq2_test_period_s`` (both or neither), so the elastic ``ShaftParams.kb`` is eq. 4 over that
  fit's gain (:meth:`Catalogue.eq2_fit_gain`; ``ShaftParams.kb_eq4`` keeps eq. 4); eq. 3 is the
  slope of the series test, so while the slip elements are on the plant's spring is eq. 3 less
  their apparent stiffness, ``[series.maxwell_slip].apparent_stiffness_pos/_neg``
  (``ShaftParams.slip_apparent``, :meth:`ShaftParams.k_spring`). The controller's eq. 8 and
  every "K_s" the studies report stay eq. 3.
"""

from __future__ import annotations

import difflib
import math
import os
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from fsarm_sim.errors import CoefficientFileError
from fsarm_sim.paths import bounded_toml, regular_file
from fsarm_sim.plant.shaft_params import PROTOTYPE_DIAMETER_MM as PROTOTYPE_DIAMETER_MM
from fsarm_sim.plant.shaft_params import PROTOTYPE_LENGTH_MM as PROTOTYPE_LENGTH_MM
from fsarm_sim.plant.shaft_params import UNCERTAINTY_GROUPS as UNCERTAINTY_GROUPS
from fsarm_sim.plant.shaft_params import Catalogue as Catalogue
from fsarm_sim.plant.shaft_params import CatalogueShaft as CatalogueShaft
from fsarm_sim.plant.shaft_params import CoefficientRange as CoefficientRange
from fsarm_sim.plant.shaft_params import ShaftParams as ShaftParams
from fsarm_sim.plant.shaft_params import check_bend_rad as check_bend_rad

DEFAULT_CATALOGUE = "shafts.toml"


# Every section ("" = the top level, "shafts[]" = each [[shafts]] entry) and the keys it may hold;
# a key that is itself listed here is a sub-section (a table).
SCHEMA: dict[str, tuple[str, ...]] = {
    "": ("meta", "validity", "series", "bending", "rating", "uncertainty", "shafts"),
    "meta": ("name", "description", "source", "units"),
    "meta.units": ("diameter", "length", "bend", "stiffness"),
    "validity": ("diameter_mm", "length_mm", "bend_rad"),
    "series": (
        "positive",
        "negative",
        "dynamic",
        "maxwell_slip",
        "length_law",
        "reference_length_mm",
    ),
    "series.positive": ("p",),
    "series.negative": ("p",),
    "series.dynamic": ("inertia_kgm2", "damping_pos_nms", "damping_neg_nms"),
    "series.maxwell_slip": (
        "enabled",
        "stiffness_fraction",
        "slip_torque_fraction",
        "unwinding_ratio",
        "bend_friction_per_rad",
        "apparent_stiffness_pos",
        "apparent_stiffness_neg",
    ),
    "bending": (
        "q",
        "stiffening_per_rad2",
        "conduit",
        "eq2_test_amplitude_rad",
        "eq2_test_period_s",
    ),
    "bending.conduit": ("branch_stiffness_fraction", "branch_time_constant_s"),
    "rating": ("coefficient_nm_per_mm3",),
    "uncertainty": UNCERTAINTY_GROUPS,
    **{f"uncertainty.{g}": ("relative", "reason") for g in UNCERTAINTY_GROUPS},
    "shafts[]": ("name", "diameter_mm", "length_mm"),
}
# [meta].units: the units the coefficients are written in (the only ones accepted), with the
# spellings accepted for each.
UNITS: dict[str, tuple[str, ...]] = {
    "diameter": ("mm",),
    "length": ("mm",),
    "bend": ("rad",),
    "stiffness": ("N*m/rad", "N·m/rad", "Nm/rad", "N m/rad", "N.m/rad"),
}


def _type_name(value: Any) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def _unknown(source: str, where: str, key: str, value: Any, allowed: tuple[str, ...]) -> str:
    prefix = f"{where}." if where else ""
    if isinstance(value, dict):
        what = f"section '{prefix}{key}'"
    else:
        what = f"key '{key}' in section '{where}'" if where else f"top-level key '{key}'"
    near = (
        difflib.get_close_matches(key, allowed, n=1, cutoff=0.5)
        or [a for a in allowed if a.startswith(key) or key.startswith(a)][:1]
    )
    hint = (
        f" (did you mean '{prefix if isinstance(value, dict) else ''}{near[0]}'?)" if near else ""
    )
    place = f"section '{where}'" if where else "the top level"
    return f"{source}: unknown {what}{hint}; allowed in {place}: {', '.join(allowed)}"


def _check_keys(table: dict[str, Any], where: str, source: str) -> None:
    """Refuse keys and sections that :data:`SCHEMA` does not list, recursively."""
    schema_key = "shafts[]" if where.startswith("shafts[") else where
    allowed = SCHEMA[schema_key]
    for key, value in table.items():
        if key not in allowed:
            raise CoefficientFileError(_unknown(source, where, key, value, allowed))
        sub = f"{where}.{key}" if where else key
        if sub == "shafts":
            if not isinstance(value, list):
                raise CoefficientFileError(
                    f"{source}: 'shafts' must be an array of tables (one table per shaft), "
                    f"got {_type_name(value)}"
                )
            for i, entry in enumerate(value):
                if not isinstance(entry, dict):
                    raise CoefficientFileError(
                        f"{source}: shafts[{i}] must be a table with name, diameter_mm, "
                        f"length_mm, got {_type_name(entry)}"
                    )
                _check_keys(entry, f"shafts[{i}]", source)
        elif sub in SCHEMA:
            if not isinstance(value, dict):
                raise CoefficientFileError(
                    f"{source}: '{sub}' must be a table (a section) with keys "
                    f"{', '.join(SCHEMA[sub])}, got {_type_name(value)} {value!r}"
                )
            _check_keys(value, sub, source)


def _check_units(units: Any, source: str) -> None:
    """``[meta].units`` must declare the units the coefficients are written in."""
    if units is None:
        return
    assert isinstance(units, dict)  # _check_keys: a table with known keys only
    for key, value in units.items():
        accepted = UNITS[key]
        if not isinstance(value, str) or value.strip() not in accepted:
            raise CoefficientFileError(
                f"{source}: 'meta.units.{key}' = {value!r} is not supported: the coefficients of "
                f"a coefficient file are written with {key} in {accepted[0]!r} "
                f"(accepted spellings: {', '.join(repr(a) for a in accepted)}); convert the "
                "coefficients to these units and declare them"
            )


def _bool(value: Any, dotted: str, source: str) -> bool:
    if not isinstance(value, bool):
        raise CoefficientFileError(
            f"{source}: '{dotted}' must be true or false (a TOML boolean, without quotes), "
            f"got {_type_name(value)} {value!r}"
        )
    return value


def _string(value: Any, dotted: str, source: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise CoefficientFileError(
            f"{source}: '{dotted}' must be a non-empty string, got {_type_name(value)} {value!r}"
        )
    return value


def _get(table: dict[str, Any], dotted: str, source: str) -> Any:
    node: Any = table
    for key in dotted.split("."):
        if not isinstance(node, dict) or key not in node:
            raise CoefficientFileError(f"{source}: missing key '{dotted}'")
        node = node[key]
    return node


def _floats(
    value: Any, n: int, dotted: str, source: str, *, positive: bool = False
) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise CoefficientFileError(
            f"{source}: '{dotted}' must be a list of {n} numbers, got {value!r}"
        )
    out = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(float(v)):
            raise CoefficientFileError(
                f"{source}: '{dotted}'[{i}] must be a finite number, got {v!r}"
            )
        if positive and float(v) < 0.0:
            raise CoefficientFileError(f"{source}: '{dotted}'[{i}] must be >= 0, got {v!r}")
        out.append(float(v))
    return tuple(out)


def _float(value: Any, dotted: str, source: str, *, minimum: float | None = None) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(float(value))
    ):
        raise CoefficientFileError(f"{source}: '{dotted}' must be a finite number, got {value!r}")
    if minimum is not None and float(value) < minimum:
        raise CoefficientFileError(f"{source}: '{dotted}' must be >= {minimum}, got {value!r}")
    return float(value)


def _positive(value: Any, dotted: str, source: str) -> float:
    v = _float(value, dotted, source)
    if v <= 0.0:
        raise CoefficientFileError(f"{source}: '{dotted}' must be > 0, got {value!r}")
    return v


def _floats_at(
    data: dict[str, Any], dotted: str, n: int, source: str, *, positive: bool = False
) -> tuple[float, ...]:
    """The ``n`` numbers at the required key ``dotted``."""
    return _floats(_get(data, dotted, source), n, dotted, source, positive=positive)


def _float_at(table: dict[str, Any], key: str, dotted: str, source: str) -> float:
    """The number >= 0 at the optional ``key`` of ``table`` (``dotted``: its full name), 0 when
    absent."""
    return _float(table.get(key, 0.0), dotted, source, minimum=0.0)


def _bending(data: dict[str, Any], source: str) -> dict[str, Any]:
    """``[bending]``: eq. 4's coefficients, the stiffening and the conduit's two branches."""
    q_bend = _floats_at(data, "bending.q", 5, source)
    beta = _float(
        _get(data, "bending.stiffening_per_rad2", source),
        "bending.stiffening_per_rad2",
        source,
        minimum=0.0,
    )
    frac = _floats_at(data, "bending.conduit.branch_stiffness_fraction", 2, source, positive=True)
    tau = _floats_at(data, "bending.conduit.branch_time_constant_s", 2, source, positive=True)
    if min(tau) <= 0.0:
        raise CoefficientFileError(
            f"{source}: 'bending.conduit.branch_time_constant_s' must be > 0, got {tau}"
        )
    return {
        "q_bend": q_bend,
        "beta": beta,
        "conduit_fraction": (frac[0], frac[1]),
        "conduit_tau": (tau[0], tau[1]),
    }


def _validity(data: dict[str, Any], source: str) -> dict[str, Any]:
    """``[validity]``: the ranges of diameter, length and bend the fit covers."""
    d_rng = _floats_at(data, "validity.diameter_mm", 2, source, positive=True)
    l_rng = _floats_at(data, "validity.length_mm", 2, source, positive=True)
    b_rng = _floats_at(data, "validity.bend_rad", 2, source)
    for name, rng in (
        ("validity.diameter_mm", d_rng),
        ("validity.length_mm", l_rng),
        ("validity.bend_rad", b_rng),
    ):
        if rng[0] >= rng[1]:
            raise CoefficientFileError(
                f"{source}: '{name}' must be [low, high] with low < high, got {list(rng)}"
            )
    return {
        "diameter_range": (d_rng[0], d_rng[1]),
        "length_range": (l_rng[0], l_rng[1]),
        "bend_range": (b_rng[0], b_rng[1]),
    }


def _maxwell_slip(slip: dict[str, Any], source: str) -> dict[str, Any]:
    """``[series.maxwell_slip]``: the slip elements (all zero when absent)."""
    slip_k = _floats(
        slip.get("stiffness_fraction", [0.0, 0.0, 0.0]),
        3,
        "series.maxwell_slip.stiffness_fraction",
        source,
        positive=True,
    )
    slip_f = _floats(
        slip.get("slip_torque_fraction", [0.0, 0.0, 0.0]),
        3,
        "series.maxwell_slip.slip_torque_fraction",
        source,
        positive=True,
    )
    for i, (k, f) in enumerate(zip(slip_k, slip_f, strict=True)):
        if k > 0.0 and f <= 0.0:
            raise CoefficientFileError(
                f"{source}: Maxwell-slip element {i + 1} has stiffness_fraction {k:g} > 0 but "
                f"slip_torque_fraction {f:g}: an element with stiffness needs a slip torque > 0 "
                "(or set both to 0 to leave it out)"
            )
    slip_enabled = _bool(slip.get("enabled", False), "series.maxwell_slip.enabled", source)
    if slip_enabled and max(slip_k) <= 0.0:
        raise CoefficientFileError(
            f"{source}: 'series.maxwell_slip.enabled' is true but no element has a "
            "stiffness_fraction > 0, so series hysteresis would have no effect; give "
            "stiffness_fraction and slip_torque_fraction (3 numbers each)"
        )
    unwinding = _float(
        slip.get("unwinding_ratio", 1.0), "series.maxwell_slip.unwinding_ratio", source, minimum=0.0
    )
    if unwinding <= 0.0:
        raise CoefficientFileError(
            f"{source}: 'series.maxwell_slip.unwinding_ratio' must be > 0 (unwinding-side slip "
            f"torque / winding-side), got {unwinding:g}"
        )
    return {
        "slip_enabled": slip_enabled,
        "slip_k_fraction": (slip_k[0], slip_k[1], slip_k[2]),
        "slip_f_fraction": (slip_f[0], slip_f[1], slip_f[2]),
        "slip_unwinding_ratio": unwinding,
    }


def _apparent_stiffness(slip: dict[str, Any], source: str) -> tuple[float, float, float, float]:
    """``series.maxwell_slip.apparent_stiffness_pos/neg``: two numbers each (zero when absent)."""
    pos, neg = (
        _floats(
            slip.get(f"apparent_stiffness_{side}", [0.0, 0.0]),
            2,
            f"series.maxwell_slip.apparent_stiffness_{side}",
            source,
        )
        for side in ("pos", "neg")
    )
    return (pos[0], pos[1], neg[0], neg[1])


def _catalogue_shafts(data: dict[str, Any], source: str) -> tuple[CatalogueShaft, ...]:
    """``[[shafts]]``: the named shafts, each with a diameter and a length > 0."""
    shafts: list[CatalogueShaft] = []
    for i, entry in enumerate(data.get("shafts", [])):
        name = _string(entry.get("name", f"shaft{i}"), f"shafts[{i}].name", source)
        if any(s.name == name for s in shafts):
            raise CoefficientFileError(f"{source}: shafts[{i}].name {name!r} is used twice")
        where = f"shafts[{i}] ({name})"
        for key in ("diameter_mm", "length_mm"):
            if key not in entry:
                raise CoefficientFileError(f"{source}: {where} lacks '{key}'")
        shafts.append(
            CatalogueShaft(
                name=name,
                diameter_mm=_positive(entry["diameter_mm"], f"shafts[{i}].diameter_mm", source),
                length_mm=_positive(entry["length_mm"], f"shafts[{i}].length_mm", source),
            )
        )
    return tuple(shafts)


def parse_catalogue(data: dict[str, Any], source: str) -> Catalogue:
    """Validate a parsed coefficient table; every problem is a CoefficientFileError.

    Strict: unknown sections/keys, wrong types and undeclared units are errors (module docstring).
    """
    if not isinstance(data, dict):
        raise CoefficientFileError(f"{source}: must be a TOML table, got {_type_name(data)}")
    _check_keys(data, "", source)
    meta = data.get("meta", {})
    for key in ("name", "description", "source"):
        if key in meta:
            _string(meta[key], f"meta.{key}", source)
    _check_units(meta.get("units"), source)
    p_pos = _floats_at(data, "series.positive.p", 7, source)
    p_neg = _floats_at(data, "series.negative.p", 7, source)
    kw: dict[str, Any] = {**_bending(data, source), **_validity(data, source)}
    kw["rating_coefficient"] = _float(
        _get(data, "rating.coefficient_nm_per_mm3", source),
        "rating.coefficient_nm_per_mm3",
        source,
        minimum=0.0,
    )
    series = data.get("series", {})
    dyn = series.get("dynamic", {})
    slip = series.get("maxwell_slip", {})
    kw.update(_maxwell_slip(slip, source))
    kw["series_reference_length_mm"] = _length_law(series, p_pos, p_neg, source)
    kw["slip_apparent_fraction"] = _apparent_stiffness(slip, source)
    kw["eq2_test_amplitude_rad"], kw["eq2_test_period_s"] = _eq2_test(
        data.get("bending", {}), source
    )
    kw["uncertainty"] = _uncertainty(data.get("uncertainty", {}), source)
    kw["shafts"] = _catalogue_shafts(data, source)
    return Catalogue(
        source=source,
        p_pos=p_pos,
        p_neg=p_neg,
        inertia_kgm2=_float_at(dyn, "inertia_kgm2", "series.dynamic.inertia_kgm2", source),
        damping_pos=_float_at(dyn, "damping_pos_nms", "series.dynamic.damping_pos_nms", source),
        damping_neg=_float_at(dyn, "damping_neg_nms", "series.dynamic.damping_neg_nms", source),
        bend_friction_per_rad=_float_at(
            slip, "bend_friction_per_rad", "series.maxwell_slip.bend_friction_per_rad", source
        ),
        **kw,
    )


def _uncertainty(table: dict[str, Any], source: str) -> tuple[CoefficientRange, ...]:
    """``[uncertainty.<group>]``: ``relative = [low, high]`` with 0 < low <= 1 <= high (the
    nominal value inside its own range) and a non-empty ``reason``."""
    out = []
    for group in UNCERTAINTY_GROUPS:
        if group not in table:
            continue
        entry = table[group]
        where = f"uncertainty.{group}"
        if not isinstance(entry, dict):
            raise CoefficientFileError(
                f"{source}: '{where}' must be a table with relative = [low, high] and reason"
            )
        for key in ("relative", "reason"):
            if key not in entry:
                raise CoefficientFileError(f"{source}: '{where}' lacks '{key}'")
        low, high = _floats(entry["relative"], 2, f"{where}.relative", source)
        if not 0.0 < low <= 1.0 <= high:
            raise CoefficientFileError(
                f"{source}: '{where}.relative' must be [low, high] factors on the nominal value "
                f"with 0 < low <= 1 <= high, got {[low, high]}"
            )
        reason = _string(entry["reason"], f"{where}.reason", source)
        out.append(CoefficientRange(group, low, high, reason))
    return tuple(out)


LENGTH_LAWS = ("affine", "inverse")


def _length_law(
    series: dict[str, Any], p_pos: tuple[float, ...], p_neg: tuple[float, ...], source: str
) -> float:
    """``series.length_law`` ("affine": eq. 3 as printed, the default; "inverse": K ~ L_ref/L
    with ``series.reference_length_mm``): the reference length, 0 for the affine law."""
    law = series.get("length_law", "affine")
    if not isinstance(law, str) or law not in LENGTH_LAWS:
        raise CoefficientFileError(
            f"{source}: 'series.length_law' must be one of {', '.join(repr(x) for x in LENGTH_LAWS)}"
            f" (a string), got {law!r}"
        )
    if law == "affine":
        if "reference_length_mm" in series:
            raise CoefficientFileError(
                f"{source}: 'series.reference_length_mm' is only read with length_law = "
                "'inverse'; remove it or declare the law"
            )
        return 0.0
    if "reference_length_mm" not in series:
        raise CoefficientFileError(
            f"{source}: length_law = 'inverse' needs 'series.reference_length_mm' (the length at "
            "which eq. 3 is evaluated before scaling by L_ref / L)"
        )
    ref = _positive(series["reference_length_mm"], "series.reference_length_mm", source)
    for side, p in (("positive", p_pos), ("negative", p_neg)):
        if p[4] != 0.0:
            raise CoefficientFileError(
                f"{source}: with length_law = 'inverse' the length enters as L_ref / L, so "
                f"'series.{side}.p'[4] (eq. 3's p4 L term) must be 0, got {p[4]!r}; fold "
                "p4 * L_ref into p0"
            )
    return ref


def _eq2_test(bending_table: dict[str, Any], source: str) -> tuple[float, float]:
    """``bending.eq2_test_amplitude_rad`` and ``eq2_test_period_s``: both or neither."""
    keys = ("eq2_test_amplitude_rad", "eq2_test_period_s")
    given = [k for k in keys if k in bending_table]
    if not given:
        return 0.0, 0.0
    if len(given) == 1:
        missing = next(k for k in keys if k not in given)
        raise CoefficientFileError(
            f"{source}: 'bending.{given[0]}' needs 'bending.{missing}' too (the sinusoidal bend "
            "at which eq. 4's K_b was identified by eq. 2's linear fit)"
        )
    amp = _positive(bending_table[keys[0]], f"bending.{keys[0]}", source)
    period = _positive(bending_table[keys[1]], f"bending.{keys[1]}", source)
    return amp, period


def catalogue_text(path: str | Path | None = None) -> str:
    """The coefficient file's text with its comments (None: the default catalogue), checked to
    load: ``fsarm shafts --export`` writes it as the template of a user's own file."""
    load_catalogue(path)
    if path is None:
        return resources.files("fsarm_sim.data").joinpath(DEFAULT_CATALOGUE).read_text("utf-8")
    return Path(path).read_text("utf-8")


def load_catalogue(path: str | Path | None = None) -> Catalogue:
    """Load and validate a coefficient file; None loads the default (estimated) catalogue."""
    if path is None:
        text = resources.files("fsarm_sim.data").joinpath(DEFAULT_CATALOGUE).read_text("utf-8")
        source = f"default catalogue ({DEFAULT_CATALOGUE})"
    else:
        p = Path(path)
        if os.path.lexists(p):  # a loop, a long name, a folder, a device or a pipe: named
            regular_file(p, "coefficient file", CoefficientFileError)
        if not p.is_file():
            raise CoefficientFileError(
                f"coefficient file not found: {p} (expected a TOML file like the default shafts.toml)"
            )
        try:
            text = p.read_text("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise CoefficientFileError(f"cannot read coefficient file {p}: {exc}") from exc
        source = str(p)
    try:
        data = bounded_toml(text, source, CoefficientFileError)
    except tomllib.TOMLDecodeError as exc:
        raise CoefficientFileError(f"{source}: not valid TOML ({exc})") from exc
    return parse_catalogue(data, source)
