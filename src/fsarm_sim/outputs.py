"""Output paths of the ``fsarm`` commands: checked before any work, written without losing results.

* :class:`OutputPlan` collects a command's outputs (files and folders, with the files a folder
  will receive) and its inputs, and :meth:`OutputPlan.check` raises :class:`OutputPathError`
  *before* the run when a file path is an existing folder, a folder path an existing file, a place
  cannot be created or written, two outputs are one file, or an output is one of the inputs.
  Paths are compared resolved (:func:`fsarm_sim.paths.checked_path`, which also names a loop of
  symbolic links, a name too long or a vanished working directory), so ``runs/../runs/a.json``
  and ``runs/a.json`` are the same file.
* :class:`SafeWriter` writes results after the run: a write that still fails (disk full,
  permissions changed meanwhile) goes to a fresh folder ``fsarm-rescue-*`` in the temporary
  directory instead, says so at once, and :meth:`SafeWriter.finish` then raises
  :class:`OutputWriteError` naming where everything went, so the command exits non-zero with the
  results kept.
* :class:`GuardedStream` wraps standard output and error while a command runs
  (:func:`guarded_streams`): a print that fails (a full device, a closed terminal, a broken
  pipe) is remembered, not raised, so it never stops a command before its work is saved.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from fsarm_sim.errors import FsarmError, OutputPathError, OutputWriteError
from fsarm_sim.paths import checked_path

T = TypeVar("T")

RESCUE_PREFIX = "fsarm-rescue-"


@dataclass(frozen=True)
class _Entry:
    label: str  # how messages start with it: "--json", "the time series (--out)"
    noun: str  # how messages refer to it: "the file of --json", "the time series --out writes"
    given: Path  # as the user wrote it
    real: Path  # resolved
    explicit: bool = True  # named by an option (not a file a folder option implies)


def _resolve(path: Path, what: str) -> Path:
    return checked_path(path, what, OutputPathError)


def _nearest_existing(path: Path) -> Path:
    p = path
    while not os.path.lexists(p) and p.parent != p:
        p = p.parent
    return p


def _check_creatable(option: str, given: Path, folder: Path) -> None:
    """``folder`` (resolved) does not exist: its nearest existing ancestor must be a writable
    folder, so that it can be created."""
    base = _nearest_existing(folder)
    if not base.is_dir():
        raise OutputPathError(
            f"{option} {given}: {base} is a file, not a folder; give a path inside a folder"
        )
    if not os.access(base, os.W_OK | os.X_OK):
        raise OutputPathError(
            f"{option} {given}: no permission to write in {base}; give a path in a writable folder"
        )


def check_file_path(option: str, path: Path) -> Path:
    """``path`` will be written as a file: not an existing folder, and creatable or writable.
    Returns the resolved path."""
    real = _resolve(path, option)
    if real.is_dir():
        raise OutputPathError(f"{option} points to the folder {path}; give a file path")
    if real.exists():
        if not os.access(real, os.W_OK):
            raise OutputPathError(
                f"{option} {path} exists and is not writable; give a writable file path"
            )
        return real
    if real.parent.is_dir():
        if not os.access(real.parent, os.W_OK | os.X_OK):
            raise OutputPathError(
                f"{option} {path}: no permission to write in {real.parent}; "
                "give a path in a writable folder"
            )
        return real
    _check_creatable(option, path, real.parent)
    return real


def check_folder_path(option: str, path: Path) -> Path:
    """``path`` will be a folder that receives files: not an existing file, and creatable or
    writable. Returns the resolved path."""
    real = _resolve(path, option)
    if real.exists() and not real.is_dir():
        raise OutputPathError(
            f"{option} points to the file {path}; give a folder (an existing one or a new name)"
        )
    if real.is_dir():
        if not os.access(real, os.W_OK | os.X_OK):
            raise OutputPathError(
                f"{option} {path}: no permission to write in this folder; give a writable folder"
            )
        return real
    _check_creatable(option, path, real)
    return real


class OutputPlan:
    """A command's outputs and inputs, checked together before the command does any work."""

    def __init__(self) -> None:
        self._files: list[_Entry] = []
        self._folders: list[_Entry] = []
        self._inputs: list[_Entry] = []

    def file(self, option: str, path: Path | None) -> OutputPlan:
        """A file the command writes (``None``: not asked for)."""
        if path is not None:
            real = check_file_path(option, path)
            self._files.append(_Entry(option, f"the file of {option}", path, real))
        return self

    def folder(
        self, option: str, path: Path | None, files: Mapping[str, str] | None = None
    ) -> OutputPlan:
        """A folder the command writes into, with the files it will put there
        (``{name: what it is}``, e.g. ``{"run.csv": "the time series"}``)."""
        if path is None:
            return self
        real = check_folder_path(option, path)
        self._folders.append(_Entry(option, f"the folder of {option}", path, real))
        for name, what in (files or {}).items():
            self._files.append(
                _Entry(
                    f"{what} ({option})",
                    f"{what} that {option} writes",
                    path / name,
                    _resolve(real / name, f"{what} ({option})"),
                    explicit=False,
                )
            )
        return self

    def input(self, what: str, path: Path | None) -> OutputPlan:
        """A file the command reads (``what``: e.g. "the dataset's sidecar"); no output may be
        written over it."""
        if path is not None:
            self._inputs.append(_Entry(what, what, path, _resolve(path, what)))
        return self

    def check(self) -> None:
        """Raise :class:`OutputPathError` if two outputs are one file, an output is an input,
        or a file output is one of the folders (or lies inside another file output)."""
        seen: dict[Path, _Entry] = {}
        for f in self._files:
            first = seen.get(f.real)
            if first is not None:
                a, b = (first, f) if first.explicit and not f.explicit else (f, first)
                raise OutputPathError(
                    f"{a.label} {a.given} is the same file as {b.noun}; "
                    "give each output its own path"
                )
            seen[f.real] = f
        inputs = {i.real: i for i in self._inputs}
        for f in self._files:
            if f.real in inputs:
                raise OutputPathError(
                    f"{f.label} {f.given} is {inputs[f.real].noun} (an input): writing it would "
                    "overwrite that input; give another path"
                )
        for d in self._folders:
            if d.real in seen:
                f = seen[d.real]
                raise OutputPathError(
                    f"{f.label} {f.given} is also {d.noun}; give the file another path"
                )
            if d.real in inputs:
                raise OutputPathError(
                    f"{d.label} {d.given} is {inputs[d.real].noun} (an input file); give a folder"
                )
        for f in self._files + self._folders:
            for parent in f.real.parents:
                if parent in seen:
                    raise OutputPathError(
                        f"{f.label} {f.given} lies inside {seen[parent].noun}, "
                        f"{seen[parent].given}, which is written as a file; give another path"
                    )
                if parent in inputs:
                    raise OutputPathError(
                        f"{f.label} {f.given} lies inside {inputs[parent].noun}, "
                        f"{inputs[parent].given}, which is a file; give another path"
                    )


def _reason(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


class SafeWriter:
    """Write results so that a failed write does not lose them.

    ``write(path, writer, what)`` calls ``writer(path)``; if that raises ``OSError`` (or the
    ``RuntimeError`` some libraries raise for I/O), it calls ``writer`` again on a fresh folder
    ``fsarm-rescue-*`` in the temporary directory (``folder=True``: the folder itself; else a file
    of the same name in it), reports where the result went through ``notify``, and carries on.
    :meth:`finish` raises :class:`OutputWriteError` if any write was rescued or lost.
    """

    def __init__(self, notify: Callable[[str], None] | None = None) -> None:
        self.problems: list[str] = []
        self._notify = notify

    def write(
        self, path: Path, writer: Callable[[Path], T], what: str, *, folder: bool = False
    ) -> T | None:
        try:
            return writer(path)
        except FsarmError:
            raise
        except (OSError, RuntimeError) as exc:
            first = _reason(exc)
        rescue = Path(tempfile.mkdtemp(prefix=RESCUE_PREFIX))
        target = rescue if folder else rescue / (path.name or "output")
        try:
            result = writer(target)
        except (OSError, RuntimeError) as exc:
            shutil.rmtree(rescue, ignore_errors=True)
            msg = (
                f"{what} could not be written to {path} ({first}) nor to {target} "
                f"({_reason(exc)}): it is lost"
            )
            self._report(msg)
            return None
        self._report(f"{what} could not be written to {path} ({first}); saved to {target} instead")
        return result

    def _report(self, msg: str) -> None:
        self.problems.append(msg)
        if self._notify is not None:
            self._notify(msg)

    def finish(self) -> None:
        """Raise :class:`OutputWriteError` if a write went elsewhere (or nowhere)."""
        if self.problems:
            raise OutputWriteError(
                f"{len(self.problems)} output(s) not written where asked: "
                + "; ".join(self.problems)
            )


def write_text(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` (UTF-8), creating its folder; return ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, "utf-8")
    return path


def safe_write(
    path: Path, writer: Callable[[Path], T], what: str, *, folder: bool = False
) -> T | None:
    """One :meth:`SafeWriter.write` followed by :meth:`SafeWriter.finish`."""
    w = SafeWriter()
    result = w.write(path, writer, what, folder=folder)
    w.finish()
    return result


class GuardedStream:
    """Standard output (or error) that never raises: the first ``OSError`` of a write or flush
    (a full device, a closed terminal, a broken pipe) is kept in :attr:`error` and what follows
    is dropped, so that a failing print cannot stop a command before it has saved its work.
    The stream's file descriptor is then pointed at ``os.devnull``, so that the interpreter's
    last flush at exit fails no more."""

    buffer = None  # writes go through :meth:`write` (click looks for a binary buffer otherwise)

    def __init__(self, stream: Any) -> None:
        self.stream = stream
        self.error: OSError | None = None

    def _fail(self, exc: OSError) -> None:
        if self.error is None:
            self.error = exc
        with contextlib.suppress(Exception):
            fd = self.stream.fileno()
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, fd)
            os.close(null)

    def write(self, text: str) -> int:
        if self.error is None:
            try:
                return int(self.stream.write(text))
            except OSError as exc:
                self._fail(exc)
        return len(text)

    def flush(self) -> None:
        if self.error is None:
            try:
                self.stream.flush()
            except OSError as exc:
                self._fail(exc)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)


@contextlib.contextmanager
def guarded_streams() -> Iterator[tuple[GuardedStream, GuardedStream]]:
    """``sys.stdout`` and ``sys.stderr`` as :class:`GuardedStream` s for the block (flushed at
    its end, so that a failure shows in their ``error``)."""
    saved = sys.stdout, sys.stderr
    out, err = GuardedStream(sys.stdout), GuardedStream(sys.stderr)
    sys.stdout, sys.stderr = out, err
    try:
        yield out, err
    finally:
        out.flush()
        err.flush()
        sys.stdout, sys.stderr = saved
