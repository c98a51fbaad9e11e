"""A user's trajectory file as a scenario (``fsarm select --trajectory-file``, issue 32).

Format: one table, ``NAME.csv`` (UTF-8, comma-separated, one header row) or ``NAME.parquet`` with
the same columns, one row per sample, SI units - the column names and units of the ``arm``
records (``specs/measured-data.md``, :mod:`fsarm_sim.records.measured`), so a record written by
``fsarm run`` is a trajectory file as it is:

==========================  ============================================================
``t``                       time from the start of the run, s; the first row at 0, then
                            strictly increasing (any spacing: positions are interpolated
                            linearly between rows)
``q1_ref q2_ref q3_ref``    joint position targets, rad (required)
``qd1_ref .. qd3_ref``      velocity targets, rad/s (optional: all three or none; absent,
                            they are the positions' finite differences)
``qdd1_ref .. qdd3_ref``    acceleration targets, rad/s^2 (optional, likewise, from the
                            velocities)
==========================  ============================================================

Other columns are ignored. The run lasts until the last row (``--duration`` may shorten it;
beyond the last row the last position is held at rest). Payload 0 kg unless the task gives one.
A file whose ``q2_ref`` is constant holds joint 2, so the task's bend angles apply to it.

The scenario's name is ``file:<absolute path>#sha256=<first 16 hex digits of the file>``: the
results store keys its points by that name, so a changed file is a new task, and a worker that
resolves the name reads the file again and refuses it if it changed since (it must see the same
path: on Dask, a shared file system). Importing this module lets
:func:`fsarm_sim.sim.scenarios.get` resolve such names.

Every problem is a named error (the classes of :mod:`fsarm_sim.records.measured`, plus
:class:`TrajectoryFileError`), one line, saying which file, column and row and what is allowed.
"""

from __future__ import annotations

import functools
import hashlib
import math
from pathlib import Path

import numpy as np
import numpy.typing as npt

from fsarm_sim.records.sidecar import MeasuredDataError
from fsarm_sim.sim import scenarios

Array = npt.NDArray[np.float64]
PREFIX = "file:"
HASH_TAG = "#sha256="
POSITIONS = ("q1_ref", "q2_ref", "q3_ref")
VELOCITIES = ("qd1_ref", "qd2_ref", "qd3_ref")
ACCELERATIONS = ("qdd1_ref", "qdd2_ref", "qdd3_ref")
MAX_ANGLE_RAD = 2.0 * math.pi  # beyond a full turn: the angles are most likely in degrees
MAX_DURATION_S = 3600.0  # the sweep's limit on duration_s
SUFFIXES = (".csv", ".parquet")


class TrajectoryFileError(MeasuredDataError):
    """A trajectory file that cannot be a task (wrong suffix, start time, units, changed file)."""


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def scenario_name(path: str | Path) -> str:
    """Check the file (named errors) and return the scenario name it runs under."""
    p = Path(path).expanduser().resolve()
    if p.suffix.lower() not in SUFFIXES:
        raise TrajectoryFileError(
            f"{path}: a trajectory file is a .csv or .parquet table (columns t, q1_ref, q2_ref, "
            f"q3_ref; see `fsarm select --help`), got suffix {p.suffix or '(none)'!r}"
        )
    table = read(p)  # validates before a name is handed out
    del table
    return f"{PREFIX}{p}{HASH_TAG}{_digest(p)}"


def read(path: Path) -> tuple[Array, Array]:
    """(t, table (n, 9): q[3], qd[3], qdd[3]) of a trajectory file, validated."""
    from fsarm_sim.records.measured import (
        MissingColumnError,
        NonFiniteError,
        TimeAxisError,
        TooFewSamplesError,
        read_table,
        to_float,
    )

    names, raw = read_table(path)
    missing = [c for c in ("t", *POSITIONS) if c not in raw]
    if missing:
        raise MissingColumnError(
            f"{path}: a trajectory file needs column(s) {', '.join(repr(c) for c in missing)} "
            "(t in s; q1_ref, q2_ref, q3_ref in rad; optional qd*_ref in rad/s and qdd*_ref in "
            f"rad/s^2); found {', '.join(repr(n) for n in names) or 'none'}"
        )
    for group in (VELOCITIES, ACCELERATIONS):
        given = [c for c in group if c in raw]
        if given and len(given) != 3:
            raise MissingColumnError(
                f"{path}: give all of {', '.join(group)} or none of them, got only "
                f"{', '.join(given)}"
            )
    used = ["t", *POSITIONS, *(c for c in VELOCITIES + ACCELERATIONS if c in raw)]
    cols = {c: to_float(raw[c], c, path) for c in used}
    n = cols["t"].size
    if n < 2:
        raise TooFewSamplesError(f"{path}: {n} row(s); a trajectory needs at least 2")
    for c in used:
        bad = np.flatnonzero(~np.isfinite(cols[c]))
        if bad.size:
            raise NonFiniteError(
                f"{path}: column '{c}', row {int(bad[0])} (0-based data row) is "
                f"{float(cols[c][bad[0]])!r} (NaN also stands for an empty cell); every value "
                "must be a finite number"
            )
    t = cols["t"]
    if abs(t[0]) > 1e-9:
        raise TimeAxisError(
            f"{path}: column 't' starts at {t[0]!r} s; the first row must be at t = 0 (time "
            "from the start of the run, s)"
        )
    nonpos = np.flatnonzero(np.diff(t) <= 0.0)
    if nonpos.size:
        i = int(nonpos[0]) + 1
        raise TimeAxisError(
            f"{path}: column 't' is not strictly increasing at row {i} "
            f"(t[{i - 1}] = {t[i - 1]!r}, t[{i}] = {t[i]!r}); rows must be in time order"
        )
    if t[-1] > MAX_DURATION_S:
        raise TimeAxisError(
            f"{path}: column 't' ends at {t[-1]:g} s; at most {MAX_DURATION_S:g} s is allowed "
            "(t is in seconds: if it is in milliseconds, divide it by 1000)"
        )
    for c in POSITIONS:
        big = np.flatnonzero(np.abs(cols[c]) > MAX_ANGLE_RAD)
        if big.size:
            raise TrajectoryFileError(
                f"{path}: column '{c}', row {int(big[0])} is {cols[c][big[0]]:g}, beyond "
                f"±2π rad; positions are in radians (degrees? multiply by π/180)"
            )
    q = np.stack([cols[c] for c in POSITIONS], axis=1)
    if all(c in cols for c in VELOCITIES):
        qd = np.stack([cols[c] for c in VELOCITIES], axis=1)
    else:
        qd = np.gradient(q, t, axis=0)
    if all(c in cols for c in ACCELERATIONS):
        qdd = np.stack([cols[c] for c in ACCELERATIONS], axis=1)
    else:
        qdd = np.gradient(qd, t, axis=0)
    return t, np.ascontiguousarray(np.concatenate([q, qd, qdd], axis=1))


def _split(name: str) -> tuple[Path, str]:
    body, tag, digest = name[len(PREFIX) :].rpartition(HASH_TAG)
    if not tag or not body:
        raise TrajectoryFileError(
            f"scenario {name!r}: a file scenario is named file:<path>{HASH_TAG}<digest> "
            "(use --trajectory-file PATH)"
        )
    return Path(body), digest


@functools.lru_cache(maxsize=16)
def resolve(name: str) -> scenarios.Scenario:
    """The scenario of a ``file:`` name (read once per process; refused if the file changed)."""
    path, digest = _split(name)
    try:
        now = _digest(path)
    except OSError as exc:
        raise TrajectoryFileError(
            f"trajectory file {path}: cannot read it ({exc.strerror or exc})"
        ) from None
    if now != digest:
        raise TrajectoryFileError(
            f"trajectory file {path} changed since this task was set up (sha256 {now}, "
            f"expected {digest}); start the task again to use the new file"
        )
    t, table = read(path)
    t.flags.writeable = False
    table.flags.writeable = False

    def reference(times: Array) -> Array:
        out = np.empty((times.size, 9))
        for k in range(9):
            out[:, k] = np.interp(times, t, table[:, k])
        out[times > t[-1], 3:] = 0.0  # beyond the last row: held at rest
        return out

    return scenarios.Scenario(
        name=name,
        description=f"trajectory file {path.name} ({t.size} rows, {t[-1]:g} s)",
        duration_s=float(t[-1]),
        payload_kg=0.0,
        reference=reference,
    )


scenarios.RESOLVERS[PREFIX] = resolve
