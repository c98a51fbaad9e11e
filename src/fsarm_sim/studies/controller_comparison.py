"""Joint-3 controllers side by side (``fsarm compare-controllers``): what an actuator engineer
compares on one joint model.

For each controller (``Gains.controller``) and shaft, the same measurements:

* tracking: joint 3's RMSE on ``fig14-sine`` (0 kg, 15 kg, and 0 kg with joint 2 held at 90 deg,
  the widest hysteresis), ``p2p-payload`` and ``step-q3``, from the control kernel's per-step
  accumulators (:func:`fsarm_sim.sim.simulation.run_scenario`,
  :func:`fsarm_sim.studies.arm_metrics.tracking`);
* the torque estimate's error (virtual sensor against the true shaft torque) on ``fig14-sine``;
* joint 3's positive motor work on ``fig14-sine`` (J);
* torque-loop bandwidth and low-frequency output impedance at each bend
  (:func:`fsarm_sim.studies.arm_metrics.torque_bandwidth`,
  :func:`fsarm_sim.studies.transparency.output_impedance`).

The hysteresis-comp controller uses, per shaft, the model given in ``models`` (e.g. identified
from that shaft's bench records, :func:`fsarm_sim.studies.hysteresis_id.identify_shaft`) or the
identified default scaled to the shaft.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace

from fsarm_sim.engine.model import CONTROLLERS, Gains, SimConfig
from fsarm_sim.errors import InvalidParameterError, RunFailedError
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.sim.simulation import Backend, run_scenario
from fsarm_sim.studies.arm_metrics import torque_bandwidth, tracking
from fsarm_sim.studies.transparency import output_impedance

DEFAULT_CONTROLLERS = ("default", "hysteresis-comp", "dob", "paper-pid")
DEFAULT_BENDS_DEG = (0.0, 45.0, 90.0)
# (label, scenario, payload kg or None for the scenario's own, joint-2 hold in deg or None for
# the scenario's own)
TRACKING_CASES: tuple[tuple[str, str, float | None, float | None], ...] = (
    ("fig14", "fig14-sine", 0.0, None),
    ("fig14-15kg", "fig14-sine", 15.0, None),
    ("fig14-bent90", "fig14-sine", 0.0, 90.0),
    ("p2p", "p2p-payload", None, None),
    ("step-q3", "step-q3", None, None),
)


@dataclass
class ControllerRow:
    """One controller on one shaft (angles in deg, torques N*m, work J, Hz, N*m/rad)."""

    controller: str
    shaft: str
    q3_rmse_deg: dict[str, float] = field(default_factory=dict)  # TRACKING_CASES label -> RMSE
    q3_max_deg: dict[str, float] = field(default_factory=dict)
    tau_estimate_rmse_nm: float = math.nan  # fig14-sine, 0 kg
    tau_estimate_rmse_15kg_nm: float = math.nan
    motor_work_j: float = math.nan  # fig14-sine, 0 kg
    bandwidth_hz: dict[str, float] = field(default_factory=dict)  # bend (deg, as text) -> Hz
    impedance_nm_per_rad: dict[str, float] = field(default_factory=dict)
    failures: list[str] = field(default_factory=list)  # runs that ended with a named error

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


def shaft_label(shaft: ShaftParams) -> str:
    return f"{shaft.diameter_mm:g}x{shaft.length_mm:g}"


def _gains(base: Gains, controller: str, model: tuple[float, ...]) -> Gains:
    return replace(
        base,
        controller=controller,
        hysteresis_model=model if controller == "hysteresis-comp" else (),
    )


def _run_tracking_cases(
    row: ControllerRow,
    cfg: SimConfig,
    duration_s: float | None,
    backend: Backend,
    progress: Callable[[str], None] | None,
) -> None:
    """The tracking cases of one controller on one shaft into ``row`` (a failed run into its
    ``failures``)."""
    label, c = row.shaft, row.controller
    for case, scenario, payload, hold in TRACKING_CASES:
        if progress:
            progress(f"{label} {c}: {case}")
        try:
            if hold is None:
                m = run_scenario(
                    scenario,
                    cfg,
                    duration_s=duration_s,
                    payload_kg=payload,
                    backend=backend,
                ).metrics
                rmse, mx = m["rmse_deg"], m["max_abs_err_deg"]
                assert isinstance(rmse, dict) and isinstance(mx, dict)
                q3, q3_max = float(rmse["q3"]), float(mx["q3"])
            else:
                flat = tracking(
                    cfg,
                    scenario,
                    duration_s=duration_s,
                    payload_kg=payload,
                    bend_rad=math.radians(hold),
                    backend=backend,
                )
                q3, q3_max = flat["q3_rmse_deg"], flat["q3_max_abs_err_deg"]
        except RunFailedError as exc:
            row.failures.append(f"{case}: {exc}")
            continue
        row.q3_rmse_deg[case] = q3
        row.q3_max_deg[case] = q3_max
        if case == "fig14":
            row.tau_estimate_rmse_nm = float(m["tau_estimate_rmse_nm"])  # type: ignore[arg-type]
            row.motor_work_j = float(m["motor_energy_j"])  # type: ignore[arg-type]
        if case == "fig14-15kg":
            row.tau_estimate_rmse_15kg_nm = float(m["tau_estimate_rmse_nm"])  # type: ignore[arg-type]


def _run_frequency_cases(
    row: ControllerRow,
    cfg: SimConfig,
    bends_deg: Sequence[float],
    backend: Backend,
    progress: Callable[[str], None] | None,
) -> None:
    """The torque bandwidth and output impedance at each bend into ``row``."""
    label, c = row.shaft, row.controller
    for b in bends_deg:
        if progress:
            progress(f"{label} {c}: bandwidth and impedance at {b:g} deg")
        key = f"{b:g}"
        try:
            bw = torque_bandwidth(cfg, math.radians(b), backend=backend)
            z = output_impedance(cfg, math.radians(b), backend=backend)
        except RunFailedError as exc:
            row.failures.append(f"bend {key}: {exc}")
            continue
        row.bandwidth_hz[key] = float(bw.bandwidth_hz)
        row.impedance_nm_per_rad[key] = float(z.low_freq_nm_per_rad)


def compare(
    shafts: Sequence[ShaftParams],
    controllers: Sequence[str] = DEFAULT_CONTROLLERS,
    *,
    bends_deg: Sequence[float] = DEFAULT_BENDS_DEG,
    duration_s: float | None = None,
    models: Mapping[str, tuple[float, ...]] | None = None,
    gains: Gains | None = None,
    frequency: bool = True,
    backend: Backend = "native",
    progress: Callable[[str], None] | None = None,
) -> list[ControllerRow]:
    """Every controller on every shaft (module docstring). ``duration_s``: of each tracking
    run (None: the scenario's own); ``models``: hysteresis models by :func:`shaft_label`;
    ``frequency``: also the bandwidth and impedance at ``bends_deg``. A run that ends with a
    named error (e.g. the health check's instability) is recorded in ``failures``."""
    bad = [c for c in controllers if c not in CONTROLLERS]
    if bad or not controllers:
        raise InvalidParameterError(
            f"unknown controller(s) {', '.join(map(repr, bad)) or '(none given)'}; known: "
            f"{', '.join(CONTROLLERS)}"
        )
    for b in bends_deg:
        if not math.isfinite(b) or abs(b) > 120.0:
            raise InvalidParameterError(f"bend angles must be within +-120 deg, got {b!r}")
    base = gains or Gains()
    rows = []
    for shaft in shafts:
        label = shaft_label(shaft)
        model = (models or {}).get(label, ())
        for c in controllers:
            row = ControllerRow(controller=c, shaft=label)
            cfg = SimConfig(shaft=shaft, gains=_gains(base, c, model))
            cfg.validate()
            _run_tracking_cases(row, cfg, duration_s, backend, progress)
            if frequency:
                _run_frequency_cases(row, cfg, bends_deg, backend, progress)
            rows.append(row)
    return rows
