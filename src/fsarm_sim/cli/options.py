"""Options several commands share, defined once (type, flag and help), so that ``--shaft-file``
or ``--backend`` reads and behaves the same in every command. A fixed set of choices is an enum of
:mod:`fsarm_sim.choices` (listed by ``--help``, accepted in any case); commands hand the
library its plain string (``str(backend)``). A command still states its own
default where it uses one: ``diameter_mm: DiameterMm = 9.0``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fsarm_sim.choices import Backend as BackendChoice
from fsarm_sim.choices import Controller as ControllerChoice
from fsarm_sim.choices import Scenario as ScenarioChoice
from fsarm_sim.choices import Transmission as TransmissionChoice
from fsarm_sim.choices import UncertaintyController as UncertaintyControllerChoice

DiameterMm = Annotated[float, typer.Option(help="shaft diameter D, mm")]
LengthMm = Annotated[float, typer.Option(help="shaft length L, mm")]
ShaftFile = Annotated[
    Path | None,
    typer.Option(help="your own shaft coefficient file (TOML); default: the built-in catalogue"),
]
Extrapolate = Annotated[
    bool, typer.Option(help="allow D/L outside the coefficient file's validity range")
]
Backend = Annotated[
    BackendChoice,
    typer.Option(
        help="callback path: native (compiled) or python (the reference)", case_sensitive=False
    ),
]
Transmission = Annotated[
    TransmissionChoice,
    typer.Option(help="joint 3's transmission (see `fsarm transmissions`)", case_sensitive=False),
]
TrParam = Annotated[
    list[str] | None,
    typer.Option(help="override a transmission parameter, NAME=VALUE (repeatable)"),
]
Effect = Annotated[
    list[str] | None,
    typer.Option(
        "--effect",
        help="switch an arm effect law of the registry on (plant only), "
        "NAME[=V1,V2,...][,KEY=VALUE,...], e.g. lugre_friction=0.3,0.45 (repeatable)",
    ),
]
Controller = Annotated[
    ControllerChoice,
    typer.Option(
        help="joint-3 controller: default (eq. 8, speed feedforward, scheduled PID), "
        "hysteresis-comp (Maxwell-slip torque estimate), dob (disturbance observer), "
        "paper-pid (seed 000 Fig. 13 as printed)",
        case_sensitive=False,
    ),
]
HysteresisModelFile = Annotated[
    Path | None,
    typer.Option(
        help="TOML file of the controller's hysteresis model ([model], fsarm identify-hysteresis "
        "writes it; default: identified on the catalogue prototype's bench records)"
    ),
]


def read_hysteresis_model(path: Path | None) -> tuple[float, ...]:
    """The twelve numbers of a hysteresis-model file, or () (the identified default)."""
    if path is None:
        return ()
    from fsarm_sim.engine.hysteresis_model import load_file

    return load_file(path)


UncertaintyController = Annotated[
    UncertaintyControllerChoice,
    typer.Option(
        help="with --uncertainty: 'nominal' - the controller keeps the catalogue's eq. 8 while the "
        "sampled shaft is the plant (a shaft used as catalogued); 'matched' - the controller "
        "is given each sample's coefficients (a shaft identified on the bench first)",
        case_sensitive=False,
    ),
]
Uncertainty = Annotated[
    int,
    typer.Option(
        help="also sample the coefficient file's [uncertainty] ranges N times (Sobol, 2 threads) "
        "and report the 5-95 % band of every metric; 0: off"
    ),
]
ScenarioOption = Annotated[
    ScenarioChoice,
    typer.Option(help="scenario to run (`fsarm scenarios` describes them)", case_sensitive=False),
]
