"""Does a long run track in its last minute as in its first? (issue 17: the control clock)

    .venv/bin/python scripts/long_run_check.py --duration 3600 --timestep 1e-5

Runs fig14-sine on the native path with sparse logging and prints joint 2/3 tracking RMSE of the
first and the last minute, the controller tick count against the step count, and how far the
summed ``data.time`` drifted from steps x timestep. The test suite runs the hour at the default
step and the last minute at 10 us from a late start (tests/test_run_health.py); this script runs
the whole hour at any step (about 15 minutes at 10 us on one core).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.kernels import layout
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import Simulation


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=3600.0, help="simulated time, s")
    ap.add_argument("--timestep", type=float, default=1e-3, help="physics timestep, s")
    ap.add_argument("--ctrl-dt", type=float, default=1e-3, help="control period, s")
    ap.add_argument("--window", type=float, default=60.0, help="first/last window, s")
    ap.add_argument("--transmission", default="flexible-shaft", help="joint 3's transmission")
    ap.add_argument("--controller", default="default", help="joint 3's controller (Gains)")
    args = ap.parse_args()
    cfg = SimConfig(
        timestep_s=args.timestep,
        gains=Gains(ctrl_dt_s=args.ctrl_dt, controller=args.controller),
        transmission=args.transmission,
    )
    n = round(args.duration / args.ctrl_dt) + 1
    table = scenarios.get("fig14-sine").reference(np.arange(n) * args.ctrl_dt)
    sim = Simulation(cfg, table, "native")
    every = max(1, round(0.01 / args.ctrl_dt))  # 100 rows per simulated second
    start = time.perf_counter()
    cols, wall = sim.run(args.duration, log_every_ticks=every)
    total = time.perf_counter() - start
    t = cols["t"]
    print(
        f"{args.transmission}, {args.duration:g} s at h = {args.timestep:g} s: "
        f"{sim.step_index()} steps, "
        f"stepping {wall:.1f} s, total {total:.1f} s"
    )
    for label, mask in (
        ("first", t < args.window),
        ("last", t >= args.duration - args.window),
    ):
        parts = []
        for j in ("q2", "q3"):
            e = cols[j][mask] - cols[f"{j}_ref"][mask]
            parts.append(f"{j} RMSE {math.degrees(float(np.sqrt(np.mean(e * e)))):.4f} deg")
        print(f"{label} {args.window:g} s: " + ", ".join(parts))
    ticks = int(sim.data.userdata[layout.U_TICK])
    print(
        f"control ticks {ticks}, steps / steps-per-tick {sim.step_index() // round(args.ctrl_dt / args.timestep)}"
    )
    print(f"data.time - steps * h = {sim.data.time - sim.step_index() * args.timestep:.3g} s")


if __name__ == "__main__":
    main()
