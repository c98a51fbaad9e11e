#!/usr/bin/env python
"""The generalisation battery (issue 28): records from the outside generator
tests/batteries/gen_bench.py (which imports nothing of the diagnosis), its development or its
held-out kinds, diagnosed by ``fsarm diagnose``'s library entry and scored:

* strict - exactly the truth's library effects named and ``unexplained`` right,
* false alarm - ``unexplained`` true on a record whose causes all lie in the library (nulls too),
* stand-in named - a library effect named for an outside cause (outside records only),
* signature - on outside records, the residual signature names the right frequency / period /
  signal / trend among its first two findings.

Each record's outcome is appended to ``--out`` (JSON lines) as it finishes (a stopped run keeps
what it finished; ``--resume`` skips the records already there). Not run in CI
(tests/test_discrepancy_heldout.py checks the machinery on a few records).

    .venv/bin/python scripts/discrepancy_battery_heldout.py --set dev --per-kind 3 --out dev.jsonl
    .venv/bin/python scripts/discrepancy_battery_heldout.py --summary dev.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import gen_bench


def signature_right(sig: dict[str, Any] | None, want: dict[str, Any] | None) -> bool:
    """Does the signature name what the outside cause is, among its first two findings?"""
    if not sig or not want:
        return False
    found = list(sig.get("findings", []))[:2]
    for f in found:
        k = f.get("kind")
        hz = want.get("line_hz")
        if hz and k in ("spectral_line", "resonance") and abs(f["frequency_hz"] - hz) <= 0.03 * hz:
            return True
        names = [f.get("signal"), *f.get("aliases", [])]  # the same angle under its other names
        if "periodic_in" in want and k == "angle_periodic" and want["periodic_in"] in names:
            p = want.get("period_rad")
            if p is None or abs(float(f["period_rad"]) - p) <= 0.05 * p:
                return True
        if "trend" in want and k == "drift" and f.get("trend") == want["trend"]:
            return True
        if want.get("localized") and k == "localized":
            return True
        if want.get("saturation") and k == "saturation":
            return True
        want_sig = want.get("signal")
        sigs = [want_sig] if isinstance(want_sig, str) else list(want_sig or [])
        if k == "signal" and f.get("signal") in sigs:
            return True
    return False


def run_one(rec: gen_bench.Record) -> dict[str, Any]:
    from fsarm_sim.discrepancy import diagnose_record
    from fsarm_sim.discrepancy.report import json_clean, result_dict
    from fsarm_sim.records.measured import load_dataset

    with tempfile.TemporaryDirectory() as tmp:
        path = gen_bench.write_record(rec, Path(tmp))
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            diag = diagnose_record(load_dataset(path))
            res = json_clean(result_dict(diag))
        except Exception as exc:  # a battery reports failures, it does not stop at them
            res = {"error": f"{type(exc).__name__}: {exc}"[:200]}
        dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    row = score(rec.name, rec.truth, res, dt)
    row["cpu_s"] = cpu  # one core's time, whatever else the machine runs
    return row


def score(name: str, truth: dict[str, Any], res: dict[str, Any], dt: float) -> dict[str, Any]:
    named = sorted(res.get("named_effects", []))
    unexp = bool(res.get("unexplained", False))
    lib = sorted(truth["library"])
    out = {
        "record": name,
        "truth": truth,
        "named": named,
        "stand_ins": res.get("stand_ins", []),
        "unexplained": unexp,
        "error": res.get("error"),
        "runtime_s": dt,
        "strict": named == lib and unexp == truth["unexplained"] and "error" not in res,
        "false_alarm": (not truth["unexplained"]) and unexp,
        "library_for_outside": truth["outside"] is not None and bool(set(named) - set(lib)),
        "signature_right": (
            signature_right(
                res.get("residual_signature"), gen_bench.signature_truth(truth["outside"])
            )
            if truth["outside"]
            else None
        ),
        "signature": (res.get("residual_signature") or {}).get("summary"),
        "findings": list((res.get("residual_signature") or {}).get("findings", [])[:3]),
    }
    return out


def summarise(rows: Iterable[dict[str, Any]]) -> str:
    rows = list(rows)
    if not rows:
        return "no records"

    def rate(sel: list[dict[str, Any]], key: str) -> str:
        if not sel:
            return "n/a"
        k = sum(bool(r[key]) for r in sel)
        return f"{k}/{len(sel)} = {100 * k / len(sel):.0f} %"

    inlib = [r for r in rows if not r["truth"]["unexplained"]]
    outside = [r for r in rows if r["truth"]["outside"]]
    nulls = [r for r in rows if r["truth"]["category"] == "null"]
    lines = [
        f"records {len(rows)}",
        f"strict (exact set and unexplained right): {rate(rows, 'strict')}",
        f"  in-library records strict: {rate(inlib, 'strict')}",
        f"  outside records strict: {rate(outside, 'strict')}",
        f"unexplained wrongly true, in-library records: {rate(inlib, 'false_alarm')}",
        f"  of which nulls: {rate(nulls, 'false_alarm')}",
        f"library effects named for an outside cause: {rate(outside, 'library_for_outside')}",
        f"signature right on outside records: {rate(outside, 'signature_right')}",
        f"runtime median {sorted(r['runtime_s'] for r in rows)[len(rows) // 2]:.1f} s, "
        f"max {max(r['runtime_s'] for r in rows):.1f} s"
        + (
            f"; CPU time (one core) max {max(r['cpu_s'] for r in rows if 'cpu_s' in r):.1f} s"
            if any("cpu_s" in r for r in rows)
            else ""
        ),
        "",
        "per kind (strict / records; named; unexplained):",
    ]
    kinds: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        kinds.setdefault(r["truth"]["kind"], []).append(r)
    for k, rs in kinds.items():
        cells = "; ".join(
            f"{'+'.join(r['named']) or '-'}{' U' if r['unexplained'] else ''}"
            + (f" [sig {'ok' if r['signature_right'] else 'no'}]" if r["truth"]["outside"] else "")
            for r in rs
        )
        lines.append(f"  {k}: {sum(r['strict'] for r in rs)}/{len(rs)}  {cells}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--set",
        choices=("dev", "heldout", "round1-heldout", "round2-heldout", "round3-heldout"),
        default="dev",
        help="dev, heldout: round 4's split; round1-heldout .. round3-heldout: the held-out "
        "kinds of rounds 1 to 3 (seen since: development now)",
    )
    ap.add_argument("--per-kind", type=int, default=3)
    ap.add_argument("--only", default="", help="kinds whose name contains this text")
    ap.add_argument(
        "--round",
        type=int,
        choices=(1, 2, 3, 4),
        default=0,
        help="only the kinds of this round (1-3: seen in earlier development; 4: added since)",
    )
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default="", help="JSON lines, one per record (appended)")
    ap.add_argument("--resume", action="store_true", help="skip records already in --out")
    ap.add_argument("--summary", default="", help="only summarise this JSON-lines file")
    args = ap.parse_args()
    if args.summary:
        rows = [json.loads(s) for s in Path(args.summary).read_text("utf-8").splitlines() if s]
        rows = list({r["record"]: r for r in rows}.values())  # a record run twice: the last
        for r in rows:  # scored again with this file's rules and the generator's truth
            if r["truth"]["outside"]:
                want = gen_bench.signature_truth(r["truth"]["outside"])
                r["signature_right"] = signature_right({"findings": r["findings"]}, want)
        print(summarise(rows))
        return
    rounds = (args.round,) if args.round else (1, 2, 3, 4)
    if args.set == "round1-heldout":
        r1 = gen_bench.split_round1()
        recs = [
            gen_bench.make_record(k, i)
            for k in gen_bench.KINDS
            if k.round == 1 and r1[k.name] == "heldout"
            for i in range(args.per_kind)
        ]
    elif args.set == "round2-heldout":
        recs = gen_bench.battery("heldout", args.per_kind, rounds=(2,), rnd=2)
    elif args.set == "round3-heldout":
        recs = gen_bench.battery("heldout", args.per_kind, rounds=(3,), rnd=3)
    else:
        recs = gen_bench.battery(args.set, args.per_kind, rounds=rounds)
    recs = [r for r in recs if args.only in r.kind.name]
    done: set[str] = set()
    if args.resume and args.out and Path(args.out).exists():
        done = {
            json.loads(s)["record"] for s in Path(args.out).read_text("utf-8").splitlines() if s
        }
    recs = [r for r in recs if r.name not in done]
    print(f"{len(recs)} records ({args.set})", flush=True)
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        for row in ex.map(run_one, recs):
            rows.append(row)
            print(
                f"  {row['record']}: {row['named']} U={row['unexplained']} "
                f"strict={row['strict']} ({row['runtime_s']:.1f} s) {row['signature'] or ''}",
                flush=True,
            )
            if args.out:
                with open(args.out, "a", encoding="utf-8") as f:
                    f.write(json.dumps(row) + "\n")
    print()
    print(summarise(rows))


if __name__ == "__main__":
    main()
