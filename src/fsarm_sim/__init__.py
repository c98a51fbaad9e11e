"""fsarm-sim: MuJoCo simulator of a 3-DOF arm whose elbow is driven through a flexible shaft.

The first script's names come from the package itself (:mod:`fsarm_sim.api`, imported on first
use so that ``import fsarm_sim`` stays cheap)::

    from fsarm_sim import SimConfig, load_catalogue, run_scenario, write_run
"""

from __future__ import annotations

from typing import Any

from fsarm_sim._version import __version__

_API = (
    "Effects",
    "FsarmError",
    "Gains",
    "RunRequest",
    "RunResult",
    "SimConfig",
    "column_units",
    "load_catalogue",
    "load_environment",
    "run_scenario",
    "scenario_names",
    "summary",
    "write_run",
)


def __getattr__(name: str) -> Any:
    if name in _API:
        from fsarm_sim import api

        return getattr(api, name)
    raise AttributeError(f"module 'fsarm_sim' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_API])


__all__ = ["__version__", *_API]
