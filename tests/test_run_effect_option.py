"""``fsarm run --effect``: the registry's arm laws switched on from the command line, the text
read by :func:`fsarm_sim.plant.effects.registry.parse_law` (positional values = the arm
variant's parameters, KEY=VALUE = any kernel parameter), bad text one named line."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects.registry import parse_law, parse_laws

from conftest import run_fsarm


def test_values_by_position_then_by_name() -> None:
    assert parse_law("shaft_drag") == ("shaft_drag", ())
    assert parse_law("shaft_drag=0.05,0.5") == (
        "shaft_drag",
        (("drag_nm", 0.05), ("mu_per_rad", 0.5)),
    )
    assert parse_law(" shaft_drag = 0.05 , omega_s=2") == (
        "shaft_drag",
        (("drag_nm", 0.05), ("omega_s", 2.0)),
    )
    assert parse_laws([]) == ()
    # the laws that act on the twist or through MuJoCo's model take their values the same way
    assert parse_law("backlash=0.03") == ("backlash", (("width_rad", 0.03),))
    assert parse_law("backlash=0.03,-0.01") == (
        "backlash",
        (("width_rad", 0.03), ("center_rad", -0.01)),
    )
    assert parse_law("coulomb_friction=0.5") == ("coulomb_friction", (("f_c_nm", 0.5),))
    assert parse_law("viscous_damping=b_nms=0.2") == ("viscous_damping", (("b_nms", 0.2),))
    # an old hand-wired effect that is a registry law now: its mass error by position
    assert parse_law("payload_error=0.5") == ("payload_error", (("dm_kg", 0.5),))


def test_a_law_geometry_read_from_the_model_cannot_be_given() -> None:
    from fsarm_sim.engine.model import Effects

    with pytest.raises(InvalidParameterError, match=r"payload_error.l2 is read from the compiled"):
        Effects(laws=(parse_law("payload_error=0.5,l2=1"),)).validate()
    with pytest.raises(InvalidParameterError, match="'payload_error' is given twice"):
        Effects(laws=(parse_law("payload_error=0.5"), parse_law("payload_error=1"))).validate()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "no_such=1",
            "'no_such' is not an arm effect law; known: coulomb_friction, viscous_damping, "
            "backlash, payload_error, shaft_drag",
        ),
        ("delay=0.1", "'delay' is not an arm effect law"),
        ("backlash=0.1,0,0", "takes at most 2 values by position (width_rad, center_rad)"),
        ("shaft_drag=1,2,3", "takes at most 2 values by position (drag_nm, mu_per_rad)"),
        ("shaft_drag=omega_s=2,0.1", "before any KEY=VALUE"),
        ("shaft_drag=k=2", "shaft_drag has no parameter 'k'; its parameters: drag_nm"),
        ("shaft_drag=x", "drag_nm must be a number, got 'x'"),
    ],
)
def test_malformed_text_is_a_named_error(text: str, message: str) -> None:
    with pytest.raises(
        InvalidParameterError, match=message.replace("(", r"\(").replace(")", r"\)")
    ):
        parse_law(text)


def test_run_switches_a_law_on_and_records_it(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    args = ("run", "step-q3", "--duration", "0.2", "--out", str(tmp_path))
    assert run_fsarm(monkeypatch, *args, "--effect", "shaft_drag=0.05,0.5") == 0
    sidecar = json.loads((tmp_path / "step-q3.json").read_text())
    assert sidecar["effects"]["laws"] == {"shaft_drag": {"drag_nm": 0.05, "mu_per_rad": 0.5}}
    with_drag = pd.read_csv(tmp_path / "step-q3.csv")
    assert run_fsarm(monkeypatch, *args) == 0
    assert "laws" not in json.loads((tmp_path / "step-q3.json").read_text())["effects"]
    assert not with_drag["tau_motor"].equals(pd.read_csv(tmp_path / "step-q3.csv")["tau_motor"])


@pytest.mark.parametrize("text", ["backlash=0.02", "coulomb_friction=0.5", "viscous_damping=2"])
def test_run_switches_the_twist_and_model_laws_on(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, text: str
) -> None:
    """A backlash (on the twist), joint-3 friction and damping (MuJoCo's model) from the command
    line: recorded as laws, and the run differs from one without."""
    args = ("run", "step-q3", "--duration", "0.2", "--out", str(tmp_path))
    assert run_fsarm(monkeypatch, *args, "--effect", text) == 0
    name, values = parse_law(text)
    laws = json.loads((tmp_path / "step-q3.json").read_text())["effects"]["laws"]
    assert laws == {name: dict(values)}
    on = pd.read_csv(tmp_path / "step-q3.csv")
    assert run_fsarm(monkeypatch, *args) == 0
    assert not on["q3"].equals(pd.read_csv(tmp_path / "step-q3.csv")["q3"])


def test_run_refuses_a_bad_effect_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ("run", "step-q3", "--duration", "0.2", "--out", str(tmp_path))
    assert run_fsarm(monkeypatch, *args, "--effect", "shaft_drag=9") == 2
    err = capsys.readouterr().err
    assert "shaft_drag.drag_nm must be within [0, 2] N*m, got 9.0" in err
    assert "Traceback" not in err and not (tmp_path / "step-q3.csv").exists()
