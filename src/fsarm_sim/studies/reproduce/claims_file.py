"""The papers' claims as data files: ``fsarm_sim/data/claims/NNN.toml``, one per seed paper.

A file names its paper and lists its claims as ``[[claim]]`` tables, each with a
``[claim.tolerance]`` table whose ``kind`` is a tolerance class of :mod:`.claims`::

    paper = "000"

    [[claim]]
    id = "000-series-k-linear-in-bend"     # starts with the paper
    title = "series stiffness falls linearly with bend"
    locator = "Sec. V; Sec. III-B1 eq. 3, Fig. 8"
    quote = "Torsional stiffness decreases linearly with bending angle"
    paper_text = "K(φ_B) linear (R² of a straight line, per side)"
    unit = "-"
    measure = "series_k_linearity"          # or not_implemented / uncheckable = "why"
    role = "consistency"                    # prediction, calibration or consistency
    role_why = "eq. 3 is linear in |φ_B| ..."

    [claim.tolerance]
    kind = "AtLeast"
    threshold = 0.98
    partly = 0.9

The keys of a claim are the fields of :class:`.claims.Claim` (``paper`` comes from the file); those
of a tolerance are the fields of its class. Reading is strict: an unknown key, a missing required
one, an unknown tolerance kind or a value of the wrong type is a :class:`ClaimsFileError` naming the
file, the claim and the key, and saying what is allowed. Every claim read is validated
(:meth:`.claims.Claim.validate`). The files are read on first use, once per process.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import tomllib
import types
import typing
from importlib import resources
from pathlib import Path
from typing import Any

from fsarm_sim.studies.reproduce.claims import PAPERS, Claim, ClaimError, Tolerance

# the tolerance classes by name: a claim's ``[claim.tolerance]`` names one as its ``kind``
KINDS: dict[str, type[Tolerance]] = {cls.__name__: cls for cls in typing.get_args(Tolerance)}
# required in every claim though the dataclass has a default (the reader must see them)
REQUIRED_CLAIM_KEYS = ("role", "role_why")
_FROM_FILE = ("paper",)  # claim fields set from the file, not from a claim's table


class ClaimsFileError(ClaimError):
    """A claims file that cannot be read: names the file, the claim, the key and what is allowed."""


def _describe(hint: Any) -> str:
    """A type hint in the file's words."""
    if hint is float:
        return "a finite number"
    if hint is int:
        return "an integer"
    if hint is bool:
        return "true or false"
    if hint is str:
        return "a string"
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(hint))
    if origin is tuple:
        return "a list of strings"
    if origin in (types.UnionType, typing.Union):
        inner = [a for a in typing.get_args(hint) if a is not type(None)]
        return " or ".join(_describe(a) for a in inner)
    raise TypeError(f"no file form for the type {hint!r}")  # a new field type: teach _convert it


def _convert(value: Any, hint: Any) -> tuple[bool, Any]:
    """(ok, value as the field holds it) for a TOML value and a field's type hint."""
    if hint is float:
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        return ok, float(value) if ok else None
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool), value
    if hint is bool:
        return isinstance(value, bool), value
    if hint is str:
        return isinstance(value, str), value
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return value in typing.get_args(hint), value
    if origin is tuple:
        ok = isinstance(value, list) and all(isinstance(v, str) for v in value)
        return ok, tuple(value) if ok else None
    if origin in (types.UnionType, typing.Union):
        for arg in typing.get_args(hint):
            if arg is type(None):
                continue
            ok, converted = _convert(value, arg)
            if ok:
                return ok, converted
        return False, None
    raise TypeError(f"no file form for the type {hint!r}")


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def _fields(
    cls: type, where: str, table: Any, skip: tuple[str, ...] = (), extra: tuple[str, ...] = ()
) -> dict[str, Any]:
    """The dataclass ``cls``'s keyword arguments from a TOML table, strictly (``skip``: fields
    not taken from the table; ``extra``: keys of the table read by the caller)."""
    if not isinstance(table, dict):
        raise ClaimsFileError(f"{where}: must be a table, got {table!r}")
    hints = _hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.name not in skip}
    unknown = sorted(set(table) - set(fields) - set(extra))
    if unknown:
        allowed = ", ".join((*fields, *extra))
        raise ClaimsFileError(f"{where}: unknown key {unknown[0]!r}; allowed: {allowed}")
    out: dict[str, Any] = {}
    for name, f in fields.items():
        no_default = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if name not in table:
            if no_default or (cls is Claim and name in REQUIRED_CLAIM_KEYS):
                raise ClaimsFileError(f"{where}: missing key {name!r} ({_describe(hints[name])})")
            continue
        ok, value = _convert(table[name], hints[name])
        if not ok:
            raise ClaimsFileError(
                f"{where}: key {name!r} must be {_describe(hints[name])}, got {table[name]!r}"
            )
        out[name] = value
    return out


def _tolerance(where: str, table: Any) -> Tolerance:
    if not isinstance(table, dict):
        raise ClaimsFileError(f"{where}: key 'tolerance' must be a table, got {table!r}")
    kinds = ", ".join(KINDS)
    kind = table.get("kind")
    if kind not in KINDS:
        raise ClaimsFileError(f"{where}: key 'tolerance.kind' must be one of {kinds}, got {kind!r}")
    cls = KINDS[kind]
    rest = {k: v for k, v in table.items() if k != "kind"}
    args = _fields(cls, f"{where}: tolerance {kind}", rest)
    try:
        tolerance: Tolerance = cls(**args)
    except ClaimError as e:
        raise ClaimsFileError(f"{where}: tolerance {kind}: {e}") from None
    return tolerance


def parse_claims(text: str, source: str) -> tuple[Claim, ...]:
    """The claims of one file's ``text`` (``source`` names it in errors)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ClaimsFileError(f"{source}: not valid TOML: {e}") from None
    unknown = sorted(set(data) - {"paper", "claim"})
    if unknown:
        raise ClaimsFileError(f"{source}: unknown key {unknown[0]!r}; allowed: paper, claim")
    paper = data.get("paper")
    if paper not in PAPERS:
        raise ClaimsFileError(
            f"{source}: key 'paper' must be one of {', '.join(PAPERS)}, got {paper!r}"
        )
    tables = data.get("claim", [])
    if not isinstance(tables, list) or not tables:
        raise ClaimsFileError(f"{source}: needs at least one [[claim]] table")
    claims: list[Claim] = []
    seen: set[str] = set()
    for i, table in enumerate(tables):
        cid = table.get("id") if isinstance(table, dict) else None
        where = f"{source}: claim {cid!r}" if isinstance(cid, str) else f"{source}: claim #{i + 1}"
        args = _fields(Claim, where, table, skip=(*_FROM_FILE, "tolerance"), extra=("tolerance",))
        if "tolerance" not in table:
            raise ClaimsFileError(f"{where}: missing key 'tolerance' (a table with a 'kind')")
        if args["id"] in seen:
            raise ClaimsFileError(f"{where}: the id is used twice in this file")
        seen.add(args["id"])
        tolerance = _tolerance(where, table["tolerance"])
        try:
            claim = Claim(paper=paper, tolerance=tolerance, **args)
            claim.validate()
        except ClaimError as e:
            raise ClaimsFileError(f"{where}: {str(e).removeprefix(args['id'] + ': ')}") from None
        claims.append(claim)
    return tuple(claims)


def read_claims(path: Path) -> tuple[Claim, ...]:
    """The claims of the file at ``path``."""
    try:
        text = path.read_text("utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise ClaimsFileError(f"{path}: cannot be read ({e})") from None
    return parse_claims(text, str(path))


LOADED: dict[str, tuple[Claim, ...]] = {}
"""The packaged files read so far, by paper (filled by :func:`paper_claims`)."""


def paper_claims(paper: str) -> tuple[Claim, ...]:
    """The claims of seed paper ``paper`` ("000".."004"), from the packaged file."""
    if paper not in PAPERS:
        raise ClaimError(f"paper must be one of {', '.join(PAPERS)}, got {paper!r}")
    if paper not in LOADED:
        name = f"claims/{paper}.toml"
        text = resources.files("fsarm_sim.data").joinpath(name).read_text("utf-8")
        claims = parse_claims(text, f"fsarm_sim/data/{name}")
        if claims[0].paper != paper:
            raise ClaimsFileError(f"fsarm_sim/data/{name}: declares paper {claims[0].paper!r}")
        LOADED[paper] = claims
    return LOADED[paper]
