"""Joint-3 transmissions: the registry (name -> kernel module and the id the kernels dispatch on).

Add a transmission: write its module against :class:`~fsarm_sim.plant.transmissions.base.
TransmissionModule` (mypy checks it through :data:`MODULES`), add it to :data:`MODULES` (its
place there is its integer kernel id, ``layout.TR_*``) and :data:`_TABLE`. The kernels' dispatch
is generated from :data:`MODULES` (:mod:`fsarm_sim.kernels.dispatch`; tests/test_layout.py checks
that every id reaches its module).
"""

from __future__ import annotations

from fsarm_sim.plant.transmissions import (
    flexible_shaft,
    magnetic_spring,
    qa_joint,
    rtca,
    tendon_sheath,
)
from fsarm_sim.plant.transmissions.base import Transmission, TransmissionError, TransmissionModule

# every registered module, typed as the interface (mypy checks each one against it); the order
# is the kernels' integer id of each (layout.TR_* reads it from here)
MODULES: dict[str, TransmissionModule] = {
    "flexible_shaft": flexible_shaft,
    "rtca": rtca,
    "qa_joint": qa_joint,
    "magnetic_spring": magnetic_spring,
    "tendon_sheath": tendon_sheath,
}

DEFAULT = "flexible-shaft"
KIND: dict[str, int] = {module: i for i, module in enumerate(MODULES)}  # module -> kernel id
# name -> (kernel id, module)
_TABLE: dict[str, tuple[int, str]] = {
    name: (KIND[module], module)
    for name, module in (
        ("flexible-shaft", "flexible_shaft"),
        ("rtca", "rtca"),
        ("qa-joint", "qa_joint"),
        ("magnetic-spring", "magnetic_spring"),
        ("tendon-sheath", "tendon_sheath"),
    )
}


def names() -> list[str]:
    """Registered transmission names, the default first."""
    return list(_TABLE)


def get(name: str) -> Transmission:
    """The transmission of that name; TransmissionError lists the known names."""
    if name not in _TABLE:
        raise TransmissionError(f"unknown transmission {name!r}; known: {', '.join(names())}")
    kind, module = _TABLE[name]
    return Transmission(name=name, kind=int(kind), module=MODULES[module])


def by_kind(kind: float) -> Transmission:
    """The transmission with kernel id ``kind`` (layout.P_TRANS)."""
    for name, (k, _) in _TABLE.items():
        if k == kind:
            return get(name)
    raise TransmissionError(f"no transmission has kernel id {kind!r}")


__all__ = ["DEFAULT", "Transmission", "TransmissionError", "by_kind", "get", "names"]
