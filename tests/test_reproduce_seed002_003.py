"""``fsarm reproduce`` for seeds 002 (QA-Joint experiments) and 003 (model selection), quick."""

from __future__ import annotations

import pytest

from fsarm_sim.studies.reproduce import measure002, measure003, runner, seed002, seed003
from fsarm_sim.studies.reproduce.claims import Context

# Table 4's linearised models on the teaching half: ours x51 / x238 worse, the paper's x1.23 /
# x1.55 (our trials' share beyond the critical angle; added by issue 27, a real disagreement)
KNOWN_CONTRADICTED = {"003-linearised-worse-teaching"}


@pytest.mark.parametrize("paper", ["002", "003"])
def test_quick_claims_run_and_only_known_predictions_are_contradicted(paper: str) -> None:
    claims = runner.select([paper], quick=True)
    report = runner.Report(papers=[paper], quick=True, backend="python")
    runner.run(claims, Context(quick=True, backend="python"), report, lambda rep, _: None)
    assert not report.failed
    verdicts = {r.claim.id: r.verdict for r in report.results}
    # contradicted: only the known predictions, each naming its cause in the note (issue 27)
    contradicted = {r.claim.id: r for r in report.results if r.verdict == "contradicted"}
    assert set(contradicted) <= KNOWN_CONTRADICTED, verdicts
    for r in contradicted.values():
        assert r.claim.role == "prediction" and r.note, r.claim.id
    # the experiments of issue 14 are measured now, not declared missing
    measured = {
        "002": ("002-efficiency-2.7", "002-efficiency-trend", "002-stiffness-adjustment-266"),
        "003": ("003-model-ranking", "003-bic-ranking", "003-fms-broadens-safe-range"),
    }[paper]
    for cid in measured:
        assert verdicts[cid] in ("reproduced", "partly"), (cid, verdicts[cid])


def test_not_implemented_claims_say_what_the_paper_lacks() -> None:
    for claims in (seed002.CLAIMS, seed003.CLAIMS):
        for c in claims:
            if c.not_implemented:
                assert "not give" in c.not_implemented or "neither" in c.not_implemented, c.id
    assert set(measure002.MEASURES) >= {c.measure for c in seed002.CLAIMS if c.measure}
    assert set(measure003.MEASURES) >= {c.measure for c in seed003.CLAIMS if c.measure}
