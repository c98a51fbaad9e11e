"""Bisection on a bracket: the one root finder the laws and the studies share where the answer
must not depend on a library's stopping rule (a fixed number of halvings)."""

from __future__ import annotations

from collections.abc import Callable


def bisect(below: Callable[[float], bool], lo: float, hi: float, halvings: int = 200) -> float:
    """The point where ``below`` turns from True (at ``lo``'s side) to False (at ``hi``'s), after
    ``halvings`` halvings of ``[lo, hi]``: the middle of the last bracket."""
    for _ in range(halvings):
        mid = 0.5 * (lo + hi)
        if below(mid):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
