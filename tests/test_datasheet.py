from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import datasheet as ds

from conftest import run_fsarm

CAT = load_catalogue()
QUICK = ds.Settings(
    bends_deg=(0.0, 90.0),
    bench_bends_deg=(90.0,),
    scenarios=("fig14-sine",),
    payloads_kg=(15.0,),
    duration_s=0.5,
    chirp_s=1.0,
)


def test_catalogue_numbers_are_the_catalogue_and_the_paper_relief() -> None:
    sheet = ds.datasheet(
        CAT, diameter_mm=9.0, length_mm=450.0, settings=ds.Settings(simulate=False)
    )
    nums = sheet["numbers"]
    shaft = CAT.shaft(9.0, 450.0)
    assert nums["k_sp.90deg"]["value"] == pytest.approx(shaft.k_series(math.pi / 2, 1))
    assert nums["k_sn.0deg"]["value"] < nums["k_sp.0deg"]["value"]
    assert nums["rating_nm"]["source"] == ds.CATALOGUE
    # the prototype's relief at 90 deg is the paper's "about 8 N*m" (the catalogue was sized on it)
    assert nums["relief_nm.90deg"]["value"] == pytest.approx(
        sheet["paper"]["relief_nm.90deg"]["value"], rel=0.01
    )
    # hysteresis grows with the bend (capstan), the bound inertia with D^4 L
    assert nums["loop_width_nm.90deg"]["value"] > nums["loop_width_nm.0deg"]["value"]
    thick = ds.measure(CAT, diameter_mm=13.0, length_mm=450.0, settings=ds.Settings(simulate=False))
    assert thick["inertia_steel_core_kgm2"] == pytest.approx(
        nums["inertia_steel_core_kgm2"]["value"] * (13.0 / 9.0) ** 4
    )
    assert (
        ds.datasheet(CAT, diameter_mm=6.0, length_mm=435.0, settings=ds.Settings(simulate=False))[
            "paper"
        ]
        == {}
    )


def test_simulated_numbers_agree_with_fsarm_run_and_transparency(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    values = ds.measure(CAT, diameter_mm=9.0, length_mm=450.0, settings=QUICK)
    summary = tmp_path / "run.json"
    args = ["run", "fig14-sine", "--duration", "0.5", "--payload-kg", "15", "--out", str(tmp_path)]
    assert run_fsarm(monkeypatch, *args, "--json", str(summary)) == 0
    run = json.loads(summary.read_text())
    key = "track.fig14-sine.15kg"
    assert values[f"{key}.q3_rmse_deg"] == pytest.approx(run["rmse_deg"]["q3"], rel=1e-9)
    assert values[f"{key}.motor_energy_j"] == pytest.approx(run["motor_energy_j"], rel=1e-9)
    tr = tmp_path / "tr.json"
    assert run_fsarm(monkeypatch, "transparency", "--bend", "90", "--json", str(tr)) == 0
    row = json.loads(tr.read_text())[0]
    assert values["impedance_low_nm_per_rad.90deg"] == pytest.approx(
        row["impedance_low_nm_per_rad"], rel=1e-9
    )
    bench = tmp_path / "bench"
    args = ["bench", "series", "--bends", "90", "--workers", "1", "--out", str(bench)]
    assert run_fsarm(monkeypatch, *args) == 0
    (row,) = pd.read_csv(bench / "series_table_D9-L450.csv").to_dict("records")
    for key, col in (("bench_k_sp", "K_sp"), ("bench_k_sn", "K_sn"), ("bench_rmse_p_nm", "RMSE_p")):
        assert values[f"{key}.90deg"] == pytest.approx(row[col], rel=1e-9)
    # the series test of the datasheet returns eq. 3 (the catalogue's round trip, 000-series-roundtrip)
    assert values["bench_k_sp.90deg"] == pytest.approx(values["k_sp.90deg"], rel=0.02)


def test_datasheet_command_writes_the_page(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["datasheet", "--shaft", "MF06-435", "--catalogue-only", "--out", str(tmp_path)]
    assert run_fsarm(monkeypatch, *args) == 0
    for ext in ("json", "html", "pdf", "png"):
        assert (tmp_path / f"MF06-435.{ext}").stat().st_size > 0
    page = (tmp_path / "MF06-435.html").read_text()
    assert "series stiffness, winding side (eq. 3)" in page and "catalogue estimate" in page
    data = json.loads((tmp_path / "MF06-435.json").read_text())
    assert data["shaft"]["diameter_mm"] == 6.0
    assert run_fsarm(monkeypatch, "datasheet", "--shaft", "MF99", "--out", str(tmp_path)) == 2
    err = capsys.readouterr().err
    assert "MF99" in err and "MF09-450" in err and "Traceback" not in err


def test_datasheet_band_with_uncertainty(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    args = ["datasheet", "--diameter-mm", "9", "--length-mm", "450", "--catalogue-only"]
    assert run_fsarm(monkeypatch, *args, "--out", str(tmp_path), "--uncertainty", "8") == 0
    data = json.loads((tmp_path / "D9-L450.json").read_text())
    band = data["numbers"]["k_sp.0deg"]["band"]
    assert band["p05"] < data["numbers"]["k_sp.0deg"]["value"] < band["p95"]
    assert data["uncertainty"]["samples"] == 8
