"""A refit keeps the name of the fit it refines (any setup's fit: bench or arm)."""

from __future__ import annotations

from typing import Protocol, TypeVar


class _Labelled(Protocol):
    label: str
    effect: str | None
    variant: str | None
    note: str


_F = TypeVar("_F", bound=_Labelled)


def labelled_as(best: _F, fit: _F) -> _F:
    """``best`` (a refit of ``fit``, any setup's fit) under ``fit``'s label, effect, variant and
    note."""
    if best is not fit:
        best.label, best.effect, best.variant, best.note = (
            fit.label,
            fit.effect,
            fit.variant,
            fit.note,
        )
    return best
