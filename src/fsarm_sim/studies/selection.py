"""Deprecated: renamed :mod:`fsarm_sim.studies.shaft_selection` (shaft selection for a desired stiffness).

The old name collided with :mod:`fsarm_sim.discrepancy.selection` (forward selection of missing
effects). This alias re-exports the same objects and will be removed in the next release; import
from :mod:`fsarm_sim.studies.shaft_selection` instead. (No DeprecationWarning at import: the test suite
treats warnings as errors.)
"""

from __future__ import annotations

from fsarm_sim.studies.shaft_selection import (
    DEFAULT_RESOLUTION_MM,
    DEFAULT_TOLERANCE,
    KINDS,
    Candidate,
    Kind,
    Selection,
    SelectionRequest,
    ShaftSelectionError,
    Variant,
    algorithm1,
    available_diameters,
    candidates,
    diameter_for_torque,
    select_shaft,
    stiffness,
    validate_request,
)

__all__ = [
    "DEFAULT_RESOLUTION_MM",
    "DEFAULT_TOLERANCE",
    "KINDS",
    "Candidate",
    "Kind",
    "Selection",
    "SelectionRequest",
    "ShaftSelectionError",
    "Variant",
    "algorithm1",
    "available_diameters",
    "candidates",
    "diameter_for_torque",
    "select_shaft",
    "stiffness",
    "validate_request",
]
