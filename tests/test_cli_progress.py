"""The progress bar of long commands: driven by the library's progress callbacks, and silent
when standard error is not a terminal (so logs and pipes get only results)."""

from __future__ import annotations

import pytest

from fsarm_sim.cli.progress import steps
from fsarm_sim.studies.dynamics_check import run_checks


def test_steps_are_silent_off_a_terminal(capsys: pytest.CaptureFixture[str]) -> None:
    with steps("demo") as report:
        for i in range(3):
            report(f"step {i}", i, 3)
    captured = capsys.readouterr()
    assert captured.out == "" and "step" not in captured.err


def test_check_dynamics_reports_each_step_in_order() -> None:
    seen: list[tuple[str, int, int]] = []
    run_checks(samples=1, trajectory=False, energy=False, progress=lambda *a: seen.append(a))
    names = [s[0] for s in seen]
    assert names == [
        "models",
        "mass matrix",
        "bias forces",
        "accelerations",
        "controller inputs",
        "done",
    ]
    assert [s[1] for s in seen] == list(range(6)) and {s[2] for s in seen} == {5}
