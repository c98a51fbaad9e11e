"""The claims files (data/claims/*.toml): every packaged file reads, bad files name what is wrong."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsarm_sim.studies.reproduce import runner
from fsarm_sim.studies.reproduce.claims import PAPERS, Between, Claim, Rel, Trend
from fsarm_sim.studies.reproduce.claims_file import (
    ClaimsFileError,
    paper_claims,
    parse_claims,
    read_claims,
)

GOOD = """
paper = "002"

[[claim]]
id = "002-example"
title = "an example"
locator = "Sec. 1"
quote = "the quote"
paper_text = "12 %"
unit = "%"
paper_value = 12
measure = "example"
issue_item = 3
quick = false
role = "calibration"
calibrates = ["a.b"]
role_why = "a.b was fitted to it"

[claim.tolerance]
kind = "Rel"
tol = 0.1
partly = 0.25

[[claim]]
id = "002-trend"
title = "a trend"
locator = "Fig. 2"
quote = "it rises"
paper_text = "rises"
unit = "-"
not_implemented = "no bench"
role = "prediction"
role_why = "nothing was chosen from it"
post_hoc = "written after ours"

[claim.tolerance]
kind = "Trend"
direction = "increasing"
strict = true
paper_change = 0.31
"""


def test_a_file_becomes_the_claims_it_declares() -> None:
    a, b = parse_claims(GOOD, "x.toml")
    assert a == Claim(
        id="002-example",
        paper="002",
        title="an example",
        locator="Sec. 1",
        quote="the quote",
        paper_text="12 %",
        unit="%",
        tolerance=Rel(0.1, partly=0.25),
        paper_value=12.0,
        measure="example",
        issue_item=3,
        quick=False,
        role="calibration",
        calibrates=("a.b",),
        role_why="a.b was fitted to it",
    )
    assert isinstance(a.paper_value, float)  # an integer in the file is a number like any other
    assert b.tolerance == Trend("increasing", strict=True, paper_change=0.31)
    assert b.post_hoc and b.not_implemented == "no bench" and b.measure is None


def test_packaged_files_hold_every_paper_and_the_runner_reads_them() -> None:
    for paper in PAPERS:
        claims = paper_claims(paper)
        assert claims and all(c.paper == paper for c in claims)
        assert paper_claims(paper) is claims  # read once
    assert runner.all_claims() == tuple(c for p in PAPERS for c in paper_claims(p))
    runner.check_registry()  # ids unique, well formed, every measure known
    kinds = {type(c.tolerance).__name__ for c in runner.all_claims()}
    assert {"Rel", "Between", "Trend", "AllOf", "Ranking"} <= kinds
    between = [c.tolerance for c in runner.all_claims() if isinstance(c.tolerance, Between)]
    assert all(isinstance(t.lo, float) and t.lo <= t.hi for t in between)


def _bad(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new, 1)


@pytest.mark.parametrize(
    ("text", "says"),
    [
        (_bad('title = "an example"', 'titel = "x"'), ["'002-example'", "'titel'", "allowed: id"]),
        (_bad('role = "calibration"\n', ""), ["'002-example'", "missing key 'role'"]),
        (_bad('role_why = "a.b was fitted to it"\n', ""), ["missing key 'role_why'"]),
        (
            _bad('role = "calibration"', 'role = "fit"'),
            ["'002-example'", "prediction, calibration"],
        ),
        (_bad('kind = "Rel"', 'kind = "Relative"'), ["'002-example'", "tolerance.kind", "Ranking"]),
        (_bad("tol = 0.1", 'tol = "10 %"'), ["tolerance Rel", "'tol' must be a finite number"]),
        (_bad("tol = 0.1", "tol = true"), ["'tol' must be a finite number"]),
        (_bad("tol = 0.1", "tol = inf"), ["'tol' must be a finite number"]),
        (
            _bad("tol = 0.1", "tol = 0.1\nslack = 2.0"),
            ["unknown key 'slack'", "allowed: tol, partly"],
        ),
        (_bad("tol = 0.1\n", ""), ["missing key 'tol'"]),
        (_bad('direction = "increasing"', 'direction = "up"'), ["'increasing', 'decreasing'"]),
        (_bad("paper_change = 0.31", "paper_change = -0.31"), ["'002-trend'", "positive fraction"]),
        (_bad("quick = false", "quick = 0"), ["'quick' must be true or false"]),
        (_bad('calibrates = ["a.b"]', 'calibrates = "a.b"'), ["'calibrates' must be a list"]),
        (_bad("issue_item = 3", "issue_item = 3.5"), ["'issue_item' must be an integer"]),
        (_bad('measure = "example"\n', ""), ["exactly one of measure"]),
        (_bad('paper = "002"', 'paper = "009"'), ["key 'paper' must be one of 000"]),
        (_bad('id = "002-trend"', 'id = "002-example"'), ["used twice"]),
        (_bad('id = "002-trend"', 'id = "001-trend"'), ["must start with the paper"]),
        (
            _bad('[claim.tolerance]\nkind = "Rel"\ntol = 0.1\npartly = 0.25\n', ""),
            ["missing key 'tolerance'"],
        ),
        (_bad('paper = "002"', 'paper = "002"\nauthor = "x"'), ["unknown key 'author'"]),
        (_bad('title = "an example"', 'paper = "002"'), ["unknown key 'paper'"]),
        (_bad('title = "an example"', "title = "), ["not valid TOML"]),
        ('paper = "002"\n', ["at least one [[claim]]"]),
    ],
)
def test_a_bad_file_is_a_named_error(text: str, says: list[str]) -> None:
    with pytest.raises(ClaimsFileError) as err:
        parse_claims(text, "bad.toml")
    message = str(err.value)
    assert message.startswith("bad.toml: ") and "\n" not in message
    for part in says:
        assert part in message, (part, message)


def test_a_missing_file_is_a_named_error(tmp_path: Path) -> None:
    with pytest.raises(ClaimsFileError, match="cannot be read"):
        read_claims(tmp_path / "none.toml")
    path = tmp_path / "002.toml"
    path.write_text(GOOD, "utf-8")
    assert [c.id for c in read_claims(path)] == ["002-example", "002-trend"]
