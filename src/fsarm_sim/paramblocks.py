"""Declared parameter blocks: how the kernels' parameter vector is laid out.

Every slot of ``model.numeric("fsarm_params")`` is *declared* - a name, a unit, a default and
where its value comes from - in a block owned by one part of the model (a law module declares its
own, e.g. :data:`fsarm_sim.plant.effects.bending.KERNEL_PARAMS`). :class:`Layout` gives the blocks
consecutive offsets in the order they are added, so no index is ever typed by hand; the offsets
come out as plain ints that :mod:`fsarm_sim.kernels.layout` keeps as module-level constants (Numba
freezes those into the compiled kernels). ``tests/test_layout.py`` checks that no two slots
overlap and that every slot is declared exactly once.

This module imports nothing from the package, so law modules can declare blocks without cycles.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Decl:
    """One kernel parameter: name, unit, default value and its source (or what it means)."""

    name: str
    unit: str
    default: float
    source: str


@dataclass(frozen=True)
class Slot:
    block: str
    decl: Decl
    index: int


class LayoutError(ValueError):
    """Two declarations collide (a name used twice in a block, a block added twice)."""


class Layout:
    """Allocates consecutive slots to declared blocks; records every slot for checks and docs."""

    def __init__(self) -> None:
        self.slots: list[Slot] = []
        self._blocks: dict[str, tuple[int, int]] = {}

    @property
    def size(self) -> int:
        return len(self.slots)

    def block(self, name: str, decls: tuple[Decl, ...]) -> dict[str, int]:
        """Add block ``name``; returns each declared name's index."""
        if name in self._blocks:
            raise LayoutError(f"parameter block {name!r} is declared twice")
        names = [d.name for d in decls]
        if len(set(names)) != len(names):
            raise LayoutError(f"parameter block {name!r} declares a name twice: {names}")
        start = self.size
        for i, d in enumerate(decls):
            self.slots.append(Slot(name, d, start + i))
        self._blocks[name] = (start, start + len(decls))
        return {d.name: start + i for i, d in enumerate(decls)}

    def array(self, name: str, n: int, unit: str, source: str) -> int:
        """Add block ``name`` of ``n`` anonymous consecutive slots (e.g. a transmission's block,
        whose meaning depends on which transmission fills it); returns its first index."""
        decls = tuple(Decl(f"{name}[{i}]", unit, 0.0, source) for i in range(n))
        return self.block(name, decls)[f"{name}[0]"]

    def one(self, block: str, name: str, unit: str, source: str, default: float = 0.0) -> int:
        """A block of one slot."""
        return self.block(block, (Decl(name, unit, default, source),))[name]

    def bounds(self, name: str) -> tuple[int, int]:
        """[start, end) of block ``name``."""
        return self._blocks[name]

    def blocks(self) -> dict[str, tuple[int, int]]:
        return dict(self._blocks)
