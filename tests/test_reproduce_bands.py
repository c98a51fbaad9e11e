from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import reproduce_bands as rb
from fsarm_sim.studies.reproduce import runner
from fsarm_sim.studies.reproduce.claims import Claim

from conftest import run_fsarm


def banded() -> list[Claim]:
    return rb.banded_claims(runner.all_claims())


def test_verdicts_are_identical_with_and_without_bands(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # only the banded claims (and one that gets no band), quick: seconds, not minutes
    others = [c for c in runner.all_claims() if c.id == "000-length-lever"]
    monkeypatch.setattr(runner, "select", lambda papers, quick: [*banded(), *others])
    plain, with_bands = tmp_path / "plain.json", tmp_path / "bands.json"
    args = ["reproduce", "--paper", "000", "--quick", "--json"]
    assert run_fsarm(monkeypatch, *args, str(plain)) == 0
    assert run_fsarm(monkeypatch, *args, str(with_bands), "--uncertainty", "2") == 0
    shown = capsys.readouterr().out
    assert "not used by any verdict" in shown

    def judged(path: Path) -> list[tuple[str, str, object]]:
        return [(c["id"], c["verdict"], c["ours"]) for c in json.loads(path.read_text())["claims"]]

    assert judged(plain) == judged(with_bands)
    assert json.loads(with_bands.read_text())["summary"] == json.loads(plain.read_text())["summary"]
    bands = json.loads((tmp_path / "bands.uncertainty.json").read_text())
    assert bands["used_by_verdicts"] is False and bands["failed"] == 0
    assert set(bands["claims"]) == {c.id for c in banded()}
    assert bands["not_banded"] == ["000-length-lever"]
    for entry in bands["claims"].values():
        for b in entry["band"]:
            assert b["p05"] <= b["p50"] <= b["p95"] and b["n"] == 2
    # the band is a spread, not the nominal value repeated
    track = bands["claims"]["000-fig14-tracking"]["band"][0]
    assert track["p95"] > track["p05"]
    # each band is of its claim's own quantity: at the nominal catalogue it is the claim's value
    assert {c.measure for c in banded()} == set(rb.BANDED)
    nominal = load_catalogue()
    values = rb.claim_values(nominal, measures=tuple(rb.BANDED), nominal=nominal, quick=True)
    for c in banded():
        want = bands["claims"][c.id]["ours"]
        got = values[c.measure]
        if isinstance(want, list):
            assert [got[i] for i in range(len(want))] == pytest.approx(want, rel=1e-12), c.id
        else:
            assert got == pytest.approx(want, rel=1e-12), c.id


def test_bad_sample_count_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run_fsarm(monkeypatch, "reproduce", "--paper", "000", "--uncertainty", "1") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--uncertainty" in err
