#!/usr/bin/env python
"""The full discrepancy battery (issue 5): every library effect hidden one at a time at two
magnitudes and two noise levels, null datasets and two-effect datasets, on the blocked series
bench, the series bench with an inertia load and the parallel bench. Prints the confusion table,
the targets, parameter recovery, gap shrink and runtimes. Not run in CI (tests/test_discrepancy.py
runs a reduced battery).

    .venv/bin/python scripts/discrepancy_battery.py [--quick] [--jobs N] [--only TEXT] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import battery


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the reduced battery of the tests")
    ap.add_argument("--jobs", type=int, default=1, help="worker processes")
    ap.add_argument("--only", default="", help="run cases whose name contains this text")
    ap.add_argument("--duration", type=float, default=30.0, help="record length, s")
    ap.add_argument("--json", default="", help="write per-case outcomes here")
    args = ap.parse_args()
    cases = [
        c
        for c in battery.cases(full=not args.quick, duration_s=args.duration)
        if args.only in c.name
    ]
    print(f"{len(cases)} cases", flush=True)
    t0 = time.perf_counter()
    outcomes = battery.run_all(
        battery.run_case,
        cases,
        args.jobs,
        lambda o: f"  {o.case.name}: {o.named} ({o.runtime_s:.1f} s)",
    )
    print()
    print(battery.format_tables(outcomes))
    print(f"\nwall time {time.perf_counter() - t0:.0f} s")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(
                [
                    {
                        "case": o.case.name,
                        "trajectory": o.case.trajectory,
                        "truth": o.truth_names,
                        "named": o.named,
                        "gap_before": o.gap_before,
                        "gap_after": o.gap_after,
                        "noise_floor": o.noise_floor,
                        "noise_floor_inputs": o.noise_floor_inputs,
                        "gap_excess_before": o.gap_excess_before,
                        "gap_excess_after": o.gap_excess_after,
                        "size": o.achieved_size,
                        "margin": o.first_margin,
                        "runner_up": o.first_runner_up,
                        "recovery": o.recovery,
                        "runtime_s": o.runtime_s,
                        "steps": o.steps,
                        "truth_model": o.truth.as_dict(),
                    }
                    for o in outcomes
                ],
                f,
                indent=1,
            )


if __name__ == "__main__":
    main()
