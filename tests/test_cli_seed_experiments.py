"""``fsarm model-selection``, ``fsarm qa-throws`` and ``fsarm rtca-fig12``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import run_fsarm


def test_model_selection_prints_table_4(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "ms.json"
    assert run_fsarm(monkeypatch, "model-selection", "--trial-s", "2", "--json", str(out)) == 0
    text = capsys.readouterr().out
    assert "Teaching set" in text and "Verifying set" in text
    data = json.loads(out.read_text())
    assert set(data["rows"]) == {"A", "B", "C", "D", "E", "F", "AL", "FL"}


def test_qa_throws_prints_epsilon(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code = run_fsarm(monkeypatch, "qa-throws", "--presets", "7", "--speeds", "75")
    assert code == 0
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.split()[:2] == ["7", "75"]]
    assert len(line) == 1 and 2.0 < float(line[0].split()[2]) < 3.5


def test_qa_throws_refuses_a_preset_outside_table_iv(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    assert run_fsarm(monkeypatch, "qa-throws", "--presets", "8", "--speeds", "75") == 2


def test_qa_throws_refuses_text_for_numbers(monkeypatch: pytest.MonkeyPatch) -> None:
    assert run_fsarm(monkeypatch, "qa-throws", "--presets", "soft") == 2
    assert run_fsarm(monkeypatch, "model-selection", "--unbalance", "-1") == 2


def test_rtca_fig12_refuses_bad_input_before_running(monkeypatch: pytest.MonkeyPatch) -> None:
    assert run_fsarm(monkeypatch, "rtca-fig12", "--radii-mm", "0") == 2
    assert run_fsarm(monkeypatch, "rtca-fig12", "--radii-mm", "flat") == 2
    assert run_fsarm(monkeypatch, "rtca-fig12", "--duration-s", "5") == 2
