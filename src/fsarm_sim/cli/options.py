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
from fsarm_sim.choices import Integrator as IntegratorChoice
from fsarm_sim.choices import Scenario as ScenarioChoice
from fsarm_sim.choices import TimeseriesFormat
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

# the options of `fsarm run` alone (RunRequest's fields)
ScenarioArgument = Annotated[
    ScenarioChoice,
    typer.Argument(
        metavar="SCENARIO",
        help="scenario (`fsarm scenarios` describes them)",
        case_sensitive=False,
        show_default=False,
    ),
]
PayloadKg = Annotated[
    float | None, typer.Option(help="payload at the flange, kg (default: the scenario's)")
]
Duration = Annotated[float | None, typer.Option(help="simulated time, s (default: the scenario's)")]
RunOut = Annotated[Path, typer.Option(help="folder for the time series and its sidecar")]
SummaryJson = Annotated[Path | None, typer.Option("--json", help="write a JSON summary here")]
Format = Annotated[
    TimeseriesFormat, typer.Option("--format", help="time-series format", case_sensitive=False)
]
SeriesHysteresis = Annotated[
    bool | None,
    typer.Option(
        help="Maxwell-slip series hysteresis on/off "
        "(default: the coefficient file's series.maxwell_slip.enabled)"
    ),
]
Integrator = Annotated[
    IntegratorChoice | None,
    typer.Option(help="MuJoCo's integrator [default: the model's]", case_sensitive=False),
]
Timestep = Annotated[float | None, typer.Option(help="physics timestep, s (default 0.001)")]
CtrlDt = Annotated[float, typer.Option(help="control period, s")]
LogEvery = Annotated[int, typer.Option(help="log one row every N control ticks")]
Rrd = Annotated[Path | None, typer.Option(help="write a Rerun recording (.rrd) of the run here")]
RrdRate = Annotated[
    float | None, typer.Option(help="recording rate, rows per simulated s (default 100)")
]
Spawn = Annotated[
    bool, typer.Option(help="open the recording in the Rerun viewer if one can run here")
]
Figures = Annotated[
    Path | None, typer.Option(help="write the run's static figures (PNG) into this folder")
]
RrdCompare = Annotated[
    list[str] | None,
    typer.Option(
        help="also run with KEY=VALUE changed (series-hysteresis=on|off, diameter-mm, "
        "length-mm, payload-kg, backend; repeatable) and record both into --rrd"
    ),
]
