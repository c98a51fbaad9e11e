"""Named exceptions. Every message says what was wrong and what is allowed."""

from __future__ import annotations

import numbers
from typing import Any


class FsarmError(Exception):
    """Base class of every error fsarm-sim raises on purpose."""


class ShaftRangeError(FsarmError, ValueError):
    """Shaft diameter, length or bend angle outside the catalogue's validity range."""


class CoefficientFileError(FsarmError, ValueError):
    """A shaft coefficient file is missing, unreadable or malformed."""


class ScenarioNotFoundError(FsarmError, KeyError):
    """No scenario of that name is registered."""

    def __str__(self) -> str:  # KeyError quotes its argument; we want the plain message
        return str(self.args[0]) if self.args else ""


class InvalidParameterError(FsarmError, ValueError):
    """A run parameter (duration, payload, gains, rates, ...) is NaN, infinite or out of range."""


class ModelStructureError(FsarmError, ValueError):
    """The MJCF lacks a joint, tendon or actuator fsarm-sim needs, or they disagree."""


class RunFailedError(FsarmError, RuntimeError):
    """A run went wrong while stepping. ``columns`` holds what was recorded up to the failure
    (empty when nothing was recorded or the failure came from outside a run)."""

    def __init__(self, message: str, columns: dict[str, Any] | None = None) -> None:
        super().__init__(message)
        self.columns: dict[str, Any] = columns or {}


class SimulationWarningError(RunFailedError):
    """MuJoCo raised a warning (bad state, instability, ...) during a run."""


class RunHealthError(RunFailedError):
    """A run's health check failed: its control clock stopped, its state is not finite, or a
    joint diverged from its reference. The message gives the time, the joint and the state."""


class CallbackBypassError(FsarmError, RuntimeError):
    """An fsarm model was stepped without fsarm's callbacks (plain ``mujoco.mj_step`` outside
    ``fsarm_sim.engine.callbacks.active()``): its shaft and controllers did not act over those steps."""


class CallbackConflictError(FsarmError, RuntimeError):
    """fsarm's process-global callbacks are held by another thread with the other backend."""


class FilePathError(FsarmError, ValueError):
    """A path cannot be used: a loop of symbolic links, a name too long for the file system, no
    permission on the way, a NUL in the name, or a working directory that no longer exists
    (:func:`fsarm_sim.paths.checked_path`)."""


class OutputPathError(FilePathError):
    """An output path cannot be used: a folder where a file is meant (or the reverse), a place
    that cannot be written, two outputs on one file, or an output on one of the inputs."""


class OutputWriteError(FsarmError, RuntimeError):
    """Writing a result failed after the work was done; the results went to a fallback place,
    which the message names."""


def real_number(value: object, what: str, error: type[FsarmError] = InvalidParameterError) -> float:
    """``value`` as a float when it is a real number (int, float, NumPy's); ``error`` for a
    boolean (``True`` is not 1 s), a string or anything else."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error(f"{what} must be a number, got {value!r}")
    return float(value)


def whole_number(
    value: object,
    what: str,
    low: int,
    high: int,
    error: type[FsarmError] = InvalidParameterError,
) -> int:
    """``value`` as an int within ``[low, high]`` (the stated cap of a size that scales work or
    memory); ``error`` for a boolean, a fraction, a string, or a value outside."""
    if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Integral)
        or not (low <= int(value) <= high)
    ):
        raise error(f"{what} must be a whole number >= {low} and <= {high}, got {value!r}")
    return int(value)
