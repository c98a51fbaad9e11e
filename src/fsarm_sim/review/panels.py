"""Time-series panels of a recording (which columns, labels and colours) and their generic logging
over plain column dicts.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.review.figures import moving_joints
from fsarm_sim.review.loop_panels import (
    bending_shown,
)

if TYPE_CHECKING:
    import rerun as rr

    from fsarm_sim.sim.simulation import RunResult

Array = npt.NDArray[np.float64]
Columns = Mapping[str, Array]

APPLICATION_ID = "fsarm_sim"
TIMELINE = "sim_time"
DEFAULT_RATE_HZ = 100.0  # logged rows per simulated second: smooth playback, small files
RAD2DEG = 180.0 / math.pi
SHAFT_POINTS = 24  # points of the drawn shaft curve (visual only)
SHAFT_RADIUS_M = 0.006  # drawn radius of the shaft line (visual only, not the shaft's D)
CAMERA_EYE_M = (1.05, -1.35, 0.95)  # default 3-D viewpoint (visual only)
CAMERA_TARGET_M = (0.25, 0.0, 0.45)

# colors (visual only)
BLUE = (31, 119, 180)
ORANGE = (255, 127, 14)
GREEN = (44, 160, 44)
RED = (214, 39, 40)
PURPLE = (148, 103, 189)
GREY = (127, 127, 127)
SHAFT_BLUE = (26, 153, 230)


# --------------------------------------------------------------------------- panels and loops


@dataclass(frozen=True)
class Series:
    """One scalar series: ``column`` of the column dict, times ``scale``, shown as ``label``."""

    column: str
    label: str
    scale: float = 1.0
    color: tuple[int, int, int] = BLUE
    width: float = 1.5  # line width, UI points


@dataclass(frozen=True)
class Panel:
    """A time-series plot: its series are logged under ``signals/<name>/<column>``.
    ``informative``: does a run's column dict carry information for it? (None: whenever one of
    its series varies.)"""

    name: str
    title: str
    series: tuple[Series, ...]
    informative: Callable[[Columns], bool] | None = None
    group: str = "signals"  # the blueprint's tab (consecutive panels of a group share one)

    @property
    def entity(self) -> str:
        return f"signals/{self.name}"


def _deg(column: str, label: str, color: tuple[int, int, int]) -> Series:
    return Series(column, label, RAD2DEG, color)


def _joint(j: int) -> Panel:
    """Joint ``j``'s angle and its reference, shown when the joint moves."""
    return Panel(
        f"joint{j}",
        f"joint {j} [deg]",
        (_deg(f"q{j}_ref", f"q{j} ref", GREY), _deg(f"q{j}", f"q{j}", BLUE)),
        informative=lambda c: j in moving_joints(c),
        group="tracking",
    )


ARM_PANELS: tuple[Panel, ...] = (
    _joint(1),
    _joint(2),
    _joint(3),
    Panel(
        "errors",
        "tracking error q - q_ref [deg]",
        (_deg("e1", "e1", BLUE), _deg("e2", "e2", ORANGE), _deg("e3", "e3", GREEN)),
        group="tracking",
    ),
    Panel(
        "shaft_angles",
        "shaft input θ_m / output θ_s [rad]",
        (Series("theta_m", "θ_m", 1.0, BLUE), Series("theta_s", "θ_s", 1.0, ORANGE)),
        group="shaft",
    ),
    Panel(
        "twist_bend",
        "twist Δθ and bend φ_B [deg]",
        (_deg("twist", "twist Δθ", BLUE), _deg("phi_b", "bend φ_B", ORANGE)),
        group="shaft",
    ),
    Panel(
        "shaft_torque",
        "shaft torque [N·m]",
        (
            Series("tau_shaft", "true τ", 1.0, BLUE),
            Series("tau_model", "modeled τ_m", 1.0, ORANGE),
            Series("tau_d_shaft", "desired τ_d", 1.0, GREY),
        ),
        group="shaft",
    ),
    Panel(
        "bending",
        "bending torque on joint 2 [N·m]",
        (
            Series("tau_bend", "total", 1.0, BLUE),
            Series("tau_conduit", "conduit part", 1.0, ORANGE),
        ),
        informative=bending_shown,
        group="shaft",
    ),
    Panel(
        "pid",
        "torque PID terms [rad/s]",
        (
            Series("pid_p", "P", 1.0, BLUE),
            Series("pid_i", "I", 1.0, ORANGE),
            Series("pid_d", "D", 1.0, GREEN),
        ),
        group="control",
    ),
    Panel(
        "speed",
        "shaft-input speed [rad/s]",
        (Series("omega_d", "ω_d", 1.0, GREY), Series("omega_m", "ω_m", 1.0, BLUE)),
        group="control",
    ),
    Panel(
        "motor_torque",
        "joint-3 motor torque [N·m]",
        (
            Series("tau_motor", "τ_motor", 1.0, BLUE),
            Series("tau_motor_limit_pos", "+limit", 1.0, RED),
            Series("tau_motor_limit_neg", "-limit", 1.0, RED),
        ),
        group="control",
    ),
    Panel(
        "joint_torques",
        "joint 1 / 2 torque commands [N·m]",
        (Series("tau1", "τ1", 1.0, BLUE), Series("tau2", "τ2", 1.0, ORANGE)),
        group="control",
    ),
)


def state_panels(result: RunResult) -> tuple[Panel, ...]:
    """Panels of a run's internal states (``RunResult.states``, logged as ``state_<name>``):
    the transmission's own (the shaft's slip elements, QA-Joint's sigma and friction, the
    tendon-sheath's capstan friction...) and the conduit branches (shown when the bend moves)."""
    colors = (BLUE, ORANGE, GREEN, GREY)
    own = [n for n in result.states if not n.startswith("conduit_branch")]
    branches = [n for n in result.states if n.startswith("conduit_branch")]
    out = []
    if own:
        out.append(
            Panel(
                "transmission_states",
                f"{result.config.transmission} states (data.act)",
                tuple(Series(f"state_{n}", n, 1.0, colors[i % 4]) for i, n in enumerate(own)),
                group="states",
            )
        )
    if branches:
        out.append(
            Panel(
                "conduit_states",
                "conduit branch states (bending hysteresis, data.act)",
                tuple(Series(f"state_{n}", n, 1.0, colors[i % 4]) for i, n in enumerate(branches)),
                informative=bending_shown,
                group="states",
            )
        )
    return tuple(out)


def with_derived(cols: Columns, tau_motor_limit_nm: float | None = None) -> dict[str, Array]:
    """The columns plus derived ones where their inputs exist: tracking errors ``e1..e3``
    (rad), bending moment ``moment_bend = -tau_bend`` (the moment that resists the bend, Fig. 9's
    sign) and the motor-torque limit lines ``tau_motor_limit_pos/neg``."""
    out = {k: np.asarray(v, dtype=np.float64) for k, v in cols.items()}
    for j in (1, 2, 3):
        if f"q{j}" in out and f"q{j}_ref" in out:
            out[f"e{j}"] = out[f"q{j}"] - out[f"q{j}_ref"]
    if "tau_bend" in out:
        out["moment_bend"] = -out["tau_bend"]
    if tau_motor_limit_nm is not None and "t" in out:
        out["tau_motor_limit_pos"] = np.full_like(out["t"], tau_motor_limit_nm)
        out["tau_motor_limit_neg"] = np.full_like(out["t"], -tau_motor_limit_nm)
    return out


# --------------------------------------------------------------------------- generic logging


def decimate(t: Array, rate_hz: float | None) -> npt.NDArray[np.intp]:
    """Row indices that log at about ``rate_hz`` rows per simulated second (None: every row).
    The last row is always kept so the recording spans the whole run."""
    n = len(t)
    if rate_hz is None or n < 2:
        return np.arange(n)
    if not math.isfinite(rate_hz) or rate_hz <= 0.0:
        raise InvalidParameterError(
            f"recording rate must be a finite number of Hz > 0, got {rate_hz!r}"
        )
    dt = float(np.median(np.diff(t)))
    stride = max(1, round(1.0 / (rate_hz * dt))) if dt > 0.0 else 1
    rows = np.arange(0, n, stride)
    if rows[-1] != n - 1:
        rows = np.append(rows, n - 1)
    return rows


def sim_time_column(t: Array) -> rr.TimeColumn:
    import rerun as rr

    return rr.TimeColumn(TIMELINE, duration=np.asarray(t, dtype=np.float64))


def log_scalar_panels(
    rec: rr.RecordingStream,
    cols: Columns,
    panels: Sequence[Panel],
    rows: npt.NDArray[np.intp],
    time_column: str = "t",
) -> list[str]:
    """Log each panel's series (columns that exist) as Scalars; return the entity paths."""
    import rerun as rr

    t = np.asarray(cols[time_column])[rows]
    logged: list[str] = []
    for panel in panels:
        for s in panel.series:
            if s.column not in cols:
                continue
            path = f"{panel.entity}/{s.column}"
            rec.log(
                path,
                rr.SeriesLines(colors=[s.color], names=[s.label], widths=[s.width]),
                static=True,
            )
            values = np.asarray(cols[s.column], dtype=np.float64)[rows] * s.scale
            rec.send_columns(
                path, indexes=[sim_time_column(t)], columns=rr.Scalars.columns(scalars=values)
            )
            logged.append(path)
    return logged
