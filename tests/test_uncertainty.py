from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from fsarm_sim.errors import CoefficientFileError
from fsarm_sim.plant.shaft import UNCERTAINTY_GROUPS, Catalogue, load_catalogue, parse_catalogue
from fsarm_sim.studies import uncertainty as unc

from conftest import run_fsarm

CAT = load_catalogue()


def _data() -> dict[str, Any]:
    import tomllib
    from importlib import resources

    text = resources.files("fsarm_sim.data").joinpath("shafts.toml").read_text("utf-8")
    return tomllib.loads(text)


def test_every_group_declares_a_range_around_nominal_with_a_reason() -> None:
    assert tuple(r.group for r in CAT.uncertainty) == UNCERTAINTY_GROUPS
    for r in CAT.uncertainty:
        assert 0.0 < r.low < 1.0 < r.high and len(r.reason) > 20


def test_a_file_without_ranges_still_loads_and_bad_ranges_are_named() -> None:
    data = _data()
    del data["uncertainty"]
    assert parse_catalogue(data, "x").uncertainty == ()
    data = _data()
    data["uncertainty"]["series"]["relative"] = [1.1, 1.3]  # nominal outside its own range
    with pytest.raises(CoefficientFileError, match="0 < low <= 1 <= high"):
        parse_catalogue(data, "x")
    data = _data()
    data["uncertainty"]["seres"] = {"relative": [0.9, 1.1], "reason": "typo"}
    with pytest.raises(CoefficientFileError, match="did you mean"):
        parse_catalogue(data, "x")
    data = _data()
    del data["uncertainty"]["bending"]["reason"]
    with pytest.raises(CoefficientFileError, match="lacks 'reason'"):
        parse_catalogue(data, "x")


def test_perturbed_scales_each_group_and_only_it() -> None:
    nominal = CAT.shaft(9.0, 450.0)
    s = CAT.perturbed({"series": 1.2}).shaft(9.0, 450.0)
    assert s.k_pos == pytest.approx(1.2 * nominal.k_pos) and s.k_neg == pytest.approx(
        1.2 * nominal.k_neg
    )
    assert s.kb == pytest.approx(nominal.kb) and s.rating_nm == pytest.approx(nominal.rating_nm)
    b = CAT.perturbed({"bending": 0.8, "rating": 1.1}).shaft(9.0, 450.0)
    assert b.kb_eq4 == pytest.approx(0.8 * nominal.kb_eq4)
    assert b.rating_nm == pytest.approx(1.1 * nominal.rating_nm)
    assert b.k_pos == pytest.approx(nominal.k_pos)
    with pytest.raises(CoefficientFileError, match="unknown coefficient group"):
        CAT.perturbed({"stiffness": 1.1})


def test_samples_are_seeded_and_fill_each_range() -> None:
    a = unc.factor_samples(CAT, 64, seed=3)
    assert a == unc.factor_samples(CAT, 64, seed=3)
    assert a != unc.factor_samples(CAT, 64, seed=4)
    for r in CAT.uncertainty:
        v = [s[r.group] for s in a]
        assert r.low <= min(v) < r.low + 0.1 * (r.high - r.low)
        assert r.high - 0.1 * (r.high - r.low) < max(v) <= r.high
    with pytest.raises(unc.UncertaintyError, match="samples"):
        unc.factor_samples(CAT, 1)


def k_sp(cat: Catalogue) -> dict[str, float]:
    return {"k_sp": cat.shaft(9.0, 450.0).k_series(0.0, 1), "nested": {"kb": cat.shaft().kb}}


def test_band_of_a_linear_metric_is_the_declared_range_within_sampling() -> None:
    prop = unc.propagate(k_sp, CAT, 64, workers=2)
    rng = next(r for r in CAT.uncertainty if r.group == "series")
    band = prop.bands["k_sp"]
    nominal = 15.0
    # uniform factor on [low, high]: the 5/95 % quantiles at 5 % / 95 % of the way
    width = rng.high - rng.low
    assert band.low / nominal == pytest.approx(rng.low + 0.05 * width, abs=0.02)
    assert band.high / nominal == pytest.approx(rng.low + 0.95 * width, abs=0.02)
    assert "nested.kb" in prop.bands and prop.failed == 0


def test_run_uncertainty_writes_its_band(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    summary = tmp_path / "s.json"
    args = ["run", "fig14-sine", "--duration", "0.3", "--out", str(tmp_path)]
    assert run_fsarm(monkeypatch, *args, "--json", str(summary), "--uncertainty", "4") == 0
    report = json.loads((tmp_path / "s.uncertainty.json").read_text())
    assert report["samples"] == 4 and report["failed"] == 0
    q3 = report["metrics"]["rmse_deg.q3"]
    assert q3["p05"] <= q3["p50"] <= q3["p95"] and q3["nominal"] > 0


def test_run_uncertainty_needs_declared_ranges(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from importlib import resources

    text = resources.files("fsarm_sim.data").joinpath("shafts.toml").read_text("utf-8")
    start, end = text.index("[uncertainty.series]"), text.index("[[shafts]]")
    f = tmp_path / "no_ranges.toml"
    f.write_text(text[:start] + text[end:])
    args = ["run", "fig14-sine", "--duration", "0.3", "--out", str(tmp_path)]
    assert run_fsarm(monkeypatch, *args, "--shaft-file", str(f), "--uncertainty", "4") == 2
    err = capsys.readouterr().err
    assert "declares no [uncertainty] ranges" in err and "Traceback" not in err


def test_nominal_controller_sees_the_sampled_plant_matched_does_not() -> None:
    """A softer plant than the catalogue says: the nominal controller's eq. 8 estimate is off and
    the joint-3 torque estimate error grows; matched to the sample, it stays as nominal."""
    from fsarm_sim.engine.model import SimConfig

    soft = CAT.perturbed({"series": 0.75})
    kw: dict[str, Any] = {
        "scenario": "fig14-sine",
        "config": SimConfig(),
        "diameter_mm": 9.0,
        "length_mm": 450.0,
        "duration_s": 1.0,
    }
    nominal = unc.run_metrics(CAT, **kw)["tau_estimate_rmse_nm"]
    matched = unc.run_metrics(soft, **kw, controller="matched")["tau_estimate_rmse_nm"]
    blind = unc.run_metrics(soft, **kw, controller="nominal")["tau_estimate_rmse_nm"]
    assert matched == pytest.approx(nominal, rel=0.2)
    assert blind > 2.0 * nominal
    with pytest.raises(unc.UncertaintyError, match="nominal, matched"):
        unc.check_controller("oracle")


def test_sweep_uncertainty_writes_bands_per_point(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    import csv

    store = tmp_path / "s.sqlite"
    args = ["sweep", "--store", str(store), "--grid", "diameter_mm=6,9", "--set", "length_mm=450"]
    args += ["--outputs", "relief", "--no-progress", "--uncertainty", "4", "--workers", "1"]
    assert run_fsarm(monkeypatch, *args) == 0
    rows = list(csv.DictReader((tmp_path / "s.uncertainty.csv").open()))
    rating = {float(r["diameter_mm"]): r for r in rows if r["output"] == "rating_nm"}
    assert set(rating) == {6.0, 9.0}
    for d, r in rating.items():
        nominal = CAT.rating_nm(d)
        assert 0.85 * nominal <= float(r["p05"]) < float(r["p95"]) <= 1.15 * nominal
