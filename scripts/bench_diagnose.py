#!/usr/bin/env python
"""Diagnosis speed (issue 15): ``fsarm diagnose`` per record, the arm's records with their
simulations one after the other (``arm_fit.simulation_threads(1)``) and side by side, alternating,
in one run. Prints per-record times, medians and maxima and the ratios, and checks that both
ways name the same effects (a bench record runs no simulations: one time only).

Records: the reduced single-effect bench battery (30 s records, every library effect and a null
record on the blocked series and the parallel bench: ``battery.reduced``) and arm records (8 s
fig14-sine, one hidden effect each).

    .venv/bin/python scripts/bench_diagnose.py [--arm-only | --bench-only] [--reps 1]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
from functools import partial
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import battery
from fsarm_sim.discrepancy import arm_fit, arm_synth, diagnose_record
from fsarm_sim.records.measured import load_dataset

ARM_EFFECTS: tuple[list[str], ...] = (
    ["delay:q3=0.005"],
    ["coulomb_friction:q3=0.1"],
    ["payload_error=0.5"],
    [],
)


@contextmanager
def _path(old: bool) -> Iterator[None]:
    """Run the block with the arm's simulations one after the other (``old``) or side by side."""
    with arm_fit.simulation_threads(1) if old else nullcontext():
        yield


def _time(job: Callable[[], Any]) -> tuple[float, Any]:
    t0 = time.perf_counter()
    out = job()
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--arm-only", action="store_true")
    ap.add_argument("--bench-only", action="store_true")
    ap.add_argument("--reps", type=int, default=1, help="repetitions per record and path")
    args = ap.parse_args()
    rows: list[tuple[str, str, float, float, bool]] = []
    if not args.arm_only:
        for case in battery.reduced(battery.cases()):
            runtime = statistics.median(battery.run_case(case).runtime_s for _ in range(args.reps))
            rows.append(("bench", case.name, runtime, runtime, True))
            print(f"bench {case.name}: {runtime:.2f} s", flush=True)
    if not args.bench_only:
        with tempfile.TemporaryDirectory() as tmp:
            for i, effects in enumerate(ARM_EFFECTS):
                truth = arm_synth.truth_model(effects)
                rec = arm_synth.ArmRecording(duration_s=8.0, noise_rad=2e-5, seed=i)
                table, _ = arm_synth.write_arm_synthetic(Path(tmp) / f"arm{i}.csv", truth, rec)
                ds = load_dataset(table)
                times = {True: [], False: []}
                named = {}
                for rep in range(args.reps):
                    for old in (rep % 2 == 0, rep % 2 != 0):  # alternate which goes first
                        with _path(old):
                            dt, diag = _time(partial(diagnose_record, ds))
                        times[old].append(dt)
                        named[old] = list(diag.named)
                label = ",".join(effects) or "null"
                rows.append(
                    (
                        "arm",
                        label,
                        statistics.median(times[True]),
                        statistics.median(times[False]),
                        named[True] == named[False],
                    )
                )
                print(f"arm {label}: {rows[-1][2]:.2f} s -> {rows[-1][3]:.2f} s", flush=True)
    print(f"\nsimulation threads (arm): {arm_fit.sim_threads()}")
    print(
        f"{'setup':6} {'records':>7} {'one at a time med/max':>24} {'side by side med/max':>20} "
        f"{'median ratio':>13} {'same effects':>13}"
    )
    for setup in ("bench", "arm"):
        sel = [r for r in rows if r[0] == setup]
        if not sel:
            continue
        t_old = [r[2] for r in sel]
        t_new = [r[3] for r in sel]
        ratio = statistics.median(o / n for o, n in zip(t_old, t_new, strict=True))
        print(
            f"{setup:6} {len(sel):7d} {statistics.median(t_old):10.2f} s / {max(t_old):6.2f} s "
            f"{statistics.median(t_new):8.2f} s / {max(t_new):6.2f} s {ratio:12.2f}x "
            f"{sum(r[4] for r in sel):>6d}/{len(sel)}"
        )


if __name__ == "__main__":
    main()
