"""Seed 001's exoskeleton study (Sec. 5.2, Fig. 19): the hip and knee torques its actuator's mass
costs, with the RTCA and with an in-line ankle actuator.

Source: /work/shared/seeds/001_874b1e7feae8d04a.txt, Sec. 5.2. The paper simulates in SimMechanics a
lower-limb exoskeleton "in which only the ankle joint is actuated", imposes "human-like position
trajectories at the hip and knee joints" and compares, by inverse dynamics, "the required torques at
the hip and knee joints to accelerate and deaccelerate an ankle joint actuator". What it gives:

* thigh 0.416 m, shank 0.418 m (a 1.70 m human, anthropometric data [36]);
* RTCA: the motor (0.7 kg) "a punctual mass located at 0.1 m from the hip joint and connected to
  the thigh"; the flexible shaft "together with the rest of the components ... a mass of 1.1 kg
  located at 0.1 m from the knee joint";
* in-line: "a total weight of 1 kg" for an actuator at the ankle.

What it does not give, and the estimates here (each named where it is used):

* the side of the knee the 1.1 kg sits on: on the **shank**, 0.1 m below the knee (**estimate**:
  the shaft's distal half, its end connector and the ankle's 90° stage of Fig. 15 hang below the
  knee; the text says only "at 0.1 m from the knee joint"). :data:`RTCA_MASSES_THIGH_SIDE` is the
  other reading, kept for the report;
* the in-line actuator's mass at the ankle joint, the end of the shank (**estimate**: "placed
  in-line with the ankle");
* the pelvis fixed in space (**estimate**: the trajectories are imposed at the hip and knee
  joints; nothing says the hip moves), gravity 9.81 m/s² along -y (**estimate**: SimMechanics'
  default), point masses only (the exoskeleton's own links are common to both designs and the
  paper compares the actuator's share);
* the hip and knee trajectories: :mod:`fsarm_sim.studies.gait_profile` (estimate: [36] is shown
  only as a figure), 1.2 s per stride as in Sec. 4.2.2.

The leg is a planar 2-link chain with point masses; the joint torques are
``tau = sum_i J_i^T m_i (p_i'' + g e_y)`` (exact for point masses), hip flexion and knee flexion
positive (the torque a joint's actuator applies in that direction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim.studies import gait_profile
from fsarm_sim.studies.gait_profile import GaitError

Array = npt.NDArray[np.float64]

THIGH_M = 0.416  # Sec. 5.2
SHANK_M = 0.418  # Sec. 5.2
GRAVITY = 9.81  # estimate: SimMechanics' default

# (mass kg, link: "thigh" from the hip / "shank" from the knee, distance m along the link)
PointMass = tuple[float, str, float]
RTCA_MASSES: tuple[PointMass, ...] = (
    (0.7, "thigh", 0.1),  # Sec. 5.2: the motor, 0.1 m from the hip on the thigh
    (1.1, "shank", 0.1),  # Sec. 5.2: shaft and the rest, 0.1 m from the knee (shank: estimate)
)
RTCA_MASSES_THIGH_SIDE: tuple[PointMass, ...] = (
    (0.7, "thigh", 0.1),
    (1.1, "thigh", THIGH_M - 0.1),  # the other reading: 0.1 m above the knee
)
INLINE_MASSES: tuple[PointMass, ...] = ((1.0, "shank", SHANK_M),)  # Sec. 5.2: 1 kg at the ankle


@dataclass(frozen=True)
class LegTorques:
    """Joint torques over the sampled times (N*m, flexion +)."""

    t: Array
    hip_nm: Array
    knee_nm: Array

    def peaks(self, joint: str) -> tuple[float, float]:
        """(peak flexion torque, peak extension torque), both >= 0."""
        tau = {"hip": self.hip_nm, "knee": self.knee_nm}.get(joint)
        if tau is None:
            raise GaitError(f"unknown joint {joint!r} (allowed: hip, knee)")
        return max(float(np.max(tau)), 0.0), max(float(-np.min(tau)), 0.0)


def _check_masses(masses: tuple[PointMass, ...]) -> None:
    for m, link, d in masses:
        length = THIGH_M if link == "thigh" else SHANK_M if link == "shank" else None
        if length is None:
            raise GaitError(f"a point mass's link must be 'thigh' or 'shank', got {link!r}")
        if not (math.isfinite(m) and m >= 0.0 and math.isfinite(d) and 0.0 <= d <= length):
            raise GaitError(
                f"point mass {m!r} kg at {d!r} m on the {link}: need a mass >= 0 and "
                f"0 <= distance <= {length} m"
            )


def joint_torques(
    masses: tuple[PointMass, ...],
    hip: npt.ArrayLike,
    knee: npt.ArrayLike,
    t: npt.ArrayLike,
    *,
    hip_rate: npt.ArrayLike,
    knee_rate: npt.ArrayLike,
    hip_acc: npt.ArrayLike,
    knee_acc: npt.ArrayLike,
) -> LegTorques:
    """Inverse dynamics of the point masses on the 2-link leg (hip fixed) for the given motion
    (angles rad, rates rad/s, accelerations rad/s²; hip flexion, knee flexion positive)."""
    _check_masses(masses)
    q1, q2 = np.asarray(hip, dtype=float), np.asarray(knee, dtype=float)
    w1, w2 = np.asarray(hip_rate, dtype=float), np.asarray(knee_rate, dtype=float)
    a1, a2 = np.asarray(hip_acc, dtype=float), np.asarray(knee_acc, dtype=float)
    phi, wphi, aphi = q1 - q2, w1 - w2, a1 - a2  # the shank's absolute angle from vertical
    tau1, tau2 = np.zeros_like(q1), np.zeros_like(q1)

    def acc(d: float, ang: Array, w: Array, a: Array) -> tuple[Array, Array]:
        """p'' of a point d along a link at absolute angle ang (p = d (sin, -cos))."""
        return d * (a * np.cos(ang) - w**2 * np.sin(ang)), d * (
            a * np.sin(ang) + w**2 * np.cos(ang)
        )

    for m, link, d in masses:
        if link == "thigh":
            ax, ay = acc(d, q1, w1, a1)
            fx, fy = m * ax, m * (ay + GRAVITY)
            tau1 += d * (np.cos(q1) * fx + np.sin(q1) * fy)
        else:
            kx, ky = acc(THIGH_M, q1, w1, a1)
            sx, sy = acc(d, phi, wphi, aphi)
            fx, fy = m * (kx + sx), m * (ky + sy + GRAVITY)
            tau1 += (THIGH_M * np.cos(q1) + d * np.cos(phi)) * fx
            tau1 += (THIGH_M * np.sin(q1) + d * np.sin(phi)) * fy
            tau2 += -d * (np.cos(phi) * fx + np.sin(phi) * fy)
    return LegTorques(t=np.asarray(t, dtype=float), hip_nm=tau1, knee_nm=tau2)


def walking_torques(
    masses: tuple[PointMass, ...],
    *,
    stride_s: float = gait_profile.STRIDE_S,
    samples: int = 1200,
) -> LegTorques:
    """The torques over one stride of :mod:`~fsarm_sim.studies.gait_profile`'s hip and knee."""
    if not (isinstance(samples, int) and 10 <= samples <= 1_000_000):
        raise GaitError(f"samples must be a whole number 10-1000000, got {samples!r}")
    hip = gait_profile.fourier_fit("hip", stride_s)
    knee = gait_profile.fourier_fit("knee", stride_s)
    t = np.arange(samples) * stride_s / samples
    return joint_torques(
        masses,
        hip.eval(t),
        knee.eval(t),
        t,
        hip_rate=hip.eval(t, 1),
        knee_rate=knee.eval(t, 1),
        hip_acc=hip.eval(t, 2),
        knee_acc=knee.eval(t, 2),
    )


@dataclass(frozen=True)
class Reduction:
    """Peak torques (flexion, extension) in-line and with the RTCA, and the reductions in %."""

    joint: str
    inline_nm: tuple[float, float]
    rtca_nm: tuple[float, float]

    def percent(self, which: str) -> float:
        """``flexion``, ``extension`` or ``peak`` (the largest |tau| of each design)."""
        if which == "peak":
            a, b = max(self.inline_nm), max(self.rtca_nm)
        elif which in ("flexion", "extension"):
            i = 0 if which == "flexion" else 1
            a, b = self.inline_nm[i], self.rtca_nm[i]
        else:
            raise GaitError(f"which must be flexion, extension or peak, got {which!r}")
        return 100.0 * (1.0 - b / a) if a > 0.0 else math.nan


def reductions(
    rtca: tuple[PointMass, ...] = RTCA_MASSES, inline: tuple[PointMass, ...] = INLINE_MASSES
) -> dict[str, Reduction]:
    """Sec. 5.2's comparison at the hip and knee."""
    a, b = walking_torques(inline), walking_torques(rtca)
    return {j: Reduction(j, a.peaks(j), b.peaks(j)) for j in ("hip", "knee")}
