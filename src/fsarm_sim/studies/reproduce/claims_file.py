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

import tomllib
import typing
from importlib import resources
from pathlib import Path
from typing import Any

from fsarm_sim import typed_tables
from fsarm_sim.studies.reproduce.claims import PAPERS, Claim, ClaimError, Tolerance

# the tolerance classes by name: a claim's ``[claim.tolerance]`` names one as its ``kind``
KINDS: dict[str, type[Tolerance]] = {cls.__name__: cls for cls in typing.get_args(Tolerance)}
# required in every claim though the dataclass has a default (the reader must see them)
REQUIRED_CLAIM_KEYS = ("role", "role_why")
_FROM_FILE = ("paper",)  # claim fields set from the file, not from a claim's table


class ClaimsFileError(ClaimError):
    """A claims file that cannot be read: names the file, the claim, the key and what is allowed."""


def _fields(
    cls: type, where: str, table: Any, skip: tuple[str, ...] = (), extra: tuple[str, ...] = ()
) -> dict[str, Any]:
    """The dataclass ``cls``'s keyword arguments from a TOML table, strictly (``skip``: fields
    not taken from the table; ``extra``: keys of the table read by the caller)."""
    if not isinstance(table, dict):
        raise ClaimsFileError(f"{where}: must be a table, got {table!r}")
    required = REQUIRED_CLAIM_KEYS if cls is Claim else ()
    try:
        return typed_tables.typed_kwargs(cls, table, skip=skip, extra=extra, required=required)
    except typed_tables.UnknownKeys as e:
        allowed = ", ".join(e.allowed)
        raise ClaimsFileError(
            f"{where}: unknown key {sorted(e.keys)[0]!r}; allowed: {allowed}"
        ) from None
    except typed_tables.MissingKey as e:
        raise ClaimsFileError(
            f"{where}: missing key {e.key!r} ({typed_tables.describe(e.hint)})"
        ) from None
    except typed_tables.Mismatch as e:
        raise ClaimsFileError(
            f"{where}: key {e.key!r} must be {typed_tables.describe(e.hint)}, got {e.value!r}"
        ) from None


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
