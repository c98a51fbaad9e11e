"""Recorded bench columns prepared for the replay (:mod:`.replay`): angles smoothed (zero-phase
cubic Savitzky-Golay, :func:`smooth`) and differentiated (:func:`derivative`: 15 ms / 31 ms
windows, cubic), so that encoder quantisation does not turn into velocity spikes, arranged as
:class:`ReplayInputs` by :func:`prepare_inputs`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.signal import savgol_filter

from fsarm_sim.records.measured import Dataset

FloatArray = npt.NDArray[np.float64]


def savgol_window(h: float, seconds: float, minimum: int = 5) -> int:
    w = max(minimum, round(seconds / h))
    return w if w % 2 == 1 else w + 1


def derivative(
    y: FloatArray, h: float, order: int = 1, window_s: float | None = None, scale: float = 1.0
) -> FloatArray:
    """Savitzky-Golay derivative (cubic; 15 ms window for rates, 31 ms for accelerations; the
    window times ``scale``)."""
    w = savgol_window(h, scale * (window_s or (0.015 if order == 1 else 0.031)), 7)
    if y.size < w:
        return np.gradient(y, h) if order == 1 else np.gradient(np.gradient(y, h), h)
    return np.asarray(savgol_filter(y, w, 3, deriv=order, delta=h), dtype=np.float64)


INPUT_SMOOTH_S = 0.021  # Savitzky-Golay window (cubic) applied to recorded angles before replay


def smooth(y: FloatArray, h: float, scale: float = 1.0) -> FloatArray:
    """Zero-phase cubic Savitzky-Golay smoothing of a recorded angle (21 ms window: -3 dB near
    65 Hz at 1 kHz, far above the benches' 0.1-20 Hz inputs). Encoder quantisation steps would
    otherwise drive stiff presliding / slip elements in jumps that the physical, continuous
    motion never makes. ``scale``: the window times this (the uncertainty's check of what the
    smoothing itself does to the fitted parameters)."""
    w = savgol_window(h, scale * INPUT_SMOOTH_S, 7)
    if y.size < w:
        return y.copy()
    return np.asarray(savgol_filter(y, w, 3), dtype=np.float64)


@dataclass
class ReplayInputs:
    """Recorded columns prepared for replay."""

    setup: str
    t: FloatArray
    h: float
    u: FloatArray  # input: theta_m (series) or phi_b (parallel)
    udot: FloatArray
    uacc: FloatArray
    s: FloatArray  # series: measured theta_s (blocked: the constant); parallel: zeros
    sdot: FloatArray
    phi: FloatArray  # bend angle per sample (parallel: phi_b itself)
    y: FloatArray  # measured main output (tau_s or m_b)
    theta_s: FloatArray | None  # series inertia: measured load angle (second output)
    inertia_load: bool
    omega_s: FloatArray | None = None  # series inertia: measured load speed (Savitzky-Golay)
    theta_s_smooth: FloatArray | None = None  # series inertia: smoothed measured load angle
    alpha_s: FloatArray | None = None  # series inertia: measured load acceleration

    @property
    def n(self) -> int:
        return int(self.t.size)


def prepare_inputs(ds: Dataset, window_scale: float = 1.0) -> ReplayInputs:
    """Columns of a bench dataset arranged for the replay kernels; ``window_scale``: every
    smoothing and differentiation window times this (1: the replay's own)."""
    c = ds.columns
    h = ds.dt
    sc = window_scale
    rest: dict[str, Any]  # what the setup measures beside its drive u
    if ds.setup == "series_bench":
        u = smooth(c["theta_m"], h, sc)
        s_raw = c["theta_s"]
        s = smooth(s_raw, h, sc)
        inertia = ds.load_inertia_kgm2 is not None
        rest = dict(
            s=s if not inertia else np.zeros_like(u),
            sdot=derivative(s, h, scale=sc) if not inertia else np.zeros_like(u),
            phi=c["phi_b"],
            y=c["tau_s"],
            theta_s=s_raw if inertia else None,
            inertia_load=inertia,
            omega_s=derivative(s, h, 1, 0.031, sc) if inertia else None,
            theta_s_smooth=s if inertia else None,
            alpha_s=derivative(s, h, 2, scale=sc) if inertia else None,
        )
    elif ds.setup == "parallel_bench":
        u = smooth(c["phi_b"], h, sc)
        z = np.zeros_like(u)
        rest = dict(s=z, sdot=z, phi=u, y=c["m_b"], theta_s=None, inertia_load=False)
    else:
        raise ValueError(f"no bench replay for setup {ds.setup!r}")
    return ReplayInputs(
        setup=ds.setup,
        t=c["t"],
        h=h,
        u=u,
        udot=derivative(u, h, scale=sc),
        uacc=derivative(u, h, 2, scale=sc),
        **rest,
    )
