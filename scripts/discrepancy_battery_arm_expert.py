#!/usr/bin/env python
"""The expert battery on the arm (issue 16): pairs and triples of arm effects, out-of-library
disturbances of the recording (50 Hz line, drifting offset, encoder cyclic error), every
transmission; prints per case what was named and the measured rates against the issue's
targets. Not run in CI (tests/test_discrepancy_arm_expert.py runs a few cases).

    .venv/bin/python scripts/discrepancy_battery_arm_expert.py [--jobs N] [--only TEXT]
        [--joint | --no-joint] [--duration 8] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import battery, battery_arm_expert
from fsarm_sim.discrepancy.report import json_clean


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=1, help="worker processes")
    ap.add_argument("--only", default="", help="run cases whose group/name contains this text")
    ap.add_argument("--duration", type=float, default=8.0, help="record length, s")
    ap.add_argument(
        "--joint",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the core's joint search, restart and pruning (default: arm.JOINT_SEARCH)",
    )
    ap.add_argument("--json", default="", help="write per-case outcomes here")
    args = ap.parse_args()
    todo = [
        c for c in battery_arm_expert.cases(args.duration) if args.only in f"{c.group}/{c.name}"
    ]
    print(f"{len(todo)} cases", flush=True)
    t0 = time.perf_counter()
    fn = partial(battery_arm_expert.run, joint=args.joint)
    res = battery.run_all(
        fn, todo, args.jobs, lambda r: f"  {r.case.name}: {r.named} ({r.runtime_s:.1f} s)"
    )
    print()
    print(battery_arm_expert.format_results(res))
    print(f"\nwall time {time.perf_counter() - t0:.0f} s")
    if args.json:
        out = [json_clean({**asdict(r), "rates": None}) for r in res]
        Path(args.json).write_text(json.dumps(out, indent=1) + "\n", "utf-8")


if __name__ == "__main__":
    main()
