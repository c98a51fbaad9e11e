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


@pytest.mark.parametrize(
    ("setup", "record_step"),
    [("series_bench", "simulating the bench"), ("arm", "running the scenario")],
)
def test_synth_reports_its_steps(setup: str, record_step: str) -> None:
    from fsarm_sim.discrepancy import synth
    from fsarm_sim.discrepancy.arm_synth import ArmRecording

    seen: list[tuple[str, int, int]] = []
    rec = (
        synth.Recording(duration_s=0.5)
        if setup != "arm"
        else ArmRecording(scenario="step-q3", duration_s=0.1)
    )
    cols, _, _ = synth.synthesize_setup(setup, recording=rec, progress=lambda *a: seen.append(a))
    assert seen == [("the truth model", 0, 2), (record_step, 1, 2)]
    assert len(cols["t"]) > 10
