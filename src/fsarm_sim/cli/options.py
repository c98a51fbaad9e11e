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
from fsarm_sim.choices import Transmission as TransmissionChoice

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
