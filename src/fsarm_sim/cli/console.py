"""The consoles the CLI prints to: terminal width on a terminal, 140 columns when piped.

Rich falls back to 80 columns when stdout is not a terminal (CI logs, ``| tee``), which folds
or truncates the wider tables; 140 keeps them readable in logs. While a command runs, both
streams are :class:`fsarm_sim.outputs.GuardedStream` s: a print that fails never stops the
command's work.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

PIPED_WIDTH = 140


def make_console(stderr: bool = False, **kwargs: Any) -> Console:
    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else PIPED_WIDTH
    return Console(stderr=stderr, width=kwargs.pop("width", width), **kwargs)


def number_table(title: str, columns: Iterable[str]) -> Table:
    """A table of numbers: one right-justified column per name (names printed as written, not
    read as Rich markup)."""
    table = Table(title=title)
    for col in columns:
        table.add_column(escape(col), justify="right")
    return table


def write_rows_json(
    json_file: Path | None, rows: Sequence[Any], console: Console, err: Console
) -> None:
    """Write a comparison's rows (each with ``as_dict()``) to ``--json`` through a SafeWriter
    (a failed write is rescued and warned about) and say where they went."""
    from fsarm_sim.outputs import SafeWriter, write_text

    writes = SafeWriter(lambda msg: err.print(f"warning: {msg}", markup=False))
    if json_file is not None:
        text = json.dumps([r.as_dict() for r in rows], indent=2)
        where = writes.write(json_file, lambda p: write_text(p, text), "the rows (--json)")
        if where is not None:
            console.print(f"rows: {where}", markup=False)
    writes.finish()
