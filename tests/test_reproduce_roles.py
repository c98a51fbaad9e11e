"""Claim roles (issue 27): predictions never reach the model, calibrations have one source."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections import Counter

import pytest

from fsarm_sim.studies.reproduce import runner
from fsarm_sim.studies.reproduce.claims import ROLES, ClaimError
from fsarm_sim.studies.reproduce.targets import claim_value

# A fresh interpreter moves the paper's values of one role's claims (x1.5: paper_value and the
# thresholds/ranges/changes of the tolerance) BEFORE the model is imported, then prints every
# model parameter it can reach: the default catalogue, the arm's SimConfig, every
# transmission's default block, the benches' settings. Run as: python -c SNAPSHOT ROLE
SNAPSHOT = r"""
import dataclasses, json, sys
from fsarm_sim.studies.reproduce import claims
from fsarm_sim.studies.reproduce import claims_file

ROLE = sys.argv[1]
SCALE = 1.5
FIELDS = {
    claims.Between: ("lo", "hi"),
    claims.AtLeast: ("threshold", "partly"),
    claims.AtMost: ("threshold", "partly"),
    claims.Trend: ("paper_change",),
}


def moved(c):
    tol = c.tolerance
    for kind, names in FIELDS.items():
        if isinstance(tol, kind):
            change = {n: getattr(tol, n) * SCALE for n in names if getattr(tol, n) is not None}
            tol = dataclasses.replace(tol, **change)
    pv = None if c.paper_value is None else c.paper_value * SCALE
    return dataclasses.replace(c, paper_value=pv, tolerance=tol)


n = 0
for paper in claims.PAPERS:
    old = claims_file.paper_claims(paper)
    new = tuple(moved(c) if c.role == ROLE else c for c in old)
    n += sum(a != b for a, b in zip(new, old))
    claims_file.LOADED[paper] = new

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import campaign, magnetic_spring_selection, rtca_bench

snap = {
    "catalogue": repr(load_catalogue()),
    "simconfig": repr(SimConfig()),
    "bench_settings": repr(campaign.BenchSettings()),
    "magnetic_bench": repr(magnetic_spring_selection.BenchConfig()),
    "rtca_bench": repr(rtca_bench.Rtca001()),
}
for name in transmissions.names():
    snap["transmission " + name] = [float(x) for x in transmissions.get(name).block()]
print(json.dumps({"moved": n, "snapshot": snap}))
"""


def _snapshot(role: str) -> dict[str, object]:
    out = subprocess.run(
        [sys.executable, "-c", SNAPSHOT, role],
        check=True,
        capture_output=True,
        text=True,
        timeout=300,
    )
    data: dict[str, object] = json.loads(out.stdout.strip().splitlines()[-1])
    return data


def test_moving_every_prediction_changes_no_model_parameter() -> None:
    """Every prediction's paper value x1.5: the model's parameters compare equal; moving the
    calibration claims' values does move a parameter (the check is not blind)."""
    base = _snapshot("none")
    pred = _snapshot("prediction")
    cal = _snapshot("calibration")
    assert base["moved"] == 0
    assert isinstance(pred["moved"], int) and pred["moved"] >= 20  # values that did move
    assert pred["snapshot"] == base["snapshot"]
    assert cal["snapshot"] != base["snapshot"]  # 002-adjust-time feeds the QA-Joint drive


def test_every_claim_has_a_role_and_calibrations_name_parameters() -> None:
    claims = runner.all_claims()
    counts = Counter(c.role for c in claims)
    assert set(counts) <= set(ROLES) and sum(counts.values()) == len(claims)
    for c in claims:
        assert c.role_why.strip(), c.id
        assert bool(c.calibrates) == (c.role == "calibration"), c.id
    params = runner.calibrated_parameters(claims)
    assert "shafts.series.p4" in params and "000-length-lever" in params["shafts.series.p4"]


def test_claim_value_reads_only_calibration_claims() -> None:
    assert claim_value("002-adjust-time") == 0.12
    with pytest.raises(ClaimError, match="prediction"):
        claim_value("002-efficiency-2.7")
    with pytest.raises(ClaimError, match="no claim"):
        claim_value("000-nothing")
    with pytest.raises(ClaimError, match="paper_value"):
        claim_value("000-series-k-falls-with-bend")  # a calibration trend has no single value


def test_calibrated_parameters_hold_their_claims_values() -> None:
    """Where a parameter was fitted to a claim's number, the model meets that number (the fit
    and its claim cannot drift apart)."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.plant.transmissions import magnetic_spring as ms
    from fsarm_sim.plant.transmissions import qa_joint
    from fsarm_sim.studies.magnetic_spring_arc import solve_shape

    # QA-Joint stiffness drive: its speed is computed from 002-adjust-time
    rate = qa_joint.SIGMA_RATE_TABLE_III
    assert qa_joint.full_range_time_s(rate) == pytest.approx(claim_value("002-adjust-time"))
    # magnetic spring shape: b2/b1, b3/b1 solved from the stable and linear ranges
    r2, r3 = solve_shape(claim_value("003-stable-range"), claim_value("003-linear-range"))
    b = ms.default_block()
    assert b[ms.I_B2] / b[ms.I_B1] == pytest.approx(r2, rel=1e-3)
    assert b[ms.I_B3] / b[ms.I_B1] == pytest.approx(r3, rel=1e-3)
    # shaft rating: c D^3 anchored on seed 001's MasterFlex08 (8 mm)
    cat = load_catalogue()
    assert cat.rating_nm(8.0) == pytest.approx(claim_value("001-rating-6nm"), rel=1e-12)
    # eq. 4's level: the prototype's elastic bending moment at 90 deg
    shaft = cat.shaft()
    assert shaft.static_relief_nm(math.pi / 2.0) == pytest.approx(
        claim_value("000-static-relief-8nm"), rel=0.01
    )
