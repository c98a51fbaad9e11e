"""Joint-3 transmissions: the registry (name -> kernel module and the id the kernels dispatch on).

Add a transmission: write its module against :mod:`fsarm_sim.transmissions.base`, give it the
next ``layout.TR_*`` id, list it here and add its branch to ``physics``' dispatch functions.
"""

from __future__ import annotations

import importlib

from fsarm_sim import layout as L
from fsarm_sim.transmissions.base import Transmission, TransmissionError

DEFAULT = "flexible-shaft"
# name -> (kernel id, module)
_TABLE: dict[str, tuple[float, str]] = {
    "flexible-shaft": (L.TR_FLEXIBLE_SHAFT, "flexible_shaft"),
    "rtca": (L.TR_RTCA, "rtca"),
    "qa-joint": (L.TR_QA_JOINT, "qa_joint"),
    "magnetic-spring": (L.TR_MAGNETIC_SPRING, "magnetic_spring"),
    "tendon-sheath": (L.TR_TENDON_SHEATH, "tendon_sheath"),
}


def names() -> list[str]:
    """Registered transmission names, the default first."""
    return list(_TABLE)


def get(name: str) -> Transmission:
    """The transmission of that name; TransmissionError lists the known names."""
    if name not in _TABLE:
        raise TransmissionError(f"unknown transmission {name!r}; known: {', '.join(names())}")
    kind, module = _TABLE[name]
    mod = importlib.import_module(f"fsarm_sim.transmissions.{module}")
    return Transmission(name=name, kind=int(kind), module=mod)


def by_kind(kind: float) -> Transmission:
    """The transmission with kernel id ``kind`` (layout.P_TRANS)."""
    for name, (k, _) in _TABLE.items():
        if k == kind:
            return get(name)
    raise TransmissionError(f"no transmission has kernel id {kind!r}")


__all__ = ["DEFAULT", "Transmission", "TransmissionError", "by_kind", "get", "names"]
