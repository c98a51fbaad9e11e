#!/usr/bin/env python
"""Discrepancy battery on the arm (issue 5): every arm effect hidden one at a time at two
magnitudes and two noise levels, plus null records, in SYNTHETIC runs of ``fig14-sine`` made by
``fsarm_sim.discrepancy.arm_synth.synthesize_arm`` (the simulator with the effect on the plant or in
the recording, 17-bit encoders, Gaussian angle noise). Prints the confusion table (truth vs the
first effect named), parameter recovery, the held-out gap before/after and runtimes.

    .venv/bin/python scripts/discrepancy_battery_arm.py [--duration 8] [--jobs 1] [--only TEXT]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from batteries import battery
from fsarm_sim.discrepancy import arm, arm_synth
from fsarm_sim.records.measured import load_dataset

NOISES = (1e-5, 5e-5)  # rad
STIFFNESS_SCALE = 1.05  # the true shaft is 5 % stiffer than the catalogue: the refit must see it
EFFECTS: dict[str, tuple[str, str]] = {  # truth name -> (small, large) effect specifications
    "payload_error": ("payload_error=0.2", "payload_error=0.8"),
    "coulomb_friction": ("coulomb_friction=0.05", "coulomb_friction=0.2"),
    "viscous_damping": ("viscous_damping=0.05", "viscous_damping=0.2"),
    "backlash": ("backlash=0.004", "backlash=0.015"),
    "hysteresis": ("hysteresis=3,0.002,1.5,0.005", "hysteresis=6,0.002,3,0.005"),
    "sensor_offset": ("sensor_offset:theta_m=0.001", "sensor_offset:theta_m=0.004"),
    "delay": ("delay:q3=0.002", "delay:q3=0.008"),
}


@dataclass(frozen=True)
class Case:
    name: str
    truth: str  # effect name or "none"
    spec: str  # effect text ("" for none)
    noise_rad: float
    stiffness_scale: float
    kb_scale: float
    duration_s: float
    seed: int


def cases(duration_s: float) -> list[Case]:
    out = []
    seed = 0
    for eff, specs in EFFECTS.items():
        for mag, spec in zip(("small", "large"), specs, strict=True):
            for noise in NOISES:
                seed += 1
                out.append(
                    Case(
                        f"{eff}-{mag}-n{noise:g}",
                        eff,
                        spec,
                        noise,
                        STIFFNESS_SCALE,
                        1.0,
                        duration_s,
                        seed,
                    )
                )
    out.append(Case("null-n1e-05", "none", "", 1e-5, 1.0, 1.0, duration_s, 101))
    out.append(Case("null-stiff-n5e-05", "none", "", 5e-5, 1.15, 0.9, duration_s, 102))
    return out


def _main_value(name: str, params: dict[str, Any]) -> float:
    if name == "hysteresis":  # total slip torque of the elements, N*m
        return float(
            sum(k * d for k, d in zip(params["k_nm_per_rad"], params["delta_rad"], strict=True))
        )
    return float(next(iter(params.values())))


def run_case(c: Case) -> dict[str, Any]:
    truth = arm_synth.truth_model(
        [c.spec] if c.spec else [], stiffness_scale=c.stiffness_scale, kb_scale=c.kb_scale
    )
    rec = arm_synth.ArmRecording(duration_s=c.duration_s, noise_rad=c.noise_rad, seed=c.seed)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{c.name}.csv"
        arm_synth.write_arm_synthetic(path, truth, rec)
        ds = load_dataset(path)
        t0 = time.perf_counter()
        d = arm.diagnose_arm(ds)
        rt = time.perf_counter() - t0
    out: dict[str, Any] = {
        "case": c.name,
        "truth": c.truth,
        "named": d.named,
        "runtime_s": rt,
        "simulations": d.ctx.n_sims,
        "gap_before": d.gap_before,
        "gap_after": d.gap_after,
        "noise_units_before": d.gap_over_noise(d.nominal),
        "noise_units_after": d.gap_over_noise(d.final),
        "margin": d.steps[0].bic_margin if d.steps and d.steps[0].added else None,
        "look_alike": bool(d.steps and d.steps[0].look_alike),
        "recovery": None,
        "k_scale_neg": d.final.model.nominal()["k_scale_neg"],
    }
    if c.truth != "none":
        t_eff = truth.effects()[0]
        fitted = {e.name: e for e in d.final.model.effects()}
        if c.truth in fitted:
            tv = _main_value(c.truth, t_eff.params)
            fv = _main_value(c.truth, fitted[c.truth].params)
            out["recovery"] = {"true": tv, "fitted": fv, "rel_err": abs(fv - tv) / abs(tv)}
    return out


def tables(res: list[dict[str, Any]]) -> str:
    names = [*EFFECTS, "none"]
    lines = ["confusion (rows: hidden; columns: first effect named)"]
    head = f"{'':18s}" + "".join(f"{n[:9]:>10s}" for n in names)
    lines.append(head)
    for t in names:
        row = [r for r in res if r["truth"] == t]
        counts = {n: 0 for n in names}
        for r in row:
            counts[r["named"][0] if r["named"] else "none"] += 1
        lines.append(f"{t:18s}" + "".join(f"{counts[n]:10d}" for n in names))
    single = [r for r in res if r["truth"] != "none"]
    right = sum(1 for r in single if r["named"] and r["named"][0] == r["truth"])
    only = sum(1 for r in single if r["named"] == [r["truth"]])
    nulls = [r for r in res if r["truth"] == "none"]
    lines.append(
        f"\nright effect named first: {right}/{len(single)}; exactly the right effect: "
        f"{only}/{len(single)}; nothing named on null records: "
        f"{sum(1 for r in nulls if not r['named'])}/{len(nulls)}"
    )
    halved = sum(1 for r in single if r["gap_after"] <= 0.5 * r["gap_before"])
    halved_n = sum(1 for r in single if r["noise_units_after"] <= 0.5 * r["noise_units_before"])
    lines.append(
        f"held-out gap halved: q3 NRMSE {halved}/{len(single)}, channel-average residual in noise "
        f"units {halved_n}/{len(single)}"
    )
    lines.append(
        f"\n{'case':34s}{'named':36s}{'q3 NRMSE % bef->aft':>22s}{'noise units':>18s}"
        f"{'recovery (true, fit, err)':>34s}{'margin':>9s}{'t s':>6s}"
    )
    for r in res:
        rec = r["recovery"]
        rs = f"{rec['true']:.4g}, {rec['fitted']:.4g}, {100 * rec['rel_err']:.1f}%" if rec else "-"
        m = f"{r['margin']:.0f}" if r["margin"] is not None else "-"
        lines.append(
            f"{r['case']:34s}{','.join(r['named']) or '-':36s}"
            f"{100 * r['gap_before']:10.4f} ->{100 * r['gap_after']:8.4f}"
            f"{r['noise_units_before']:9.1f}->{r['noise_units_after']:6.2f}"
            f"{rs:>34s}{m:>9s}{r['runtime_s']:6.1f}"
        )
    rts = [r["runtime_s"] for r in res]
    lines.append(
        f"\nruntime per record: median {sorted(rts)[len(rts) // 2]:.1f} s, max {max(rts):.1f} s"
    )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--duration", type=float, default=8.0, help="record length, s")
    ap.add_argument("--jobs", type=int, default=1, help="worker processes")
    ap.add_argument("--only", default="", help="run cases whose name contains this text")
    ap.add_argument("--json", default="", help="write per-case outcomes here")
    args = ap.parse_args()
    todo = [c for c in cases(args.duration) if args.only in c.name]
    print(f"{len(todo)} cases", flush=True)
    t0 = time.perf_counter()
    res = battery.run_all(
        run_case, todo, args.jobs, lambda r: f"  {r['case']}: {r['named']} ({r['runtime_s']:.1f} s)"
    )
    print()
    print(tables(res))
    print(f"\nwall time {time.perf_counter() - t0:.0f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2) + "\n", "utf-8")


if __name__ == "__main__":
    main()
