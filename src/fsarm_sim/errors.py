"""Named exceptions. Every message says what was wrong and what is allowed."""

from __future__ import annotations


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


class SimulationWarningError(FsarmError, RuntimeError):
    """MuJoCo raised a warning (bad state, instability, ...) during a run."""
