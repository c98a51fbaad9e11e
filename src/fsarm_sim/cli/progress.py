"""A progress bar for commands that take longer than a couple of seconds (on standard error, so
standard output keeps only the results; nothing is drawn when it is not a terminal)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from fsarm_sim.cli.console import make_console


@contextmanager
def steps(title: str) -> Iterator[Callable[[str, int, int | None], None]]:
    """``with steps("check-dynamics") as report: run(..., progress=report)``: ``report(step,
    done, total)`` moves the bar to ``done`` of ``total`` (None: not known ahead) and names the
    current step. Nothing is drawn where stderr is not a terminal."""
    bar = Progress(
        TextColumn(f"{title}: [bold]{{task.description}}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=make_console(stderr=True),
        transient=True,
    )
    task = bar.add_task("starting", total=None)

    def report(step: str, done: int, total: int | None) -> None:
        bar.update(task, description=step, completed=done, total=total)

    with bar:
        yield report
