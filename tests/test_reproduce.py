"""``fsarm reproduce``: the claim registry, the verdict rules, the report and the command."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from fsarm_sim.studies.reproduce import runner
from fsarm_sim.studies.reproduce.claims import (
    PAPERS,
    ROLES,
    VERDICTS,
    Abs,
    AllOf,
    AtLeast,
    AtMost,
    Between,
    Claim,
    ClaimError,
    Context,
    Factor,
    Measured,
    Ranking,
    Rel,
    Result,
    Trend,
)

from conftest import run_fsarm

# ------------------------------------------------------------------------------ the registry


def _claim(**changes: Any) -> Claim:
    """A prediction of paper 002 with every required field; ``changes`` replace fields (it is
    built here, so a bad role already fails)."""
    fields: dict[str, Any] = {
        "id": "002-x",
        "paper": "002",
        "title": "t",
        "locator": "Sec. I",
        "quote": "q",
        "paper_text": "1",
        "unit": "-",
        "tolerance": Rel(0.1),
        "paper_value": 1.0,
        "measure": "m",
        "role": "prediction",
    }
    return Claim(**{**fields, **changes})


def test_registry_is_well_formed() -> None:
    runner.check_registry()  # validate(), unique ids, every measure name known
    claims = runner.all_claims()
    assert len(claims) >= 100
    for c in claims:
        assert c.paper in PAPERS
        assert c.locator.strip() and c.quote.strip() and c.title.strip()
        assert c.unit.strip()
        assert c.paper_text.strip()  # the paper's value or the trend it states
        assert c.tolerance.text(c.unit).strip()
        if getattr(c.tolerance, "needs_paper_value", False):
            assert c.paper_value is not None and math.isfinite(c.paper_value)
        assert sum(bool(w) for w in (c.measure, c.not_implemented, c.uncheckable)) == 1
    for paper in PAPERS:
        assert any(c.paper == paper and c.measure for c in claims), paper


def test_issue_items_are_covered_for_seeds_000_and_001() -> None:
    items = {c.issue_item for c in runner.all_claims() if c.paper in ("000", "001")}
    assert {1, 2, 3, 4, 5} <= items


def test_a_malformed_claim_is_refused() -> None:
    good = {"id": "000-x", "paper": "000", "paper_text": "1 N·m", "unit": "N·m"}
    _claim(**good).validate()
    for change in (
        {"paper": "007"},
        {"id": "001-x"},
        {"locator": " "},
        {"paper_value": None},
        {"not_implemented": "why"},  # two ways at once
        {"measure": None},  # none
        {"role": ""},  # no role
        {"role": "guess"},
        {"role": "calibration"},  # names no parameter
        {"role": "calibration", "calibrates": ("",)},
        {"calibrates": ("k",)},  # a prediction names no calibrated parameter
        {"role": "consistency", "post_hoc": "seen"},  # only a prediction can be post-hoc
    ):
        with pytest.raises(ClaimError):
            _claim(**{**good, **change}).validate()


def test_post_hoc_predictions_are_counted_apart_and_never_as_evidence() -> None:
    base = {"tolerance": AtLeast(1.0), "paper_value": None}
    blind = _claim(id="002-blind", **base)
    late = _claim(id="002-late", post_hoc="written after ours was seen", **base)
    results = [Result(blind, "reproduced"), Result(late, "reproduced")]
    s = runner.summarize(results, ["002"])["002"]
    assert s["prediction"]["reproduced"] == 1 and s["post_hoc"]["reproduced"] == 1
    assert s["roles"]["prediction"] == 1 and s["roles"]["post_hoc"] == 1
    assert sum(s["roles"].values()) == s["total"] == 2
    assert [r.as_dict()["evidence"] for r in results] == [True, False]
    assert results[1].as_dict()["post_hoc"] == "written after ours was seen"
    # the two claims of issue 27 written after our numbers are marked
    marked = {c.id for c in runner.all_claims() if c.post_hoc}
    assert {
        "002-efficiency-largest-where",
        "002-speed-window",
        "000-thick-shaft-without-joint-gear",
    } <= marked


# --------------------------------------------------------------------------- verdict rules


def test_rel_abs_factor_boundaries() -> None:
    r = Rel(0.05, partly=0.2)
    assert r.judge(10.0, 10.5) == "reproduced"  # exactly at the tolerance
    assert r.judge(10.0, 9.5) == "reproduced"
    assert r.judge(10.0, 10.51) == "partly"
    assert r.judge(10.0, 12.0) == "partly"
    assert r.judge(10.0, 12.01) == "contradicted"
    assert Rel(0.05).judge(10.0, 11.0) == "contradicted"  # no partly band
    a = Abs(0.5, partly=1.0)
    assert a.judge(6.0, 5.5) == "reproduced"
    assert a.judge(6.0, 5.38) == "partly"
    assert a.judge(6.0, 4.99) == "contradicted"
    f = Factor(2.0, partly=5.0)
    assert f.judge(0.05, 0.1) == "reproduced"
    assert f.judge(0.05, 0.025) == "reproduced"
    assert f.judge(0.05, 0.0101) == "partly"
    assert f.judge(0.05, 0.009) == "contradicted"
    assert f.judge(0.05, 0.0) == "contradicted"


def test_range_and_inequality_boundaries() -> None:
    b = Between(0.17, 1.01, partly_factor=3.0)
    assert b.judge(None, [0.17, 0.5, 1.01]) == "reproduced"
    assert b.judge(None, [0.1, 0.5]) == "partly"
    assert b.judge(None, [1e-15, 0.5]) == "contradicted"  # no hysteresis at all
    assert AtLeast(1.1, partly=1.01).judge(None, 1.1) == "reproduced"
    assert AtLeast(1.1, partly=1.01).judge(None, 1.05) == "partly"
    assert AtLeast(1.1, partly=1.01).judge(None, 1.0) == "contradicted"
    assert AtMost(0.05, partly=0.15).judge(None, 0.05) == "reproduced"
    assert AtMost(0.05, partly=0.15).judge(None, 0.15) == "partly"
    assert AtMost(0.05, partly=0.15).judge(None, 0.33) == "contradicted"
    with pytest.raises(ClaimError):
        AtMost(0.05).judge(None, math.nan)


def test_trend_direction_monotonicity_and_size() -> None:
    t = Trend("decreasing", min_change=0.10, tie=0.01)
    assert t.judge(None, [6.22, 5.87, 4.32, 4.30]) == "reproduced"  # seed 001's own numbers
    assert t.judge(None, [6.0, 5.99, 5.0]) == "reproduced"  # a tie within 1 % is allowed
    assert t.judge(None, [6.0, 6.5, 5.0]) == "partly"  # falls overall, not monotonically
    assert t.judge(None, [6.0, 5.8, 5.7]) == "partly"  # monotone but only 5 %
    assert t.judge(None, [6.0, 6.02, 5.99]) == "contradicted"  # flat within the tie
    assert t.judge(None, [4.62, 3.0, 1.5][::-1]) == "contradicted"  # rises
    strict = Trend("increasing", tie=0.0, strict=True)
    assert strict.judge(None, [1.0, 2.0, 3.0]) == "reproduced"
    assert strict.judge(None, [1.0, 1.0, 3.0]) == "partly"
    floor = Trend("increasing", min_change=0.1, floor=1e-6)
    assert floor.judge(None, [1e-16, 3e-16, 9e-16]) == "contradicted"  # absent quantity
    both = Trend("increasing", min_change=0.1)
    assert both.judge(None, {"p": [1.0, 2.0], "n": [1.0, 2.0]}) == "reproduced"
    assert both.judge(None, {"p": [1.0, 2.0], "n": [1.0, 1.05]}) == "partly"  # worst counts
    assert both.judge(None, {"p": [1.0, 2.0], "n": [1.0, 0.5]}) == "contradicted"
    with pytest.raises(ClaimError):
        t.judge(None, [1.0])


def test_trend_judges_the_papers_size_of_change() -> None:
    """A trend with the paper's own change (seed 001: 6.22 -> 4.30 Hz, 31 %) is judged by size:
    a 1 % fall the right way is no longer enough."""
    t = Trend("decreasing", tie=0.01, paper_change=0.309)
    assert t.judge(None, [6.22, 5.87, 4.32, 4.30]) == "reproduced"  # the paper's own numbers
    assert t.judge(None, [6.0, 5.0, 4.6]) == "reproduced"  # 23 %: within x2 of 31 %
    assert t.judge(None, [6.0, 5.7, 5.5]) == "partly"  # 8 %: within x4
    assert t.judge(None, [6.0, 5.95, 5.9]) == "contradicted"  # 1.7 %: the right way, too small
    assert t.judge(None, [6.0, 1.0, 0.1]) == "partly"  # 98 %: too large for x2, within x4
    assert t.judge(None, [6.0, 7.0, 3.5]) == "partly"  # the size, but not monotone
    assert t.judge(None, [6.0, 6.5]) == "contradicted"  # the wrong way
    assert "30.9 %" in t.text("Hz")
    for bad in ({"paper_change": 0.0}, {"paper_change": 0.3, "min_change": 0.1}):
        with pytest.raises(ClaimError):
            Trend("decreasing", **bad)  # type: ignore[arg-type]
    with pytest.raises(ClaimError):
        Trend("decreasing", paper_change=0.3, change_factor=1.0)


def test_all_of_and_ranking() -> None:
    a = AllOf(("x", "y", "z"))
    assert a.judge(None, [True, True, True]) == "reproduced"
    assert a.judge(None, [True, True, False]) == "partly"
    assert a.judge(None, [True, False, False]) == "contradicted"
    with pytest.raises(ClaimError):
        a.judge(None, [True])
    r = Ranking(("F", "E", "D", "C", "B", "A"), tie=0.001)
    paper = {"A": 4175, "B": 3051, "C": 2976, "D": 2050, "E": 2021, "F": 2001}
    assert r.judge(None, paper) == "reproduced"
    tie = {**paper, "D": 2976.0}  # C and D tied: 14 of 15 pairs in order
    assert r.judge(None, tie) == "partly"
    assert r.judge(None, {k: -v for k, v in paper.items()}) == "contradicted"


# ----------------------------------------------------------------------------- the runner


def test_failed_experiment_and_interrupt_keep_finished_claims(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    def ok(ctx: Context) -> Measured:
        return Measured(ours=1.05, text="1.05")

    def broken(ctx: Context) -> Measured:
        raise RuntimeError("no such bench")

    def ctrl_c(ctx: Context) -> Measured:
        raise KeyboardInterrupt

    claims = (
        _claim(id="002-a", locator="Sec. V", measure="ok"),
        _claim(id="002-b", locator="Sec. V", measure="broken"),
        _claim(id="002-c", locator="Sec. V", measure="ctrl_c"),
    )
    monkeypatch.setattr(
        runner, "REGISTRY", {"002": (claims, {"ok": ok, "broken": broken, "ctrl_c": ctrl_c})}
    )
    path = tmp_path / "r.json"
    report = runner.Report(papers=["002"], quick=True, backend="native")
    runner.run(
        list(claims), Context(quick=True), report, lambda rep, _: runner.write_json(path, rep)
    )
    assert report.interrupted and not report.complete
    data = json.loads(path.read_text())
    assert [c["id"] for c in data["claims"]] == ["002-a", "002-b"]  # written as they finished
    assert data["claims"][0]["verdict"] == "reproduced"
    failed = data["claims"][1]
    assert failed["verdict"] == "not_implemented" and failed["failed"]
    assert "no such bench" in failed["why"]
    assert report.failed == ["002-b"]


# ---------------------------------------------------------------------------- the command


FIELDS = {
    "id",
    "paper",
    "locator",
    "quote",
    "paper_value",
    "paper_text",
    "unit",
    "tolerance",
    "ours",
    "ours_text",
    "verdict",
    "why",
    "details",
    "post_hoc",
}


def test_reproduce_paper_000_quick_writes_json(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sub" / "report.json"
    assert run_fsarm(monkeypatch, "reproduce", "--paper", "000", "--quick", "--json", str(out)) == 0
    data = json.loads(out.read_text())
    assert data["papers"] == ["000"] and data["quick"] is True
    assert data["complete"] is True and data["failed"] == []
    assert data["finished"] == data["planned"] == len(data["claims"]) > 20
    for c in data["claims"]:
        assert set(c) >= FIELDS
        assert c["paper"] == "000"
        assert c["verdict"] in VERDICTS
        if c["verdict"] in ("not_implemented", "uncheckable"):
            assert c["why"]
        else:
            assert c["ours_text"]
    summary = data["summary"]["000"]
    assert summary["total"] == len(data["claims"])
    assert sum(summary["roles"].values()) == summary["total"]
    for role in (*ROLES, "post_hoc"):
        assert sum(summary[role][v] for v in VERDICTS) == summary[role]["total"]
        assert summary[role]["total"] == sum(
            bool(c["post_hoc"]) if role == "post_hoc" else c["role"] == role and not c["post_hoc"]
            for c in data["claims"]
        )
    for c in data["claims"]:
        assert c["role"] in ROLES
        assert c["evidence"] == (
            c["role"] == "prediction" and not c["post_hoc"] and c["verdict"] == "reproduced"
        )
        assert bool(c["calibrates"]) == (c["role"] == "calibration")
        for name in c["calibrates"]:
            assert c["id"] in data["calibrated_parameters"][name]
    shown = capsys.readouterr().out
    assert "predictions by paper" in shown and "000-length-lever" in shown
    # every contradicted prediction is listed with the cause its note names
    for c in data["claims"]:
        if c["role"] == "prediction" and c["verdict"] == "contradicted":
            assert f"- {c['id']}: " in shown and "no cause named" not in shown


def test_bad_paper_is_one_line_exit_2(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "r.json"
    assert run_fsarm(monkeypatch, "reproduce", "--paper", "005", "--json", str(out)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "--paper" in err and "000" in err and "'005'" in err
    assert not out.exists()
