"""``fsarm run --controller``, ``fsarm compare-controllers``: options, records, named errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsarm_sim.engine import hysteresis_model as hm
from fsarm_sim.plant.shaft import load_catalogue

from conftest import run_fsarm


def test_run_records_the_controller_and_its_model(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    model = tmp_path / "m.toml"
    values = hm.scaled(hm.default_fractions(), load_catalogue().shaft())
    values = (*values[:7], *(1.3 * f for f in values[7:10]), *values[10:])  # slip torques +30 %
    model.write_text(hm.model_toml(values), "utf-8")
    args = ["run", "fig14-sine", "--duration", "0.3", "--out", str(tmp_path)]
    code = run_fsarm(
        monkeypatch, *args, "--controller", "hysteresis-comp", "--hysteresis-model", str(model)
    )
    assert code == 0
    gains = json.loads((tmp_path / "fig14-sine.json").read_text())["gains"]
    assert gains["controller"] == "hysteresis-comp"
    assert gains["hysteresis_model"] == pytest.approx(list(values))
    # without a file the identified default is written out (the record replays as it ran)
    assert run_fsarm(monkeypatch, *args, "--controller", "hysteresis-comp") == 0
    gains = json.loads((tmp_path / "fig14-sine.json").read_text())["gains"]
    assert len(gains["hysteresis_model"]) == 12


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--controller", "pd"], "'pd' is not one of 'default', 'hysteresis-comp', 'dob'"),
        (["--controller", "hysteresis-comp", "--hysteresis-model", "nofile.toml"], "nofile"),
    ],
)
def test_run_refuses_bad_controller_options(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    extra: list[str],
    message: str,
) -> None:
    code = run_fsarm(monkeypatch, "run", "fig14-sine", "--duration", "0.3", *extra)
    assert code == 2
    assert message in capsys.readouterr().err


def test_compare_controllers_table_and_json(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "rows.json"
    code = run_fsarm(
        monkeypatch,
        "compare-controllers",
        "--controller",
        "default",
        "--controller",
        "dob",
        "--duration",
        "0.5",
        "--no-frequency",
        "--json",
        str(out),
    )
    assert code == 0
    assert "dob" in capsys.readouterr().out
    rows = json.loads(out.read_text())
    assert [r["controller"] for r in rows] == ["default", "dob"]
    for r in rows:
        assert set(r["q3_rmse_deg"]) == {"fig14", "fig14-15kg", "fig14-bent90", "p2p", "step-q3"}
        assert r["tau_estimate_rmse_nm"] > 0.0 and not r["failures"]
    assert run_fsarm(monkeypatch, "compare-controllers", "--controller", "pid") == 2
