"""SynthRequest: ``fsarm synth``'s checks and recording settings as a library object (the
command's output is covered by tests/test_synth.py)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from fsarm_sim.choices import Setup
from fsarm_sim.discrepancy.synth_request import SynthRequest
from fsarm_sim.errors import InvalidParameterError


def test_from_options_takes_choices_as_strings() -> None:
    request = SynthRequest.from_options(
        {"out": Path("x.csv"), "setup": Setup.ARM, "effect": ["delay=0.01"], "progress": 1}
    )
    assert request.setup == "arm" and type(request.setup) is str
    assert request.effect == ("delay=0.01",)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"inertia": -1.0}, "--inertia must be a finite number > 0"),
        ({"noise": math.nan}, "--noise must be a finite number >= 0"),
        ({"rate": 0.0}, "--rate must be a finite number > 0 Hz"),
        ({"setup": "arm", "bend_deg": 3.0}, "--bend-deg set the benches' recordings"),
    ],
)
def test_bad_or_contradictory_options_are_refused(changes: dict, message: str) -> None:
    with pytest.raises(InvalidParameterError, match=message):
        SynthRequest(Path("x.csv"), **changes).check()


def test_recording_takes_the_defaults_of_what_is_not_given() -> None:
    from fsarm_sim.discrepancy import synth

    rec = SynthRequest(Path("x.csv"), bend_deg=30.0, trajectory="steps").recording()
    assert isinstance(rec, synth.Recording)
    assert rec.bend_rad == pytest.approx(math.radians(30.0)) and rec.trajectory == "steps"
    assert rec.rate_hz == synth.Recording.rate_hz and rec.duration_s == synth.Recording.duration_s
