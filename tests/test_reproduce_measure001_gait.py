"""Seed 001's walking and exoskeleton claims (fsarm_sim.studies.reproduce.measure001_gait)."""

from __future__ import annotations

import math
from typing import Any

import pytest

from fsarm_sim.studies import exo_leg
from fsarm_sim.studies.reproduce import claims_file
from fsarm_sim.studies.reproduce import measure001_gait as mg
from fsarm_sim.studies.reproduce.claims import Context
from fsarm_sim.studies.rtca_walking import Walking

CLAIMS = {c.id: c for c in claims_file.paper_claims("001")}


def _fake_walks(peaks: dict[str, list[float]]) -> Any:
    def walks(ctx: Context) -> dict[str, list[Walking]]:
        return {
            j: [
                Walking(j, r, p, 0.5 * p, 0.3 * p, 0.2 * p)
                for r, p in zip(mg.R_WALKING_M, v, strict=True)
            ]
            for j, v in peaks.items()
        }

    return walks


def test_walking_transparency_judges_most_conditions_by_the_median(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    claim = CLAIMS["001-walking-transparency"]
    # five of nine runs within 0.05 N·m: "most conditions" holds
    peaks = {"hip": [0.03, 0.04, 0.045], "knee": [0.04, 0.05, 0.2], "ankle": [0.06, 0.07, 0.3]}
    monkeypatch.setattr(mg, "_walks", _fake_walks(peaks))
    m = mg.walking_transparency(Context())
    assert m.ours == 0.05 and "5 of 9" in m.text
    assert claim.tolerance.judge(claim.paper_value, m.ours) == "reproduced"
    # four of nine: the median is the fifth-smallest, above 0.05
    peaks["knee"][1] = 0.09
    m = mg.walking_transparency(Context())
    assert m.ours == pytest.approx(0.06)
    assert claim.tolerance.judge(claim.paper_value, m.ours) == "partly"


def test_walking_bend_increase_needs_every_joint_to_rise(monkeypatch: pytest.MonkeyPatch) -> None:
    claim = CLAIMS["001-walking-bend-increase"]
    rising = {"hip": [0.05, 0.052, 0.054], "knee": [0.1, 0.11, 0.12], "ankle": [0.1, 0.1, 0.11]}
    monkeypatch.setattr(mg, "_walks", _fake_walks(rising))
    assert claim.tolerance.judge(None, mg.walking_bend_increase(Context()).ours) == "reproduced"
    rising["ankle"] = [0.1, 0.09, 0.08]
    assert claim.tolerance.judge(None, mg.walking_bend_increase(Context()).ours) != "reproduced"


def test_exo_claims_read_the_legs_reductions() -> None:
    ctx = Context()
    red = exo_leg.reductions()
    hip = mg.exo_hip_reduction(ctx)
    knee = mg.exo_knee_reduction(ctx)
    assert hip.ours == pytest.approx(red["hip"].percent("flexion"))
    assert knee.ours == pytest.approx(red["knee"].percent("peak"))
    # gravity alone, both designs' knee masses on the shank: the ratio of their moments m d
    ratio = 1.1 * 0.1 / (1.0 * exo_leg.SHANK_M)
    assert knee.details["gravity_only_percent"]["peak"] == pytest.approx(100 * (1 - ratio), abs=0.5)
    assert math.isfinite(hip.details["thigh_side_percent"]["flexion"])
