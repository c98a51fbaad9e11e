"""Side-by-side comparison of joint-3 transmissions on the same arm, scenario and controller.

For each transmission: the scenario's tracking (joint-3 RMSE and max error), the peak torque it
carries and its ratio to its rating, the positive work of joint 3's motor, the torque-loop
bandwidth at the scenario's bend (:func:`fsarm_sim.studies.arm_metrics.torque_bandwidth`) and the output
impedance at 1 Hz-ish with zero commanded torque (:func:`fsarm_sim.studies.transparency.output_impedance`).
A transmission that cannot run the scenario (e.g. a torque beyond a magnetic spring's stable
range) gets its error message in the row instead of numbers: it is a result, not a crash.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import FsarmError
from fsarm_sim.plant import transmissions
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import Backend, run_scenario
from fsarm_sim.studies.arm_metrics import torque_bandwidth
from fsarm_sim.studies.transparency import output_impedance


@dataclass
class Row:
    transmission: str
    metrics: dict[str, float] = field(default_factory=dict)
    error: str | None = None

    def as_dict(self) -> dict[str, Any]:
        return {"transmission": self.transmission, "error": self.error, **self.metrics}


COLUMNS = (
    ("q3_rmse_deg", "q3 RMSE [deg]", "{:.3f}"),
    ("q3_max_err_deg", "q3 max err [deg]", "{:.3f}"),
    ("peak_torque_nm", "peak torque [N·m]", "{:.2f}"),
    ("torque_over_rating", "peak/rating", "{:.2f}"),
    ("motor_energy_j", "motor work [J]", "{:.2f}"),
    ("bandwidth_hz", "torque BW [Hz]", "{:.2f}"),
    ("impedance_nm_per_rad", "|Z| out [N·m/rad]", "{:.2f}"),
)


def compare(
    names: list[str] | None = None,
    scenario: str = "fig14-sine",
    *,
    payload_kg: float | None = None,
    duration_s: float | None = None,
    base: SimConfig | None = None,
    backend: Backend = "native",
    analyses: bool = True,
) -> list[Row]:
    """One :class:`Row` per transmission (all registered ones by default)."""
    sc = scenarios.get(scenario)
    chosen = names or transmissions.names()
    for n in chosen:
        transmissions.get(n)  # unknown names fail before any work
    (base or SimConfig()).gains.validate()  # so do bad gains
    bend = float(sc.reference(np.zeros(1))[0, 1])  # joint 2's angle at the start: the bend
    rows = []
    for name in chosen:
        cfg = (base or SimConfig()).with_(transmission=name)
        row = Row(name)
        try:
            res = run_scenario(
                scenario, cfg, payload_kg=payload_kg, duration_s=duration_s, backend=backend
            )
            m = res.metrics
            rmse, mx = m["rmse_deg"], m["max_abs_err_deg"]
            assert isinstance(rmse, dict) and isinstance(mx, dict)
            row.metrics.update(
                q3_rmse_deg=rmse["q3"],
                q3_max_err_deg=mx["q3"],
                peak_torque_nm=float(m["peak_shaft_torque_nm"]),  # type: ignore[arg-type]
                torque_over_rating=float(m["peak_shaft_torque_over_rating"]),  # type: ignore[arg-type]
                motor_energy_j=float(m["motor_energy_j"]),  # type: ignore[arg-type]
            )
            if analyses:
                bw = torque_bandwidth(cfg, bend, backend=backend)
                z = output_impedance(cfg, bend, backend=backend)
                row.metrics.update(
                    bandwidth_hz=bw.bandwidth_hz, impedance_nm_per_rad=z.low_freq_nm_per_rad
                )
        except FsarmError as exc:
            row.error = str(exc)
        rows.append(row)
    return rows


def fmt(value: float | None, pattern: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return pattern.format(value)
