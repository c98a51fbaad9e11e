"""Seed 001's transparency with walking profiles (Sec. 4.2.2, Fig. 14) on its own bench.

Source: /work/shared/seeds/001_874b1e7feae8d04a.txt. The load motor (position mode, the set-up of
Fig. 11) imposes a human hip, knee or ankle angle profile at 1.2 s/stride on the RTCA's output
while its torque loop holds a 0 N*m set-point ("transparent mode"); the paper reports the
interaction torque the torque sensor measures and the estimate ``T̂_s`` at straight, R = 450 and
200 mm. The profiles are :mod:`fsarm_sim.studies.gait_profile`'s normative estimate (the paper
shows [36] only as a figure); the load motor is :class:`~fsarm_sim.studies.rtca_tracking.
LoadServo`; the actuator and its control are :mod:`fsarm_sim.studies.rtca_bench`'s.

The profile is imposed relative to its value at heel strike (the bench's output starts at 0 with
the shaft untwisted, as a load motor homed there would) and the first ``settle_strides`` strides
are not scored (the loop's integral settles); the interaction torque is scored over the rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fsarm_sim.studies import gait_profile
from fsarm_sim.studies.rtca_actuator import BenchError, Pid, Rtca001, run
from fsarm_sim.studies.rtca_tracking import LoadServo, load_motion


@dataclass(frozen=True)
class Walking:
    """One joint profile at one bend: the scored strides' interaction torques."""

    joint: str
    radius_m: float
    max_sensor_nm: float  # max |T_s| the torque sensor reads (the interaction torque)
    max_est_nm: float  # max |T̂_s(Δθ, R)| (the estimate the loop holds at 0)
    rms_sensor_nm: float
    rms_est_nm: float


def walking(
    act: Rtca001,
    pid: Pid,
    joint: str,
    *,
    radius_m: float = math.inf,
    strides: int = 3,
    settle_strides: int = 1,
    load: LoadServo | None = None,
    stride_s: float = gait_profile.STRIDE_S,
) -> Walking:
    """Impose ``joint``'s walking profile through the load motor at a 0 N*m set-point."""
    if not (isinstance(strides, int) and isinstance(settle_strides, int)):
        raise BenchError("strides and settle_strides must be whole numbers")
    if not (0 <= settle_strides < strides <= 50):
        raise BenchError(
            f"need 0 <= settle_strides < strides <= 50, got {settle_strides}, {strides}"
        )
    fit = gait_profile.fourier_fit(joint, stride_s)
    dt = act.ctrl_dt_s
    n = round(strides * stride_s / dt)
    t = np.arange(n) * dt
    ref = fit.eval(t) - fit.eval(0.0)
    theta_s = load_motion(load, ref, dt)
    r = run(act, pid, np.zeros(n), radius_m=radius_m, theta_s=theta_s)
    keep = t >= settle_strides * stride_s
    sens, est = r.tau_sensor[keep], r.tau_est[keep]
    return Walking(
        joint=joint,
        radius_m=radius_m,
        max_sensor_nm=float(np.max(np.abs(sens))),
        max_est_nm=float(np.max(np.abs(est))),
        rms_sensor_nm=float(np.sqrt(np.mean(sens**2))),
        rms_est_nm=float(np.sqrt(np.mean(est**2))),
    )
