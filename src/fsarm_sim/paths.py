"""Every path fsarm opens or writes, resolved with the operating system's errors named.

:func:`checked_path` is the one door: it makes a path absolute and resolves it, and turns what
the operating system can say about a path into the caller's named error (one line: the option,
the path, what is wrong, what to do) instead of a traceback:

* a loop of symbolic links (``ELOOP``; ``Path.resolve`` raises ``RuntimeError`` for it),
* a name longer than the file system allows (``ENAMETOOLONG``),
* a working directory that no longer exists (``os.getcwd`` raises ``FileNotFoundError``),
* no permission to look into a folder on the way (``EACCES``), a NUL character in the name.

:func:`os_problem` words any ``OSError`` (``ENOSPC``, ``EACCES``, ``EROFS``, ``EIO`` ...) the
same way for the readers and writers that meet one later; :func:`named_os_errors` wraps a
block that opens or writes a file. :func:`bounded_toml` and :func:`bounded_json` parse a
file's text with its nesting depth bounded (:data:`MAX_NESTING`): deeper input is a named error,
never a ``RecursionError``.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from fsarm_sim.errors import FilePathError, FsarmError

# deepest nesting of arrays/tables/objects a parsed file may have (fsarm's own files nest at
# most 4 deep; the limit keeps every recursive walk of the parsed value far from Python's)
MAX_NESTING = 32

_PHRASES = {
    errno.ELOOP: "it is a loop of symbolic links",
    errno.ENAMETOOLONG: "the name is longer than the file system allows",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "the disk quota is exceeded",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EROFS: "the file system is read-only",
    errno.ENOENT: "no such file or folder",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EISDIR: "it is a folder, not a file",
    errno.EIO: "input/output error of the device",
    errno.EPIPE: "the pipe was closed by its reader",
    errno.EFBIG: "the file is larger than the file system allows",
}


def os_problem(exc: BaseException) -> str:
    """What an operating-system error means, in words (``ENOSPC``: "no space left on the
    device"); ``Path.resolve``'s ``RuntimeError`` for a loop counts as ``ELOOP``."""
    if isinstance(exc, RuntimeError) and "Symlink loop" in str(exc):
        return _PHRASES[errno.ELOOP]
    if isinstance(exc, OSError) and exc.errno in _PHRASES:
        return _PHRASES[exc.errno]
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


def working_dir(error: type[FsarmError] = FilePathError) -> Path:
    """The working directory, or ``error`` when it no longer exists."""
    try:
        return Path(os.getcwd())
    except OSError as exc:
        raise error(
            f"the working directory no longer exists ({os_problem(exc)}: it was deleted or "
            "moved); cd to an existing folder, or give absolute paths"
        ) from None


def checked_path(
    path: str | os.PathLike[str], what: str, error: type[FsarmError] = FilePathError
) -> Path:
    """``path`` made absolute and resolved (symbolic links followed); ``error`` (a one-line
    message starting with ``what`` and the path as given) for a loop of symbolic links, a name
    too long, no permission on the way, a NUL in the name or a vanished working directory. A
    path that does not exist (yet) is fine: whether it must exist is the caller's business."""
    text = os.fspath(path)
    if "\x00" in text:
        raise error(f"{what} {text!r} contains a NUL character; give a plain file name")
    p = Path(text)
    if not p.is_absolute():
        p = working_dir(error) / p
    try:
        real = Path(os.path.normpath(p)).resolve()
        os.stat(real)  # resolve() passes over what it cannot look at: look once more
    except (FileNotFoundError, NotADirectoryError):
        return Path(os.path.normpath(p)).resolve()
    except (OSError, RuntimeError) as exc:
        raise error(f"{what} {text}: {os_problem(exc)}; give another path") from None
    return real


@contextmanager
def named_os_errors(
    what: str, path: str | os.PathLike[str], error: type[FsarmError] = FilePathError
) -> Iterator[None]:
    """Turn an ``OSError`` (or a loop's ``RuntimeError``) raised in the block into ``error``:
    "``what`` ``path``: ``os_problem``"."""
    try:
        yield
    except FsarmError:
        raise
    except (OSError, RuntimeError) as exc:
        if isinstance(exc, RuntimeError) and "Symlink loop" not in str(exc):
            raise
        raise error(f"{what} {os.fspath(path)}: {os_problem(exc)}") from exc


def nesting_depth(value: Any) -> int:
    """Deepest nesting of lists/tuples/dicts in ``value`` (a scalar: 0), found without recursion."""
    deepest = 0
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        v, depth = stack.pop()
        if isinstance(v, dict):
            children: Any = v.values()
        elif isinstance(v, list | tuple):
            children = v
        else:
            continue
        depth += 1
        deepest = max(deepest, depth)
        if depth > MAX_NESTING:
            return depth
        stack.extend((c, depth) for c in children)
    return deepest


def _too_deep(source: str, error: type[FsarmError]) -> FsarmError:
    return error(
        f"{source}: arrays/tables nest deeper than {MAX_NESTING} levels; fsarm's files nest "
        "a few levels at most"
    )


def _check_nesting(value: Any, source: str, error: type[FsarmError]) -> Any:
    if nesting_depth(value) > MAX_NESTING:
        raise _too_deep(source, error)
    return value


def bounded_toml(text: str, source: str, error: type[FsarmError]) -> dict[str, Any]:
    """``tomllib.loads`` with the nesting depth bounded (:data:`MAX_NESTING`); a
    ``TOMLDecodeError`` is left to the caller."""
    import tomllib  # here, not at import: the command's start-up does not need it

    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise _too_deep(source, error) from None
    return dict(_check_nesting(data, source, error))


def bounded_json(text: str, source: str, error: type[FsarmError]) -> Any:
    """``json.loads`` with the nesting depth bounded (:data:`MAX_NESTING`); a
    ``JSONDecodeError`` is left to the caller."""
    import json

    try:
        data = json.loads(text)
    except RecursionError:
        raise _too_deep(source, error) from None
    return _check_nesting(data, source, error)


def read_json_file(path: Path, what: str, error: type[FsarmError], unreadable: str) -> Any:
    """The JSON in the file ``path`` (:func:`regular_file`, then :func:`bounded_json`); a file
    that cannot be read or decoded is ``error`` with the message ``unreadable`` (a format
    string of ``p``, the path, and ``exc``, what went wrong)."""
    import json

    regular_file(path, what, error)  # loops, long names ...
    try:
        return bounded_json(path.read_text("utf-8"), str(path), error)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise error(unreadable.format(p=path, exc=exc)) from exc


def regular_file(
    path: str | os.PathLike[str], what: str, error: type[FsarmError] = FilePathError
) -> Path:
    """:func:`checked_path` of a file to read, which must be a regular file: a folder, a
    device (``/dev/zero`` never ends) or a named pipe (blocks until someone writes) is
    ``error``, as is a missing file. Returns the resolved path."""
    real = checked_path(path, what, error)
    try:
        mode = os.stat(real).st_mode
    except OSError as exc:
        raise error(f"{what} {os.fspath(path)}: {os_problem(exc)}") from None
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file (a device or a pipe)"
        raise error(f"{what} {os.fspath(path)} is {kind}; give a file")
    return real
