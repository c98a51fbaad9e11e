"""A normative sagittal walking profile: hip, knee and ankle angles over one stride.

Seed 001 (/work/shared/seeds/001_874b1e7feae8d04a.txt) imposes "human-like position profiles: hip,
knee and ankle, taken from human data [36] at a speed of 1.2 s/stride" on its RTCA's output
(Sec. 4.2.2, Fig. 13) and drives its SimMechanics exoskeleton with "human-like kinematic profiles"
at the hip and knee (Sec. 5.2). It shows [36]'s profiles only as a figure and prints no number.

The profile here is an **estimate because the paper shows [36] only as a figure**: the mean adult
sagittal angles at normal cadence as published in the standard normative gait curves (Winter,
*Biomechanics and Motor Control of Human Movement*, 4th ed., Wiley 2009, normal-cadence sagittal
joint angles; the same shape as Perry & Burnfield, *Gait Analysis*, 2nd ed. 2010, Figs. 4-3, 4-9,
4-15), given approximately at every 5 % of the cycle from heel strike (:data:`KEY_PERCENT`,
:data:`KEY_ANGLES_DEG`): textbook values written from those curves' shape and landmarks, not
digitised from a copy of them (no copy is in the project). Hip: flexion +, peak ~28° in late
swing, extension to -10° near toe-off;
knee: flexion +, loading peak ~19° at 15 %, swing peak ~62° at 75 %; ankle: dorsiflexion +,
plantarflexion to -18° just after toe-off. The read values are smoothed by a least-squares Fourier
series of :data:`HARMONICS` harmonics (the usual representation of a periodic gait curve), which
also gives the velocities and accelerations analytically. Nothing here is fitted to any claim.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import InvalidParameterError

Array = npt.NDArray[np.float64]

STRIDE_S = 1.2  # seed 001 Sec. 4.2.2: "1.2 s/stride, considered as normal walking speed"
HARMONICS = 5  # Fourier order of the smoothing (estimate: 5 keeps the knee's two peaks)
JOINTS = ("hip", "knee", "ankle")

KEY_PERCENT: tuple[float, ...] = tuple(float(p) for p in range(0, 100, 5))
# Approximate normative means, degrees, at 0, 5, ..., 95 % of the stride (heel strike at 0 %):
# estimates after the published normative curves named in the module docstring (not digitised).
KEY_ANGLES_DEG: dict[str, tuple[float, ...]] = {
    "hip": (25, 25, 23, 20, 15, 10, 6, 2, -2, -6, -9, -10, -6, 2, 11, 19, 25, 28, 28, 26),
    "knee": (3, 10, 16, 19, 17, 13, 9, 6, 5, 6, 10, 18, 32, 48, 59, 62, 55, 40, 20, 7),
    "ankle": (0, -5, -3, 1, 4, 6, 8, 9, 10, 10, 7, 0, -12, -18, -12, -5, -1, 0, 1, 0),
}


class GaitError(InvalidParameterError):
    """A bad request for the gait profile."""


@dataclass(frozen=True)
class Fourier:
    """``q(t) = a0 + sum_n a_n cos(n w t) + b_n sin(n w t)``, radians, ``w = 2 pi / stride``."""

    a0: float
    a: tuple[float, ...]
    b: tuple[float, ...]
    stride_s: float

    def eval(self, t: npt.ArrayLike, derivative: int = 0) -> Array:
        """The angle (``derivative`` 0), its rate (1) or its acceleration (2) at times ``t``."""
        if derivative not in (0, 1, 2):
            raise GaitError(f"derivative must be 0, 1 or 2, got {derivative!r}")
        tt = np.asarray(t, dtype=float)
        w = 2.0 * math.pi / self.stride_s
        out = np.full_like(tt, self.a0 if derivative == 0 else 0.0)
        for n, (an, bn) in enumerate(zip(self.a, self.b, strict=True), start=1):
            c, s = np.cos(n * w * tt), np.sin(n * w * tt)
            k = (n * w) ** derivative
            if derivative == 0:
                out += an * c + bn * s
            elif derivative == 1:
                out += k * (-an * s + bn * c)
            else:
                out += -k * (an * c + bn * s)
        return out


def fourier_fit(joint: str, stride_s: float = STRIDE_S, harmonics: int = HARMONICS) -> Fourier:
    """The least-squares Fourier series of ``joint``'s key values (``hip``, ``knee``, ``ankle``)."""
    if joint not in KEY_ANGLES_DEG:
        raise GaitError(f"unknown joint {joint!r} (allowed: {', '.join(JOINTS)})")
    if not (math.isfinite(stride_s) and stride_s > 0.0):
        raise GaitError(f"stride must be a positive finite time in s, got {stride_s!r}")
    if not (1 <= harmonics <= (len(KEY_PERCENT) - 1) // 2):
        raise GaitError(f"harmonics must be 1-{(len(KEY_PERCENT) - 1) // 2}, got {harmonics!r}")
    phase = 2.0 * math.pi * np.asarray(KEY_PERCENT) / 100.0
    cols = [np.ones_like(phase)]
    for n in range(1, harmonics + 1):
        cols += [np.cos(n * phase), np.sin(n * phase)]
    y = np.radians(np.asarray(KEY_ANGLES_DEG[joint], dtype=float))
    coef = np.linalg.lstsq(np.stack(cols, axis=1), y, rcond=None)[0]
    return Fourier(
        a0=float(coef[0]),
        a=tuple(float(v) for v in coef[1::2]),
        b=tuple(float(v) for v in coef[2::2]),
        stride_s=stride_s,
    )


def profile(joint: str, t: npt.ArrayLike, stride_s: float = STRIDE_S) -> Array:
    """``joint``'s angle (rad) at times ``t`` (s; heel strike at t = 0, one stride = ``stride_s``)."""
    return fourier_fit(joint, stride_s).eval(t)
