"""What a first script needs, importable from the package itself::

    from fsarm_sim import SimConfig, load_catalogue, run_scenario, write_run

    shaft = load_catalogue().shaft(diameter_mm=9.0, length_mm=450.0)
    result = run_scenario("fig14-sine", SimConfig(shaft=shaft), payload_kg=15.0)
    print(result.metrics["rmse_deg"], column_units(result)["tau_shaft"])
    write_run(result, "runs", "parquet")  # runs/fig14-sine.parquet + its sidecar

A run with every option of ``fsarm run`` (checked against each other, outputs planned) is a
:class:`RunRequest`: ``RunRequest("step-q3", payload_kg=5.0).execute()``.

``fsarm_sim/__init__`` imports these lazily (on first use), so ``import fsarm_sim`` and the
``fsarm`` command stay fast.
"""

from __future__ import annotations

from pathlib import Path

from fsarm_sim.engine.model import Effects, Gains, SimConfig
from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.records.sidecar import UNITS
from fsarm_sim.records.timeseries import summary, write_summary, write_timeseries
from fsarm_sim.run_request import RunRequest
from fsarm_sim.sim.scenarios import REGISTRY
from fsarm_sim.sim.simulation import RunResult, run_scenario
from fsarm_sim.studies.dmc_env import load as load_environment


def scenario_names() -> tuple[str, ...]:
    """The registered scenarios (``fsarm scenarios`` lists them with their descriptions)."""
    return tuple(REGISTRY)


def column_units(result: RunResult) -> dict[str, str]:
    """SI unit of each of ``result.columns`` (the sidecar's ``columns``)."""
    return {name: UNITS.get(name, "") for name in result.columns}


def write_run(
    result: RunResult, out_dir: str | Path, fmt: str = "csv", *, summary_json: bool = True
) -> Path:
    """Write a run as ``fsarm run --out`` does: ``<out_dir>/<scenario>.<fmt>`` (``csv`` or
    ``parquet``; Parquet carries the units and the sidecar in its schema) with its ``.json``
    sidecar, and with ``summary_json`` the metrics as ``<scenario>.summary.json``. Returns the
    table's path."""
    out = Path(out_dir)
    path = write_timeseries(result, out, fmt)
    if summary_json:
        write_summary(result, out / f"{result.scenario}.summary.json")
    return path


__all__ = [
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
]
