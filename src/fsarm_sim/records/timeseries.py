"""Writing runs: the time series (CSV or Parquet) with a JSON sidecar, and the JSON summary.

The time series of an arm run is written in the measured-data format of
``../shared/specs/measured-data.md``, setup ``arm`` (documented in the README): SI columns, one row
per logged control tick, and a sidecar with what is needed to replay the run. The sidecar is a
:class:`fsarm_sim.records.sidecar.Sidecar` (``writer`` "fsarm run", every column with its unit).
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim._version import __version__
from fsarm_sim.engine import hysteresis_model
from fsarm_sim.engine.model import Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.records import sidecar as rec
from fsarm_sim.sim.simulation import RunResult

FORMATS = ("csv", "parquet")
PARQUET_SIDECAR_KEY = "fsarm.sidecar"  # schema metadata key of a run Parquet file: the sidecar JSON


def _clean(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_clean(v) for v in x]
    if isinstance(x, float | np.floating):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def run_record(result: RunResult) -> rec.Sidecar:
    """The typed sidecar of an arm run: setup, transmission, shaft, payload, gains, effects,
    columns with their units, version."""
    cfg = result.config
    sh = cfg.shaft
    tr = cfg.transmission_model()
    plant, ctrl = cfg.transmission_blocks()
    names = tr.param_names()
    return rec.Sidecar(
        schema=rec.SCHEMA,
        writer=rec.WRITER_RUN,
        setup="arm",
        scenario=result.scenario,
        duration_s=float(result.duration_s),
        interrupted=bool(result.interrupted),
        shaft=rec.ShaftRef(diameter_mm=sh.diameter_mm, length_mm=sh.length_mm),
        shaft_params=rec.shaft_params_entry(sh),
        transmission=rec.TransmissionRef(
            name=tr.name,
            source=tr.source,
            params=dict(zip(names, plant[: len(names)].tolist(), strict=True)),
            controller_params=dict(zip(names, ctrl[: len(names)].tolist(), strict=True)),
        ),
        payload_kg=float(cfg.payload_kg),
        ctrl_dt_s=float(cfg.gains.ctrl_dt_s),
        gains=rec.gains_entry(resolved_gains(cfg)),
        effects=rec.effects_entry(cfg.effects),
        timestep_s=cfg.timestep_s,
        integrator=cfg.integrator,
        fsarm_sim_version=__version__,
        columns={c: rec.UNITS.get(c, "") for c in result.columns},
    )


def run_metadata(result: RunResult) -> dict[str, Any]:
    """Sidecar of an arm run as JSON (:func:`run_record`'s ``to_json``)."""
    return run_record(result).to_json()


def write_timeseries(result: RunResult, out_dir: Path, fmt: str = "csv") -> Path:
    """Write ``<out_dir>/<scenario>.<fmt>`` and its ``.json`` sidecar; return the table's path."""
    if fmt not in FORMATS:
        raise InvalidParameterError(f"format must be one of {FORMATS}, got {fmt!r}")
    # pyarrow's C++ writers (imported here, when a table is written: about 10x pandas' CSV
    # writer, and the numbers are written exactly - shortest round-trip decimal)
    import pyarrow as pa

    out_dir.mkdir(parents=True, exist_ok=True)
    names, arrays = [], []
    for k, v in result.columns.items():
        x = np.ascontiguousarray(v, dtype=np.float64)
        # straight from the buffer: pa.array() would import pandas (0.4 s) to check its types
        arrays.append(pa.Array.from_buffers(pa.float64(), len(x), [None, pa.py_buffer(x)]))
        names.append(k)
    record = run_record(result)
    path = out_dir / f"{result.scenario}.{fmt}"
    if fmt == "parquet":
        # Parquet carries what the sidecar says: each column's unit as field metadata and the
        # whole sidecar as schema metadata, so the table alone is self-describing
        fields = [
            pa.field(k, pa.float64(), metadata={"unit": (record.columns or {}).get(k, "")})
            for k in names
        ]
        schema = pa.schema(fields, metadata={PARQUET_SIDECAR_KEY: json.dumps(record.to_json())})
        table = pa.Table.from_arrays(arrays, schema=schema)
    else:
        table = pa.Table.from_arrays(arrays, names=names)
    if fmt == "csv":
        import pyarrow.csv as pa_csv

        pa_csv.write_csv(
            table, path, pa_csv.WriteOptions(quoting_style="none", quoting_header="none")
        )
    else:
        import pyarrow.parquet as pq

        pq.write_table(table, path)
    rec.write_sidecar(path.with_suffix(".json"), record)
    return path


def summary(result: RunResult) -> dict[str, Any]:
    """The ``--json`` summary: metrics (``rmse_rad``, ``realtime_factor``, ...) and the setup."""
    return _clean({"scenario": result.scenario, **result.metrics, "setup": run_metadata(result)})


def write_summary(result: RunResult, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(summary(result), indent=2) + "\n", "utf-8")


def resolved_gains(cfg: SimConfig) -> Gains:
    """The run's gains as the controller used them: the hysteresis-comp controller's model
    written out (its identified default resolved for the controller's shaft), so the sidecar
    replays the run even if the default is re-identified later."""
    g = cfg.gains
    if g.controller != "hysteresis-comp" or g.hysteresis_model:
        return g
    shaft = cfg.controller_shaft or cfg.shaft
    return replace(g, hysteresis_model=hysteresis_model.resolve((), shaft))
