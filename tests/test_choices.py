"""The command's choice enums: each equals the set its library owner accepts, and the command
lists them in ``--help`` and takes them in any case."""

from __future__ import annotations

from enum import Enum
from pathlib import Path

import pytest

from fsarm_sim import choices
from fsarm_sim.discrepancy.synth import TRAJECTORIES
from fsarm_sim.engine.model import CONTROLLERS, INTEGRATORS
from fsarm_sim.executors import EXECUTORS
from fsarm_sim.plant import transmissions
from fsarm_sim.records.sidecar import SETUPS
from fsarm_sim.records.timeseries import FORMATS
from fsarm_sim.review.figures import FORMATS as FIGURE_FORMATS
from fsarm_sim.sim import scenarios
from fsarm_sim.studies.qa_joint_experiments import ADJUST_MODES
from fsarm_sim.studies.uncertainty import CONTROLLER_MODES

from conftest import run_fsarm


@pytest.mark.parametrize(
    ("choice", "owner"),
    [
        (choices.Integrator, tuple(INTEGRATORS)),
        (choices.TimeseriesFormat, FORMATS),
        (choices.FigureFormat, FIGURE_FORMATS),
        (choices.Transmission, tuple(transmissions.names())),
        (choices.Pool, EXECUTORS),
        (choices.Executor, ("auto", *EXECUTORS)),
        (choices.Setup, SETUPS),
        (choices.BenchTrajectory, TRAJECTORIES),
        (choices.StiffnessAdjust, ADJUST_MODES),
        (choices.Controller, tuple(CONTROLLERS)),
        (choices.UncertaintyController, CONTROLLER_MODES),
        (choices.Scenario, tuple(scenarios.REGISTRY)),
    ],
)
def test_each_enum_is_its_owners_set(choice: type[Enum], owner: tuple[str, ...]) -> None:
    assert set(choices.values(choice)) == set(owner)


def test_help_lists_the_choices(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("COLUMNS", "250")
    assert run_fsarm(monkeypatch, "run", "--help") == 0
    out = capsys.readouterr().out
    assert "euler|rk4|implicit|implicitfast" in out
    assert "csv|parquet" in out and "native|python" in out
    assert "flexible-shaft|rtca|qa-joint" in out
    assert "fig14-sine|p2p-payload|step-q3" in out


def test_choices_are_case_insensitive_and_reach_the_library_as_its_strings(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``--integrator rk4`` runs with MuJoCo's RK4 (its sidecar names it as the library does)."""
    args = ["run", "Step-Q3", "--duration", "0.02", "--out", str(tmp_path)]
    args += ["--integrator", "rk4", "--format", "PARQUET", "--backend", "Python"]
    args += ["--json", str(tmp_path / "s.json")]
    assert run_fsarm(monkeypatch, *args) == 0
    assert (tmp_path / "step-q3.parquet").is_file()
    text = (tmp_path / "s.json").read_text() + (tmp_path / "step-q3.json").read_text()
    assert "Integrator." not in text and "Backend." not in text and "Scenario." not in text


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["run", "step-q3", "--integrator", "rk5"], "'rk5' is not one of"),
        (["run", "step-q3", "--duration", "abc"], "'abc' is not a valid float"),
        (["synth", "x.csv", "--setup", "bench"], "--setup"),
        (["sweep", "--store", "s.db", "--executor", "gpu"], "--executor"),
    ],
)
def test_a_bad_choice_is_one_named_line(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    words: str,
) -> None:
    assert run_fsarm(monkeypatch, *args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error:") and words in err and "--help" in err
