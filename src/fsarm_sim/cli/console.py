"""The consoles the CLI prints to: terminal width on a terminal, 140 columns when piped.

Rich falls back to 80 columns when stdout is not a terminal (CI logs, ``| tee``), which folds
or truncates the wider tables; 140 keeps them readable in logs.
"""

from __future__ import annotations

import sys
from typing import Any

from rich.console import Console

PIPED_WIDTH = 140


def make_console(stderr: bool = False, **kwargs: Any) -> Console:
    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else PIPED_WIDTH
    return Console(stderr=stderr, width=kwargs.pop("width", width), **kwargs)
