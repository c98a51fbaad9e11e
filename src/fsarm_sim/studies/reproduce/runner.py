"""Run the claims, judge them, and keep the report safe while it grows.

* :func:`select` picks the claims of the requested papers (``--quick``: the claims marked
  ``quick``, with the shorter settings the measurements use in quick mode).
* :func:`run` measures one claim at a time and calls ``on_result`` after each, so the caller can
  write the JSON report as every claim finishes (:func:`write_json` replaces the file atomically:
  a reader never sees half a file, and an interrupted run keeps every finished claim).
  Ctrl-C stops the run between claims: the claim in progress is dropped (its experiment may have
  been cut short inside a simulation, which keeps running on KeyboardInterrupt), everything
  finished is kept and the report says ``interrupted``.
* A measurement that raises is reported as ``not_implemented`` with ``failed: true`` and the
  error in ``why`` (the report goes on; the command exits 1).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsarm_sim.studies.reproduce import (
    measure000,
    measure001,
    measure002,
    measure003,
    measure004,
)
from fsarm_sim.studies.reproduce.claims import (
    PAPERS,
    ROLES,
    VERDICTS,
    Claim,
    ClaimError,
    Context,
    MeasureFn,
    Result,
    judge,
)
from fsarm_sim.studies.reproduce.claims_file import paper_claims

REGISTRY: dict[str, tuple[tuple[Claim, ...], dict[str, MeasureFn]]] = {
    "000": (paper_claims("000"), measure000.MEASURES),
    "001": (paper_claims("001"), measure001.MEASURES),
    "002": (paper_claims("002"), measure002.MEASURES),
    "003": (paper_claims("003"), measure003.MEASURES),
    "004": (paper_claims("004"), measure004.MEASURES),
}


def all_claims() -> tuple[Claim, ...]:
    return tuple(c for claims, _ in REGISTRY.values() for c in claims)


def check_registry() -> None:
    """Every claim well formed, ids unique, every ``measure`` name known to its paper."""
    seen: set[str] = set()
    for paper, (claims, measures) in REGISTRY.items():
        for c in claims:
            c.validate()
            if c.paper != paper:
                raise ClaimError(f"{c.id} is listed under paper {paper}")
            if c.id in seen:
                raise ClaimError(f"claim id {c.id} is used twice")
            seen.add(c.id)
            if c.measure is not None and c.measure not in measures:
                raise ClaimError(f"{c.id}: no measurement {c.measure!r} in measure{paper}")


def select(papers: Sequence[str] | None, quick: bool) -> list[Claim]:
    wanted = list(PAPERS) if not papers else list(papers)
    return [c for p in wanted for c in REGISTRY[p][0] if not quick or c.quick or c.measure is None]


@dataclass
class Report:
    papers: list[str]
    quick: bool
    backend: str
    started: str = field(
        default_factory=lambda: _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    )
    results: list[Result] = field(default_factory=list)
    planned: int = 0
    elapsed_s: float = 0.0
    complete: bool = False
    interrupted: bool = False

    @property
    def failed(self) -> list[str]:
        return [r.claim.id for r in self.results if r.failed]

    def summary(self) -> dict[str, dict[str, Any]]:
        return summarize(self.results, self.papers)

    def as_dict(self) -> dict[str, Any]:
        return {
            "command": "fsarm reproduce",
            "papers": self.papers,
            "quick": self.quick,
            "backend": self.backend,
            "started": self.started,
            "elapsed_s": round(self.elapsed_s, 2),
            "planned": self.planned,
            "finished": len(self.results),
            "complete": self.complete,
            "interrupted": self.interrupted,
            "failed": self.failed,
            "verdicts": list(VERDICTS),
            "roles": list(ROLES),
            "summary": self.summary(),
            "calibrated_parameters": calibrated_parameters([r.claim for r in self.results]),
            "claims": [r.as_dict() for r in self.results],
        }


def summarize(results: Sequence[Result], papers: Sequence[str]) -> dict[str, dict[str, Any]]:
    """Per paper (and ``all``): how many claims of each role (``roles``), and for each role the
    counts per verdict with their ``total``. Only the ``prediction`` row is evidence: a
    calibration claim that holds says the fit holds, a consistency claim that holds says the
    code carries the paper's number or formula; neither counts as reproduced. The
    ``prediction`` row counts the blind predictions only; those written after ours was seen
    (``Claim.post_hoc``) have their own row, ``post_hoc``, and ``roles`` counts them apart."""
    out: dict[str, dict[str, Any]] = {}
    for p in [*papers, "all"]:
        mine = [r for r in results if p in ("all", r.claim.paper)]
        entry: dict[str, Any] = {"roles": {role: 0 for role in ROLES}, "total": len(mine)}
        for role in (*ROLES, "post_hoc"):
            row: dict[str, int] = {v: 0 for v in VERDICTS}
            for r in mine:
                if _row_of(r.claim) == role:
                    row[r.verdict] += 1
            row["total"] = sum(row[v] for v in VERDICTS)
            entry["roles"][role] = row["total"]
            entry[role] = row
        out[p] = entry
    return out


def _row_of(claim: Claim) -> str:
    """The summary row a claim counts in: its role, or ``post_hoc`` for a post-hoc prediction."""
    return "post_hoc" if claim.post_hoc else claim.role


def calibrated_parameters(claims: Sequence[Claim]) -> dict[str, list[str]]:
    """Each calibrated parameter and the claims it was chosen or fitted from."""
    out: dict[str, list[str]] = {}
    for c in claims:
        for name in c.calibrates:
            out.setdefault(name, []).append(c.id)
    return dict(sorted(out.items()))


def run_claim(claim: Claim, measures: dict[str, MeasureFn], ctx: Context) -> Result:
    """Measure and judge one claim (not_implemented / uncheckable claims pass straight through)."""
    start = time.perf_counter()
    if claim.uncheckable:
        return Result(claim, "uncheckable", why=claim.uncheckable)
    if claim.not_implemented:
        return Result(claim, "not_implemented", why=claim.not_implemented)
    assert claim.measure is not None
    try:
        m = measures[claim.measure](ctx)
        verdict = judge(claim, m)
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # a broken experiment is reported, the report goes on
        return Result(
            claim,
            "not_implemented",
            why=f"experiment failed: {type(exc).__name__}: {exc}",
            failed=True,
            seconds=time.perf_counter() - start,
        )
    return Result(
        claim,
        verdict,
        ours=m.ours,
        ours_text=m.text,
        note=m.note,
        details=m.details,
        seconds=time.perf_counter() - start,
    )


@contextmanager
def _interrupt_flag() -> Iterator[list[bool]]:
    """Remember a Ctrl-C even where a simulation swallows its KeyboardInterrupt."""
    flag = [False]
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return

    def handler(signum: int, frame: Any) -> None:
        flag[0] = True
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGINT, handler)
    try:
        yield flag
    finally:
        signal.signal(signal.SIGINT, old)


def run(
    claims: Sequence[Claim],
    ctx: Context,
    report: Report,
    on_result: Callable[[Report, Result], None] | None = None,
) -> Report:
    """Run ``claims`` in order into ``report`` (see the module docstring)."""
    t0 = time.perf_counter()
    report.planned = len(claims)
    with _interrupt_flag() as flag:
        for claim in claims:
            try:
                result = run_claim(claim, REGISTRY[claim.paper][1], ctx)
                if flag[0]:  # the claim's experiment may have been cut short: drop it
                    report.interrupted = True
                    break
                report.results.append(result)
                report.elapsed_s = time.perf_counter() - t0
                if on_result is not None:
                    on_result(report, result)
            except KeyboardInterrupt:
                report.interrupted = True
                break
    report.elapsed_s = time.perf_counter() - t0
    report.complete = not report.interrupted and len(report.results) == len(claims)
    return report


def start(papers: Sequence[str], quick: bool) -> tuple[list[Claim], Report]:
    """Check the registry, pick the claims of ``papers`` (all when empty) and open their report:
    what ``fsarm reproduce`` runs, ready for :func:`run`."""
    check_registry()
    claims = select(papers or None, quick)
    report = Report(papers=list(papers) or list(REGISTRY), quick=quick, backend="native")
    return claims, report


ROLE_ORDER = {"prediction": 0, "calibration": 1, "consistency": 2}


def by_paper(results: Sequence[Result]) -> dict[str, list[Result]]:
    """The results per paper, predictions first, then calibrations, then consistency checks."""
    out: dict[str, list[Result]] = {}
    for r in sorted(results, key=lambda r: ROLE_ORDER.get(r.claim.role, 3)):
        out.setdefault(r.claim.paper, []).append(r)
    return out


def checkable(entry: dict[str, Any], *rows: str) -> int:
    """How many claims of the ``rows`` of a :func:`summarize` entry could be judged (neither
    not_implemented nor uncheckable)."""
    return sum(
        entry[r]["total"] - entry[r]["not_implemented"] - entry[r]["uncheckable"]
        for r in rows
        if r in entry
    )


def write_json(path: Path, report: Report) -> Path:
    """Write the report atomically (temporary file in the same folder, then rename)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(report.as_dict(), indent=2, ensure_ascii=False, allow_nan=False)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text + "\n", "utf-8")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path
