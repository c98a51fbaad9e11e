"""Measure task-level selection against an exhaustive fine grid (issue 32).

    python scripts/select_vs_grid.py --scenario fig14-sine --objective q3_rmse_deg [--duration S]

Runs the grid (D step 0.25 mm, L step 10 mm over the validity box) and the optimiser in separate
temporary stores, and prints both optima, their distance in grid steps and the simulation counts.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from fsarm_sim.studies import task_selection as ts


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", default="fig14-sine")
    ap.add_argument("--objective", default="q3_rmse_deg")
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument("--payload-kg", type=float, default=None)
    ap.add_argument("--budget", type=int, default=96)
    ap.add_argument("--rating-margin", type=float, default=1.0)
    ap.add_argument("--d-step", type=float, default=0.25)
    ap.add_argument("--l-step", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=32)
    args = ap.parse_args()
    task = ts.Task(
        scenario=args.scenario,
        duration_s=args.duration,
        payload_kg=args.payload_kg,
        rating_margin=args.rating_margin,
    )
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ds = np.round(np.arange(4.0, 13.0 + 1e-9, args.d_step), 6)
        ls = np.round(np.arange(235.0, 535.0 + 1e-9, args.l_step), 6)
        g_best, n_grid = ts.grid(task, Path(tmp) / "grid.sqlite", args.objective, ds, ls)
        t_grid = time.perf_counter() - t0
        t0 = time.perf_counter()
        s = ts.select(
            task, Path(tmp) / "opt.sqlite", args.objective, budget=args.budget, seed=args.seed
        )
        t_opt = time.perf_counter() - t0
    assert g_best is not None and s.best is not None
    steps = (
        abs(s.best.diameter_mm - g_best.diameter_mm) / args.d_step,
        abs(s.best.length_mm - g_best.length_mm) / args.l_step,
    )
    print(
        json.dumps(
            {
                "scenario": args.scenario,
                "objective": args.objective,
                "duration_s": args.duration,
                "grid": {
                    "points": n_grid,
                    "best": [g_best.diameter_mm, g_best.length_mm],
                    "value": g_best.outputs[args.objective],
                    "wall_s": round(t_grid, 1),
                },
                "optimiser": {
                    "simulations": s.simulations,
                    "best": [s.best.diameter_mm, s.best.length_mm],
                    "value": s.best.outputs[args.objective],
                    "wall_s": round(t_opt, 1),
                    "nearest_catalogue": s.nearest_names,
                },
                "distance_grid_steps": [round(steps[0], 2), round(steps[1], 2)],
                "within_one_step": max(steps) <= 1.0,
                "sim_fraction": round(s.simulations / n_grid, 3),
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
