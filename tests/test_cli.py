"""The fsarm command: thin, and bad input is one named line with exit code 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from conftest import run_fsarm


def test_scenarios_lists_registry(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run_fsarm(monkeypatch, "scenarios") == 0
    out = capsys.readouterr().out
    assert "fig14-sine" in out and "p2p-payload" in out


def test_run_writes_timeseries_and_summary(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    summary = tmp_path / "s.json"
    code = run_fsarm(
        monkeypatch,
        "run",
        "fig14-sine",
        "--duration",
        "0.5",
        "--out",
        str(tmp_path),
        "--json",
        str(summary),
    )
    assert code == 0
    data = json.loads(summary.read_text())
    assert set(data["rmse_rad"]) == {"q1", "q2", "q3"}
    assert data["realtime_factor"] > 0
    table = pd.read_csv(tmp_path / "fig14-sine.csv")
    assert {"t", "q1", "q2", "q3", "q3_ref", "theta_m", "theta_s", "tau_shaft", "tau_model"} <= set(
        table.columns
    )
    sidecar = json.loads((tmp_path / "fig14-sine.json").read_text())
    assert sidecar["setup"] == "arm"
    assert sidecar["shaft"] == {"diameter_mm": 9.0, "length_mm": 450.0}


@pytest.mark.parametrize("transmission", ["rtca", "tendon-sheath"])
def test_run_shaft_size_sets_the_bending_on_joint_2_of_a_routed_transmission(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, transmission: str
) -> None:
    """The shaft options refused for transmissions that ignore them stay allowed where they
    act: a routed transmission keeps the catalogue shaft's bending moment on joint 2."""
    bend = []
    for length in ("450", "300"):
        out = tmp_path / length
        args = ["run", "fig14-sine", "--duration", "0.3", "--out", str(out)]
        args += ["--transmission", transmission, "--length-mm", length]
        assert run_fsarm(monkeypatch, *args) == 0
        bend.append(pd.read_csv(out / "fig14-sine.csv")["tau_bend"].to_numpy())
    assert abs(bend[0] - bend[1]).max() > 1e-3


def test_run_parquet(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    assert (
        run_fsarm(
            monkeypatch,
            "run",
            "step-q3",
            "--duration",
            "0.2",
            "--out",
            str(tmp_path),
            "--format",
            "parquet",
        )
        == 0
    )
    assert len(pd.read_parquet(tmp_path / "step-q3.parquet")) == 200


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "nope"], "'nope' is not one of 'fig14-sine'"),
        (["run", "fig14-sine", "--duration", "nan"], "duration"),
        (["run", "fig14-sine", "--duration", "-2"], "duration"),
        (["run", "fig14-sine", "--diameter-mm", "20"], "validity range"),
        (["run", "fig14-sine", "--length-mm", "100"], "validity range"),
        (["run", "fig14-sine", "--shaft-file", "/no/such.toml"], "not found"),
        (["run", "fig14-sine", "--payload-kg", "40"], "payload"),
        (["run", "fig14-sine", "--format", "xlsx"], "format"),
    ],
)
def test_bad_input_is_a_named_error(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    args: list[str],
    message: str,
) -> None:
    assert run_fsarm(monkeypatch, *args, "--out", str(tmp_path)) == 2 if args[0] == "run" else True
    err = capsys.readouterr().err
    assert "error:" in err and message in err
    assert "Traceback" not in err


def test_malformed_coefficient_file(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("[series]\n")
    assert (
        run_fsarm(
            monkeypatch, "run", "fig14-sine", "--shaft-file", str(bad), "--out", str(tmp_path)
        )
        == 2
    )
    assert "missing key" in capsys.readouterr().err


@pytest.mark.parametrize(("transmission", "noted"), [("magnetic-spring", True), ("rtca", False)])
def test_transparency_says_when_the_bend_cannot_matter(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    transmission: str,
    noted: bool,
) -> None:
    """A transmission not routed over joint 2 gets a note under its bend table (its law does
    not read the bend); a routed one does not."""
    args = ["transparency", "--transmission", transmission, "--bend", "0"]
    assert run_fsarm(monkeypatch, *args) == 0
    assert ("is not routed over joint 2" in capsys.readouterr().out) is noted


def test_campaign_coefficient_changes_have_no_nan() -> None:
    """A coefficient the catalogue holds at 0 (eq. 3's p4 under the inverse-length law) has no
    relative change: it is said as it is, never as ``+nan %``."""
    from fsarm_sim.cli.bench import coefficient_change

    assert coefficient_change("p1", 0.021, 1.4, 1.37) == "p1: +2.1 %"
    assert coefficient_change("p4", math.nan, 0.0, 0.0) == "p4: 0 in both (held at 0, not fitted)"
    assert "nan" not in coefficient_change("p4", math.nan, -0.003, 0.0)


def test_a_negative_fitted_inertia_is_explained() -> None:
    from fsarm_sim.cli.bench import inertia_note

    assert inertia_note([0.001, 0.002]) == ""
    note = inertia_note([0.001, -0.0014])
    assert "not identifiable" in note and "-0.0014" in note
