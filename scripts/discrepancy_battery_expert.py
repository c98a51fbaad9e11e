#!/usr/bin/env python
"""The expert battery (issue 16): two- and three-effect records, out-of-library residuals
(50 Hz line, stiffness drift, twist ripple), near-threshold magnitudes, 500 Hz - 2 kHz; prints
per case what was named and the measured rates against the issue's targets. Not run in CI
(tests/test_discrepancy_expert.py runs a few cases).

    .venv/bin/python scripts/discrepancy_battery_expert.py [--jobs N] [--only TEXT] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import battery, battery_expert
from fsarm_sim.discrepancy.report import json_clean


def _run(gc: tuple[str, object]) -> battery_expert.Result:
    g, c = gc
    return battery_expert.run(g, c)  # type: ignore[arg-type]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=1, help="worker processes")
    ap.add_argument("--only", default="", help="run cases whose group/name contains this text")
    ap.add_argument("--duration", type=float, default=30.0, help="record length, s")
    ap.add_argument("--json", default="", help="write per-case results here")
    args = ap.parse_args()
    todo = [(g, c) for g, c in battery_expert.cases(args.duration) if args.only in f"{g}/{c.name}"]
    print(f"{len(todo)} cases", flush=True)
    t0 = time.perf_counter()
    results = battery.run_all(
        _run,
        todo,
        args.jobs,
        lambda r: (
            f"  {r.case.name}: {r.named} unexplained={r.unexplained} "
            f"({r.runtime_s:.1f} s) {r.error}"
        ),
    )
    print()
    print(battery_expert.format_results(results))
    print(f"\nwall time {time.perf_counter() - t0:.0f} s")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(
                json_clean(
                    [
                        {
                            "group": r.group,
                            "case": r.case.name,
                            "rate_hz": r.case.rate_hz,
                            "truth": r.truth_names,
                            "extra": r.case.extra,
                            "named": r.named,
                            "unexplained": r.unexplained,
                            "signature_right": battery_expert.signature_right(r),
                            "signature": r.signature,
                            "ci_covered": r.covered,
                            "runtime_s": r.runtime_s,
                            "cpu_s": r.cpu_s,
                            "error": r.error,
                        }
                        for r in results
                    ]
                ),
                f,
                indent=1,
            )


if __name__ == "__main__":
    main()
