"""Start-up helpers of the ``fsarm`` command: its Typer app, completed on first use, and
background imports.

Importing every command module (``fsarm_sim.cli.review``, ``.sweep``, ``.discrepancy``, ...) and
letting Typer build all of their commands costs about 0.05 s of start-up that a short
``fsarm run`` does not need. :class:`LazyTyper` keeps the app whole for every reader - ``app()``,
``typer.main.get_command(app)``, ``CliRunner().invoke(app, ...)``, ``fsarm --help`` - because the
extension modules are registered the first time Typer reads the command list (after
:meth:`LazyTyper.ready`), except inside :meth:`LazyTyper.core_only`, which ``fsarm``'s ``main``
uses when the command asked for is one defined in ``fsarm_sim.cli`` itself (``fsarm run ...``).
:func:`preload` imports a module in a background thread (``fsarm run`` imports its writer,
pyarrow, while the run steps with the GIL released).

A type, so it lives in the library (``tests/test_imports.py``: CLI modules define none); it
knows nothing of fsarm's commands.
"""

from __future__ import annotations

import atexit
import contextlib
import gc
import importlib
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import typer

_FREEZE_AT_EXIT: list[bool] = []


def freeze_at_exit() -> None:
    """At interpreter exit (after the command returned and its files were closed), move every
    object into the collector's permanent generation (``gc.freeze``): the exit's collections then
    skip them, which took 0.06-0.1 s of a short ``fsarm run`` (its imports alone hold ~10^5
    objects). What this gives up - ``__del__`` of objects still in reference cycles at exit - is
    what Python does not promise at exit anyway ("It is not guaranteed that __del__() methods
    are called for objects that still exist when the interpreter exits", the data model).
    Registered once per process."""
    if not _FREEZE_AT_EXIT:
        _FREEZE_AT_EXIT.append(True)
        atexit.register(gc.freeze)


def freeze_imports_if_entry(entry: Callable[[], None]) -> bool:
    """``gc.freeze()`` now if this process exists to run ``entry``: its ``__main__`` imported it
    (the ``fsarm`` console script, ``python -c "from fsarm_sim.cli import main; main()"``). The
    objects made by the imports so far live as long as the process, and the collector's full
    passes over them took ~0.04 s of a short ``fsarm run``; frozen, they are skipped. A process
    that merely calls ``entry`` (a test) is left alone: freezing there would also keep whatever
    garbage it holds at that moment. Returns whether it froze."""
    if getattr(sys.modules.get("__main__"), "main", None) is not entry:
        return False
    gc.freeze()
    return True


def preload(*modules: str) -> threading.Thread:
    """Import ``modules`` in a background thread, while the caller goes on (a run steps with the
    GIL released, so an import of the output writer there costs no wall time where a second
    core is free). An import that fails here fails again, and is reported, where it is used."""

    def work() -> None:
        for name in modules:
            with contextlib.suppress(Exception):
                importlib.import_module(name)

    # not a daemon: the interpreter never shuts down in the middle of an import
    thread = threading.Thread(target=work, name="fsarm-preload")
    thread.start()
    return thread


def command_name(argv: Sequence[str]) -> str | None:
    """The subcommand in ``argv`` (the first argument not starting with ``-``); None if there
    is none or an option comes first (``fsarm --help run`` needs the whole app)."""
    if not argv or argv[0].startswith("-"):
        return None
    return argv[0]


class LazyTyper(typer.Typer):
    """A Typer app whose extension commands are registered by ``register_extensions`` the first
    time the command list is read after :meth:`ready` (not inside :meth:`core_only`)."""

    def __init__(self, *, register_extensions: Callable[[], None], **kwargs: Any) -> None:
        self._register_extensions = register_extensions
        self._ready = False
        self._loaded = False
        self._core_only = False
        self._commands: list[Any] = []
        self._groups: list[Any] = []
        super().__init__(**kwargs)

    def _load(self) -> None:
        if self._ready and not self._loaded and not self._core_only:
            self._loaded = True
            self._register_extensions()

    # Typer's own attributes, read when it builds the command line and appended to by
    # ``@app.command`` / ``app.add_typer``
    @property
    def registered_commands(self) -> list[Any]:
        self._load()
        return self._commands

    @registered_commands.setter
    def registered_commands(self, value: list[Any]) -> None:
        self._commands = value

    @property
    def registered_groups(self) -> list[Any]:
        self._load()
        return self._groups

    @registered_groups.setter
    def registered_groups(self, value: list[Any]) -> None:
        self._groups = value

    def ready(self) -> None:
        """The commands of this module are defined: the next read of the command list registers
        the extension modules' commands."""
        self._ready = True

    def core_names(self) -> set[str]:
        """Names of the commands registered so far without the extensions."""
        return {c.name for c in self._commands if c.name}

    @contextlib.contextmanager
    def core_only(self) -> Iterator[None]:
        """Within: reading the command list does not register the extensions (unless they
        already are)."""
        self._core_only = True
        try:
            yield
        finally:
            self._core_only = False
