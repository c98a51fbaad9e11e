"""Options several commands share, defined once (type, flag and help), so that ``--shaft-file``
or ``--backend`` reads and behaves the same in every command. A command still states its own
default where it uses one: ``diameter_mm: DiameterMm = 9.0``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

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
    str, typer.Option(help="callback path: native (compiled) or python (the reference)")
]
Transmission = Annotated[
    str, typer.Option(help="joint 3's transmission (see `fsarm transmissions`)")
]
TrParam = Annotated[
    list[str] | None,
    typer.Option(help="override a transmission parameter, NAME=VALUE (repeatable)"),
]
UncertaintyController = Annotated[
    str,
    typer.Option(
        help="with --uncertainty: 'nominal' - the controller keeps the catalogue's eq. 8 while the "
        "sampled shaft is the plant (a shaft used as catalogued); 'matched' - the controller "
        "is given each sample's coefficients (a shaft identified on the bench first)"
    ),
]
Uncertainty = Annotated[
    int,
    typer.Option(
        help="also sample the coefficient file's [uncertainty] ranges N times (Sobol, 2 threads) "
        "and report the 5-95 % band of every metric; 0: off"
    ),
]
