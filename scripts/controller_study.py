"""The measurements of README "Joint-3 controllers" (issue 30), in one run (~5 min, one core).

1. ``fsarm compare-controllers`` on the default 9 x 450 mm shaft (the default hysteresis model,
   identified on the prototype's simulated bench records).
2. Robustness of hysteresis-comp to identification error: every slip parameter of the
   controller's model (element stiffnesses and slip torques, unwinding ratio, bend growth)
   off by +-30 %, at a few corners; fig14-sine, 0 kg.
3. A shaft whose hysteresis differs from the catalogue's (another D/L, other slip fractions,
   ratio and bend growth): its controller model identified from its own simulated series-bench
   records, then the same comparison (fig14-bent90 is fig14-sine with the shaft bent 90 deg).
4. Every registered scenario at its own payload and disturbance with every controller: does
   any run end with the health check's named error (instability)?

    .venv/bin/python scripts/controller_study.py [--json out.json] [--skip-other-shaft]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time

from fsarm_sim.engine import hysteresis_model as hm
from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import RunFailedError
from fsarm_sim.plant.shaft import ShaftParams, load_catalogue
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import run_scenario
from fsarm_sim.studies import controller_comparison as cc
from fsarm_sim.studies import hysteresis_id as hid

# slip parameters of the controller's model: k1-k3, f1-f3, unwinding ratio, bend growth
SLIP = ("k1", "k2", "k3", "f1", "f2", "f3", "unwinding_ratio", "bend_friction_per_rad")
CORNERS: dict[str, dict[str, float]] = {
    "all +30 %": dict.fromkeys(SLIP, 1.3),
    "all -30 %": dict.fromkeys(SLIP, 0.7),
    "k +30 %, f -30 %, r/mu +30 %": {
        **dict.fromkeys(("k1", "k2", "k3"), 1.3),
        **dict.fromkeys(("f1", "f2", "f3"), 0.7),
        "unwinding_ratio": 1.3,
        "bend_friction_per_rad": 1.3,
    },
    "k -30 %, f +30 %, r/mu -30 %": {
        **dict.fromkeys(("k1", "k2", "k3"), 0.7),
        **dict.fromkeys(("f1", "f2", "f3"), 1.3),
        "unwinding_ratio": 0.7,
        "bend_friction_per_rad": 0.7,
    },
    "f +30 %, r -30 %, mu +30 %": {
        **dict.fromkeys(("f1", "f2", "f3"), 1.3),
        "unwinding_ratio": 0.7,
        "bend_friction_per_rad": 1.3,
    },
    "f -30 %, r +30 %, mu -30 %": {
        **dict.fromkeys(("f1", "f2", "f3"), 0.7),
        "unwinding_ratio": 1.3,
        "bend_friction_per_rad": 0.7,
    },
}


def other_shaft() -> ShaftParams:
    """6 x 335 mm with hysteresis unlike the catalogue's: a stiffer first element, slip torques
    in another proportion, a weaker unwinding side and faster growth with the bend
    (estimates chosen to differ, not measured)."""
    sh = load_catalogue().shaft(6.0, 335.0, series_hysteresis=True)
    k0, rating = sh.k_pos, sh.rating_nm
    return dataclasses.replace(
        sh,
        slip_k=(1.0 * k0, 0.25 * k0, 0.1 * k0),
        slip_f=(0.03 * rating, 0.012 * rating, 0.06 * rating),
        slip_unwinding_ratio=0.45,
        bend_friction_per_rad=0.6,
    )


def robustness(shaft: ShaftParams) -> list[dict[str, object]]:
    base = dict(zip(hm.NAMES, hm.resolve((), shaft), strict=True))
    out = []
    for name, scale in {"identified": {}, **CORNERS}.items():
        vals = tuple(base[k] * scale.get(k, 1.0) for k in hm.NAMES)
        cfg = SimConfig(
            shaft=shaft, gains=Gains(controller="hysteresis-comp", hysteresis_model=vals)
        )
        row: dict[str, object] = {"corner": name}
        for pay in (0.0, 15.0):
            m = run_scenario("fig14-sine", cfg, payload_kg=pay).metrics
            rmse = m["rmse_deg"]
            assert isinstance(rmse, dict)
            row[f"q3_rmse_deg_{pay:g}kg"] = rmse["q3"]
            row[f"tau_est_rmse_nm_{pay:g}kg"] = m["tau_estimate_rmse_nm"]
        out.append(row)
        print(json.dumps(row))
    return out


def stability(shafts: list[ShaftParams], models: dict[str, tuple[float, ...]]) -> list[str]:
    failures = []
    for sh in shafts:
        for c in cc.DEFAULT_CONTROLLERS:
            model = models.get(cc.shaft_label(sh), ()) if c == "hysteresis-comp" else ()
            cfg = SimConfig(shaft=sh, gains=Gains(controller=c, hysteresis_model=model))
            for name in sorted(scenarios.REGISTRY):
                try:
                    run_scenario(name, cfg)
                except RunFailedError as exc:
                    failures.append(f"{cc.shaft_label(sh)} {c} {name}: {exc}")
    return failures


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=None)
    ap.add_argument("--skip-other-shaft", action="store_true")
    a = ap.parse_args()
    t0 = time.perf_counter()
    default = load_catalogue().shaft(series_hysteresis=True)
    shafts = [default]
    models: dict[str, tuple[float, ...]] = {}
    report: dict[str, object] = {}
    if not a.skip_other_shaft:
        other = other_shaft()
        fit = hid.identify_shaft(other)
        models[cc.shaft_label(other)] = fit.values
        report["other_shaft_identification"] = {
            "plant": {
                "slip_k": other.slip_k,
                "slip_f": other.slip_f,
                "unwinding_ratio": other.slip_unwinding_ratio,
                "bend_friction_per_rad": other.bend_friction_per_rad,
            },
            "identified": fit.as_dict(),
            "fit_rmse_nm": fit.rmse_nm,
            "eq8_rmse_nm": fit.eq8_rmse_nm,
        }
        print(json.dumps(report["other_shaft_identification"]))
        shafts.append(other)
    rows = cc.compare(shafts, models=models)
    report["comparison"] = [r.as_dict() for r in rows]
    for r in rows:
        print(json.dumps(r.as_dict()))
    report["robustness"] = robustness(default)
    report["instability"] = stability(shafts, models)
    print("instability:", report["instability"] or "none")
    print(f"{time.perf_counter() - t0:.0f} s")
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(report, f, indent=2)


if __name__ == "__main__":
    main()
