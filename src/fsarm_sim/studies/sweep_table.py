"""A sweep's results as a tidy table: one row per finished point, one column per input and
output, each column with its unit and description in the Parquet schema.

The results store (SQLite, :mod:`fsarm_sim.records.store`) keeps each point's inputs and outputs
as JSON text, which is what makes it resumable and safe under parallel writers; readers want a
flat table. :func:`write_tidy` writes ``<store>.parquet`` beside the store (``fsarm sweep`` does
after every run), readable as it is by pandas, Polars, DuckDB or Arrow with its units.

Units follow the field names' suffixes (``_mm``, ``_deg``, ``_nm``, ``_hz``, ...); the handful
of fields without one are named in :data:`UNITS_BY_NAME`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fsarm_sim.records.store import ResultStore

# suffix -> unit, longest first (``_rad_s`` before ``_s``)
UNIT_SUFFIXES: tuple[tuple[str, str], ...] = (
    ("_rad_s", "rad/s"),
    ("_mm", "mm"),
    ("_deg", "deg"),
    ("_kg", "kg"),
    ("_nm", "N*m"),
    ("_hz", "Hz"),
    ("_rad", "rad"),
    ("_j", "J"),
    ("_s", "s"),
)
UNITS_BY_NAME: dict[str, str] = {
    "k_sp": "N*m/rad",
    "k_sn": "N*m/rad",
    "kb": "N*m/rad",
    "kb_cubic": "1/rad^2",  # eq. 2's beta
    "k_sp_catalogue": "N*m/rad",
    "k_sn_catalogue": "N*m/rad",
    "kb_catalogue": "N*m/rad",
    "kb_rmse": "N*m",
    "series_rmse_p": "N*m",
    "series_rmse_n": "N*m",
}
DESCRIPTIONS: dict[str, str] = {
    "diameter_mm": "shaft diameter D",
    "length_mm": "shaft length L",
    "bend_deg": "bend angle φ_B",
    "payload_kg": "payload",
    "duration_s": "scenario duration",
    "q1_rmse_deg": "joint-1 tracking RMSE",
    "q2_rmse_deg": "joint-2 tracking RMSE",
    "q3_rmse_deg": "joint-3 tracking RMSE",
    "q3_max_abs_err_deg": "joint-3 largest tracking error",
    "tau_estimate_rmse_nm": "joint-3 torque-estimate error, RMS",
    "torque_bandwidth_hz": "torque bandwidth",
    "static_relief_nm": "static joint-2 relief from the bent shaft",
    "peak_motor_torque_nm": "peak joint-3 motor torque",
    "peak_motor_speed_rad_s": "peak joint-3 motor speed",
    "peak_shaft_torque_nm": "peak shaft torque",
    "motor_energy_j": "joint-3 motor work",
    "k_sp": "series stiffness, winding side (bench)",
    "k_sn": "series stiffness, unwinding side (bench)",
    "kb": "bending stiffness K_b (bench)",
    "rating_nm": "shaft torque rating",
    "wall_s": "wall time of the point",
}


def unit(name: str) -> str:
    """The SI(-style) unit of a sweep field ("" for a count, a flag or text)."""
    if name in UNITS_BY_NAME:
        return UNITS_BY_NAME[name]
    for suffix, u in UNIT_SUFFIXES:
        if name.endswith(suffix):
            return u
    return ""


def label(name: str) -> str:
    """Axis label of a sweep field: its description (or name) and unit, e.g. ``shaft diameter D
    [mm]``."""
    u = unit(name)
    text = DESCRIPTIONS.get(name, name)
    return f"{text} [{u}]" if u else text


def tidy_frame(store_path: str | Path, sweep: str | None = None) -> Any:
    """The finished points of ``store_path`` (one sweep, or all) as a pandas DataFrame: one row
    per point, one column per input and output (``ResultStore.frame``)."""
    with ResultStore(store_path) as store:
        return store.frame(sweep)


def write_tidy(
    store_path: str | Path, out: str | Path | None = None, sweep: str | None = None
) -> Path:
    """Write the tidy table of a store as Parquet (default ``<store>.parquet``): each column's
    unit and description as field metadata, the store and sweep as schema metadata."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    store = Path(store_path)
    path = Path(out) if out is not None else store.with_suffix(".parquet")
    table = pa.Table.from_pandas(tidy_frame(store, sweep), preserve_index=False)
    fields = [
        f.with_metadata({"unit": unit(f.name), "description": DESCRIPTIONS.get(f.name, f.name)})
        for f in table.schema
    ]
    meta = {"fsarm.sweep": json.dumps({"store": store.name, "sweep": sweep})}
    table = pa.Table.from_arrays(table.columns, schema=pa.schema(fields, metadata=meta))
    pq.write_table(table, path)
    return path
