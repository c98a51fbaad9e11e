#!/usr/bin/env python
"""Speed benchmark of issue 4 (same numbers as `fsarm bench-speed`).

Times, in one run: raw MuJoCo (callbacks off) vs the Python and the native callback paths per
step on the full model, the real-time factor of a 10 s fig14-sine run without logging (native),
and the throughput of a batch of differently configured runs on 1..N worker threads.
Prints medians; the machine may be shared, so compare numbers from one run, not across runs.

    .venv/bin/python scripts/bench_step.py [--reps 15] [--quick] [--max-workers N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict
from pathlib import Path

from fsarm_sim.studies.speed import format_report, measure_speed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=15, help="repetitions of each per-step timing")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions, shorter runs")
    ap.add_argument("--max-workers", type=int, default=None, help="default: all cores")
    ap.add_argument("--json", type=Path, default=None, help="also write the numbers here")
    args = ap.parse_args()
    if args.quick:
        report = measure_speed(
            reps=5, rtf_reps=2, rtf_duration_s=2.0, batch_reps=2, max_workers=args.max_workers
        )
    else:
        report = measure_speed(reps=args.reps, max_workers=args.max_workers)
    print(format_report(report))
    if args.json is not None:
        args.json.write_text(json.dumps(asdict(report), indent=2))
        print(f"numbers: {args.json}")


if __name__ == "__main__":
    main()
