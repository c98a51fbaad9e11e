"""A run's metrics from its recorded columns and the kernels' accumulators: tracking errors, motor
energy.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from fsarm_sim.engine.model import (
    ArmStructure,
)
from fsarm_sim.errors import (
    InvalidParameterError,
)
from fsarm_sim.kernels import layout

Array = npt.NDArray[np.float64]


def motor_energy_j(cols: dict[str, Array], st: ArmStructure | None) -> float:
    """Positive mechanical work of joint 3's motor, J (trapezoid of max(tau * omega_rotor, 0)).

    Regenerated energy is not credited (a typical servo amplifier burns it in a shunt).
    """
    if st is None or len(cols["t"]) < 2:
        return float("nan")
    power = np.maximum(cols["tau_motor"] * cols["omega_m"] / st.coef_m, 0.0)
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(cols["t"])))


def kernel_metrics(acc: Array) -> dict[str, float | dict[str, float]]:
    """Tracking and effort metrics from the control kernel's per-step accumulators
    (``layout.A_*``): every physics step counts, whatever the logging options."""
    n = float(acc[layout.A_COUNT])
    if n < 1.0:
        raise InvalidParameterError(
            "no physics step was taken with the controllers on, so there are no metrics"
        )
    joints = ("q1", "q2", "q3")
    rmse = {j: math.sqrt(float(acc[layout.A_SQ_ERR + i]) / n) for i, j in enumerate(joints)}
    max_err = {j: float(acc[layout.A_MAX_ERR + i]) for i, j in enumerate(joints)}
    return {
        "rmse_rad": rmse,
        "rmse_deg": {k: math.degrees(v) for k, v in rmse.items()},
        "max_abs_err_rad": max_err,
        "max_abs_err_deg": {k: math.degrees(v) for k, v in max_err.items()},
        "tau_estimate_rmse_nm": math.sqrt(float(acc[layout.A_SQ_TAU_EST]) / n),
        "tau_estimate_max_abs_err_nm": float(acc[layout.A_MAX_TAU_EST]),
        "peak_motor_torque_nm": float(acc[layout.A_PEAK_MOTOR_TORQUE]),
        "peak_motor_speed_rad_s": float(acc[layout.A_PEAK_ROTOR_SPEED]),
        "peak_shaft_torque_nm": float(acc[layout.A_PEAK_SHAFT_TORQUE]),
        "peak_twist_rad": float(acc[layout.A_PEAK_TWIST]),
        "peak_tau2_nm": float(acc[layout.A_PEAK_TAU2]),
        "motor_energy_j": float(acc[layout.A_MOTOR_WORK]),
        "metric_samples": n,
    }


def compute_metrics(
    cols: dict[str, Array],
    duration_s: float,
    wall_s: float,
    st: ArmStructure | None = None,
    rating_nm: float | None = None,
    acc: Array | None = None,
) -> dict[str, float | dict[str, float]]:
    """Tracking and torque-estimate metrics of a run.

    With ``acc`` (the kernel's accumulators, :meth:`Simulation.metrics`) they cover every physics
    step; without it they are computed from the recorded rows ``cols`` (a record from elsewhere).
    """
    if acc is not None:
        out = kernel_metrics(acc)
    else:
        if len(cols["t"]) < 1:
            raise InvalidParameterError("the record has no rows, so there are no metrics")
        rmse: dict[str, float] = {}
        max_err: dict[str, float] = {}
        for j in (1, 2, 3):
            e = cols[f"q{j}"] - cols[f"q{j}_ref"]
            rmse[f"q{j}"] = float(np.sqrt(np.mean(e * e)))
            max_err[f"q{j}"] = float(np.max(np.abs(e)))
        te = cols["tau_model"] - cols["tau_shaft"]
        out = {
            "rmse_rad": rmse,
            "rmse_deg": {k: math.degrees(v) for k, v in rmse.items()},
            "max_abs_err_rad": max_err,
            "max_abs_err_deg": {k: math.degrees(v) for k, v in max_err.items()},
            "tau_estimate_rmse_nm": float(np.sqrt(np.mean(te * te))),
            "tau_estimate_max_abs_err_nm": float(np.max(np.abs(te))),
            "peak_motor_torque_nm": float(np.max(np.abs(cols["tau_motor"]))),
            "peak_motor_speed_rad_s": float(np.max(np.abs(cols["omega_m"])))
            / (st.coef_m if st else 1.0),
            "peak_shaft_torque_nm": float(np.max(np.abs(cols["tau_shaft"]))),
            "peak_twist_rad": float(np.max(np.abs(cols["twist"]))),
            "peak_tau2_nm": float(np.max(np.abs(cols["tau2"]))),
            "motor_energy_j": motor_energy_j(cols, st),
        }
    peak = out["peak_shaft_torque_nm"]
    assert isinstance(peak, float)
    out.update(
        {
            "peak_shaft_torque_over_rating": peak / rating_nm if rating_nm else float("nan"),
            "sim_time_s": duration_s,
            "wall_time_s": wall_s,
            "realtime_factor": duration_s / wall_s if wall_s > 0 else float("inf"),
        }
    )
    return out
