"""RunRequest: ``fsarm run``'s orchestration as a library object (the CLI tests cover the
command's own output; these cover what a Python user gets)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsarm_sim import RunRequest, SimConfig, load_catalogue, run_scenario
from fsarm_sim.choices import Backend
from fsarm_sim.errors import InvalidParameterError, OutputPathError
from fsarm_sim.run_request import run_output_plan


def test_execute_writes_what_the_command_writes_and_matches_a_plain_run(tmp_path: Path) -> None:
    request = RunRequest(
        "step-q3", duration=0.05, out=tmp_path / "runs", json_file=tmp_path / "s.json"
    )
    result = request.execute()
    assert (tmp_path / "runs" / "step-q3.csv").is_file()
    assert (tmp_path / "runs" / "step-q3.json").is_file()
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["rmse_rad"] == result.metrics["rmse_rad"]
    plain = run_scenario("step-q3", SimConfig(shaft=load_catalogue().shaft()), duration_s=0.05)
    for name in ("q3", "tau_shaft"):
        assert result.columns[name].tobytes() == plain.columns[name].tobytes()
    assert request.title(result) == "step-q3: D=9 mm, L=450 mm, payload=0 kg"
    assert request.rating_warning(result) is None


def test_from_options_takes_choices_as_strings_and_none_as_default() -> None:
    request = RunRequest.from_options(
        {"scenario": "step-q3", "backend": Backend.PYTHON, "tr_param": None, "ctx": object()},
        ("diameter_mm",),
    )
    assert request.backend == "python" and type(request.backend) is str
    assert request.tr_param == () and request.given == ("diameter_mm",)


def test_inconsistent_options_are_refused_before_the_run(tmp_path: Path) -> None:
    with pytest.raises(InvalidParameterError, match="--rrd-compare needs --rrd"):
        RunRequest("step-q3", rrd_compare=("payload-kg=1",)).check()
    with pytest.raises(InvalidParameterError, match="--diameter-mm would change nothing"):
        RunRequest("step-q3", transmission="qa-joint", given=("diameter_mm",)).check()
    clash = tmp_path / "x.json"
    with pytest.raises(OutputPathError):
        run_output_plan(RunRequest("step-q3", json_file=clash, rrd=clash)).check()
