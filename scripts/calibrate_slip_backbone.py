"""Calibrate ``series.maxwell_slip.apparent_stiffness_pos/_neg`` of a coefficient file.

Seed 000 identifies eq. 3 as the slope of a line fitted to the series test's loops (Sec. III-B1:
chirp 0.5-20 Hz into the torque controller, amplitude by the rating, bends 0-90 deg in 15 deg
steps). The Maxwell-slip elements add to that slope, so the plant's spring must carry eq. 3 less
their apparent stiffness for the paper's procedure to return eq. 3. This script finds that
apparent stiffness on the simulated bench by fixed-point iteration,

    app_{n+1}(phi) = app_n(phi) + (K_fit,n(phi) - K_eq3(phi))      per side,

fits it as ``a0 + a1 |phi|`` in units of the straight K_sp (the elements scale with K_sp and the
rating, the test's twist with rating / K, so the fractions hold for every shaft of the file), and
prints the two lines to put in the file. Then it reports the round trip on a few shafts.

    .venv/bin/python scripts/calibrate_slip_backbone.py [--shaft-file FILE] [--iterations 4]
"""

from __future__ import annotations

import argparse
import dataclasses
import math

import numpy as np

from fsarm_sim.plant.shaft import Catalogue, load_catalogue
from fsarm_sim.studies import campaign as cp


def fits(cat: Catalogue, d: float, ell: float, bends_deg: tuple[float, ...]) -> np.ndarray:
    """Rows (bend_rad, K_fit+, K_eq3+, K_fit-, K_eq3-) of the series test of one shaft."""
    sh = cat.shaft(d, ell)
    s = cp.BenchSettings()
    rows = []
    for b in bends_deg:
        phi = math.radians(b)
        f = cp.fit_series(cp.series_test(sh, phi, s), b)
        rows.append((phi, f.k_pos, sh.k_series(phi, 1), f.k_neg, sh.k_series(phi, -1)))
    return np.asarray(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--shaft-file", default=None)
    ap.add_argument("--iterations", type=int, default=4)
    args = ap.parse_args()
    cat = load_catalogue(args.shaft_file)
    bends = cp.BEND_STEPS_DEG
    frac = np.asarray(cat.slip_apparent_fraction, dtype=float)
    for it in range(args.iterations):
        cat = dataclasses.replace(cat, slip_apparent_fraction=tuple(float(x) for x in frac))
        k0 = cat.shaft().k_pos
        r = fits(cat, 9.0, 450.0, bends)
        phi = r[:, 0]
        new = []
        for side, (fit_col, eq3_col) in enumerate(((1, 2), (3, 4))):
            a0, a1 = frac[2 * side], frac[2 * side + 1]
            app = (a0 + a1 * phi) * k0 + (r[:, fit_col] - r[:, eq3_col])
            slope, icpt = np.polyfit(phi, app / k0, 1)
            new += [icpt, slope]
        err = np.max(np.abs(np.concatenate((r[:, 1] / r[:, 2], r[:, 3] / r[:, 4])) - 1.0))
        print(f"iteration {it}: largest |K_fit/K_eq3 - 1| = {100 * err:.2f} %, fractions {frac}")
        frac = np.asarray(new)
    cat = dataclasses.replace(cat, slip_apparent_fraction=tuple(float(x) for x in frac))
    print(f"apparent_stiffness_pos = [{frac[0]:.4f}, {frac[1]:.4f}]")
    print(f"apparent_stiffness_neg = [{frac[2]:.4f}, {frac[3]:.4f}]")
    for d, ell in ((9.0, 450.0), (4.0, 235.0), (6.0, 435.0), (13.0, 435.0)):
        r = fits(cat, d, ell, (0.0, 45.0, 90.0))
        err = np.concatenate((r[:, 1] / r[:, 2], r[:, 3] / r[:, 4])) - 1.0
        print(
            f"{d:g} x {ell:g} mm: K_fit/K_eq3 - 1 = " + ", ".join(f"{100 * e:+.1f} %" for e in err)
        )


if __name__ == "__main__":
    main()
