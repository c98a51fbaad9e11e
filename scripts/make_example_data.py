#!/usr/bin/env python
"""Regenerate the SYNTHETIC example datasets in examples/data/ (see its README.md).

.venv/bin/python scripts/make_example_data.py
"""

from __future__ import annotations

import math
from pathlib import Path

from fsarm_sim.discrepancy import synth
from fsarm_sim.discrepancy.benchmodel import EffectInstance
from fsarm_sim.plant.shaft import load_catalogue

OUT = Path(__file__).resolve().parent.parent / "examples" / "data"
DURATION_S = 10.0


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    sh = load_catalogue().shaft()
    cases = [
        (
            "series_null.csv",
            synth.truth_model("series_bench", stiffness_scale=1.1),
            synth.Recording(
                DURATION_S, noise=0.003, trajectory="triangle", bend_rad=math.radians(30), seed=1
            ),
        ),
        (
            "series_coulomb.csv",
            synth.truth_model(
                "series_bench", [EffectInstance("coulomb_friction", "shaft", {"f_c_nm": 0.25})]
            ),
            synth.Recording(DURATION_S, noise=0.003, trajectory="random", seed=2),
        ),
        (
            "series_backlash_viscous.csv",
            synth.truth_model(
                "series_bench",
                [
                    EffectInstance("backlash", "coupling", {"width_rad": 0.03, "center_rad": 0.0}),
                    EffectInstance("viscous_damping", "shaft", {"b_nms": 0.05}),
                ],
            ),
            synth.Recording(DURATION_S, noise=0.005, trajectory="multisine", seed=3),
        ),
        (
            "series_load_friction.parquet",
            synth.truth_model(
                "series_bench",
                [EffectInstance("coulomb_friction", "load", {"f_c_nm": 0.1})],
                load_inertia_kgm2=0.01,
                true_inertia_kgm2=0.012,
            ),
            synth.Recording(DURATION_S, noise=0.003, trajectory="multisine", seed=4),
        ),
        (
            "parallel_conduit.csv",
            synth.truth_model(
                "parallel_bench",
                [
                    EffectInstance(
                        "hysteresis",
                        "viscoelastic",
                        {"k_nm_per_rad": list(sh.conduit_k), "tau_s": list(sh.conduit_tau)},
                    ),
                    EffectInstance(
                        "nonlinear_stiffness",
                        "poly",
                        {"c2_nm": 0.0, "c3_nm": sh.kb * sh.beta * 1.2**3, "x_ref_rad": 1.2},
                    ),
                ],
            ),
            synth.Recording(DURATION_S, noise=0.003, trajectory="steps", seed=5),
        ),
    ]
    for name, truth, rec in cases:
        table, _side = synth.write_synthetic(OUT / name, truth, rec)
        print(
            f"{table.name}: {table.stat().st_size / 1e6:.2f} MB, hidden {[e.label for e in truth.effects]}"
        )


if __name__ == "__main__":
    main()
