"""Least-squares identification of the QA-Joint's stiffness and friction (seed 002 eq. 16-19).

Source: seed 002_93b61736cab1a199.txt Sec. V. The link is clamped, the position motor drives
cyclic motions at several presets sigma, and the link-side torque sensor measures the elastic
torque plus the friction of the elastic mechanism. The paper fits

* the stiffness coefficients of eq. 16 to the centre line of the hysteresis,
  ``y = M p`` (eq. 17), ``M = [exp(b (phi - sigma)), -exp(b (-phi - sigma))]``,
  ``p = (M^T M)^-1 M^T y`` (eq. 18);
* the friction coefficients of eq. 19 to the half-width, with the same exponential parts but
  ``+`` for ``b_F``.

Here both are one regression on the raw samples: the direction of motion ``s = sgn(phi')`` (from
the deflection's time derivative) multiplies the friction columns, so the measured torque is
``y = a_S E+ - b_S E- + s (a_F E+ + b_F E-)`` with ``E+- = exp(b (+-phi - sigma))``, i.e. the
friction sits in parallel with the spring (as in :mod:`fsarm_sim.plant.transmissions.qa_joint`). For
data with matched loading/unloading sweeps this equals the paper's two steps (centre line, then
half-width). Samples slower than ``min_speed_rad_s`` (standstill, reversals) carry no direction
and are dropped; ``reversal_band_rad`` also drops the presliding travel right after each reversal.

With a moving link, eq. 15 gives the transmitted torque as ``M q'' + tau_g + tau_ext``: pass the
load torque as ``torque_nm`` and the link inertia and angle, and ``M q''`` is added.

The solution is computed with an SVD least-squares solver (the same ``p`` as eq. 18, better
conditioned); the covariance ``s^2 (M^T M)^-1`` gives standard errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError

FloatArray = npt.NDArray[np.float64]

B_EXP_PER_RAD = 15.0  # seed 002 eq. 12-13, 16, 19
MAX_DEFLECTION_RAD = 1.0  # the law is used for |phi| <= sigma <= 15 deg; beyond 1 rad: units?
MAX_CONDITION = 1e6  # of the column-normalised data matrix (real sweeps: 1-10)


class IdentificationError(FsarmError, ValueError):
    """Identification data that cannot give a fit; the message says what is needed."""


class DataLengthError(IdentificationError):
    """Input arrays of different lengths."""


class NonFiniteDataError(IdentificationError):
    """NaN or infinite samples."""


class TooFewSamplesError(IdentificationError):
    """Fewer usable samples than the fit needs."""


class NoMotionError(IdentificationError):
    """No (or too little) motion in one direction: friction cannot be separated from stiffness."""


class IllConditionedDataError(IdentificationError):
    """The data matrix is (nearly) rank-deficient: the deflection does not vary enough."""


@dataclass(frozen=True)
class QaJointFit:
    """Fitted eq. 16 / eq. 19 coefficients (N*m) and how well they explain the data."""

    a_s_nm: float
    b_s_nm: float
    a_f_nm: float
    b_f_nm: float
    b_exp_per_rad: float
    std_errors_nm: tuple[float, float, float, float]  # a_S, b_S, a_F, b_F
    n_total: int
    n_used: int
    n_loading: int  # samples with phi' > 0
    n_unloading: int  # samples with phi' < 0
    residual_rms_nm: float
    residual_max_nm: float
    r_squared: float
    condition_number: float

    def overrides(self) -> dict[str, float]:
        """Parameter overrides for :mod:`fsarm_sim.plant.transmissions.qa_joint`."""
        return {"a_s": self.a_s_nm, "b_s": self.b_s_nm, "a_f": self.a_f_nm, "b_f": self.b_f_nm}


def data_matrix(
    deflection_rad: FloatArray,
    sigma_rad: FloatArray,
    direction: FloatArray,
    b_exp: float = B_EXP_PER_RAD,
) -> FloatArray:
    """Columns [E+, -E-, s E+, s E-] (eq. 17 for a_S, b_S; eq. 19 for a_F, b_F, times sgn(phi'))."""
    e_pos = np.exp(b_exp * (deflection_rad - sigma_rad))
    e_neg = np.exp(b_exp * (-deflection_rad - sigma_rad))
    return np.column_stack([e_pos, -e_neg, direction * e_pos, direction * e_neg])


def _as_1d(name: str, values: npt.ArrayLike) -> FloatArray:
    arr = np.asarray(values, dtype=float)
    if arr.ndim != 1:
        raise IdentificationError(f"{name} must be a 1-D array of samples, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.isfinite(arr))[0])
        raise NonFiniteDataError(
            f"{name} has NaN/inf samples (first at index {bad}); drop or fill them first"
        )
    return arr


def _check_lengths(arrays: dict[str, FloatArray]) -> int:
    lengths = {k: len(v) for k, v in arrays.items()}
    if len(set(lengths.values())) > 1:
        desc = ", ".join(f"{k}={n}" for k, n in lengths.items())
        raise DataLengthError(f"all input arrays must have the same length, got {desc}")
    return next(iter(lengths.values()))


def _deflection(
    deflection_rad: npt.ArrayLike | None,
    motor_rad: npt.ArrayLike | None,
    link_rad: npt.ArrayLike | None,
) -> FloatArray:
    """phi = theta - q (eq. 5, 11), or the deflection given directly."""
    if deflection_rad is not None:
        return _as_1d("deflection_rad", deflection_rad)
    if motor_rad is None or link_rad is None:
        raise IdentificationError(
            "give either deflection_rad or both motor_rad and link_rad (phi = theta - q, eq. 5)"
        )
    motor, link = _as_1d("motor_rad", motor_rad), _as_1d("link_rad", link_rad)
    _check_lengths({"motor_rad": motor, "link_rad": link})
    return motor - link


def _directions(
    deflection: FloatArray, rate: FloatArray, min_speed: float, reversal_band: float
) -> FloatArray:
    """sgn(phi') where |phi'| >= min_speed and the travel since the last reversal >= band; else 0."""
    s = np.where(rate >= min_speed, 1.0, np.where(rate <= -min_speed, -1.0, 0.0))
    if reversal_band <= 0.0:
        return s
    out = s.copy()
    last_dir, origin = 0.0, float(deflection[0])
    for i in range(len(s)):
        if s[i] == 0.0:
            continue
        if s[i] != last_dir:
            last_dir, origin = s[i], float(deflection[i])
        if abs(float(deflection[i]) - origin) < reversal_band:
            out[i] = 0.0
    return out


def _check_options(
    b_exp: float,
    min_speed_rad_s: float,
    reversal_band_rad: float,
    link_inertia_kgm2: float,
    min_samples: int,
    min_per_direction: int,
) -> None:
    """The fit's settings: finite and >= 0, b_exp > 0, enough samples asked for."""
    for name, v in (
        ("b_exp", b_exp),
        ("min_speed_rad_s", min_speed_rad_s),
        ("reversal_band_rad", reversal_band_rad),
        ("link_inertia_kgm2", link_inertia_kgm2),
    ):
        if not math.isfinite(v) or v < 0.0:
            raise IdentificationError(f"{name} must be a finite number >= 0, got {v!r}")
    if b_exp == 0.0:
        raise IdentificationError("b_exp must be > 0 (seed 002: 15 1/rad)")
    if min_samples < 5 or min_per_direction < 1:
        raise IdentificationError("min_samples must be >= 5 and min_per_direction >= 1")


def _least_squares(
    m: FloatArray, yu: FloatArray
) -> tuple[npt.NDArray[np.floating[Any]], FloatArray, FloatArray, float, float]:
    """Eq. 17-18 solved: (parameters, their standard errors, residuals, R², the scaled data
    matrix's condition number); :class:`IllConditionedDataError` when the columns are nearly
    parallel."""
    norms = np.linalg.norm(m, axis=0)
    cond = float(np.linalg.cond(m / norms))
    if not math.isfinite(cond) or cond > MAX_CONDITION:
        raise IllConditionedDataError(
            f"data matrix condition number {cond:.3g} (> {MAX_CONDITION:g}): the deflection must "
            f"sweep a range on both sides (the exponential columns are nearly parallel)"
        )
    p, *_ = np.linalg.lstsq(m, yu, rcond=None)
    resid = yu - m @ p
    dof = max(len(yu) - 4, 1)
    s2 = float(resid @ resid) / dof
    cov = s2 * np.linalg.inv(m.T @ m)
    ss_tot = float(np.sum((yu - yu.mean()) ** 2))
    r2 = 1.0 - float(resid @ resid) / ss_tot if ss_tot > 0.0 else 0.0
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return p, se, resid, r2, cond


def _check_motion(
    s: FloatArray, min_speed_rad_s: float, min_samples: int, min_per_direction: int
) -> tuple[int, int]:
    """(samples loading, unloading) of the directions ``s``; named errors when either side or the
    whole has too few."""
    n_pos, n_neg = int(np.sum(s > 0.0)), int(np.sum(s < 0.0))
    if n_pos < min_per_direction or n_neg < min_per_direction:
        raise NoMotionError(
            f"need motion in both directions to separate friction from stiffness: "
            f"{n_pos} samples with phi' > 0 and {n_neg} with phi' < 0 (at least "
            f"{min_per_direction} each, |phi'| >= {min_speed_rad_s:g} rad/s)"
        )
    if n_pos + n_neg < min_samples:
        raise TooFewSamplesError(
            f"{n_pos + n_neg} moving samples; the fit needs at least {min_samples} "
            f"(lower min_speed_rad_s/reversal_band_rad or record longer)"
        )
    return n_pos, n_neg


def identify(
    time_s: npt.ArrayLike,
    torque_nm: npt.ArrayLike,
    sigma_rad: float | npt.ArrayLike,
    *,
    deflection_rad: npt.ArrayLike | None = None,
    motor_rad: npt.ArrayLike | None = None,
    link_rad: npt.ArrayLike | None = None,
    link_inertia_kgm2: float = 0.0,
    b_exp: float = B_EXP_PER_RAD,
    min_speed_rad_s: float = 1e-3,
    reversal_band_rad: float = 0.0,
    min_samples: int = 20,
    min_per_direction: int = 5,
) -> QaJointFit:
    """Fit a_S, b_S (eq. 16) and a_F, b_F (eq. 19) by least squares (eq. 17-18).

    ``time_s`` strictly increasing; ``torque_nm`` the measured joint torque (clamped link) or the
    load torque with ``link_inertia_kgm2`` and ``link_rad`` given; ``sigma_rad`` the preset
    (scalar or one value per sample); the deflection either directly or as ``motor_rad`` and
    ``link_rad``. Raises a subclass of :class:`IdentificationError` for unusable data.
    """
    t = _as_1d("time_s", time_s)
    tau = _as_1d("torque_nm", torque_nm)
    phi = _deflection(deflection_rad, motor_rad, link_rad)
    arrays = {"time_s": t, "torque_nm": tau, "deflection": phi}
    sig_arr = np.asarray(sigma_rad, dtype=float)
    if sig_arr.ndim == 0:
        sig = np.full(len(phi), float(sig_arr))
    else:
        sig = _as_1d("sigma_rad", sig_arr)
        arrays["sigma_rad"] = sig
    n = _check_lengths(arrays)
    _check_options(
        b_exp, min_speed_rad_s, reversal_band_rad, link_inertia_kgm2, min_samples, min_per_direction
    )
    if n < max(min_samples, 3):
        raise TooFewSamplesError(f"{n} samples given; the fit needs at least {min_samples}")
    if not np.all(np.isfinite(sig)) or np.any(sig <= 0.0) or np.any(sig > MAX_DEFLECTION_RAD):
        raise IdentificationError("sigma_rad must be finite and in (0, 1] rad (Table IV: 3-15 deg)")
    if np.any(np.diff(t) <= 0.0):
        raise IdentificationError("time_s must be strictly increasing")
    if np.max(np.abs(phi)) > MAX_DEFLECTION_RAD:
        raise IdentificationError(
            f"|deflection| reaches {np.max(np.abs(phi)):.3g} rad; the QA-Joint law holds for "
            f"|phi| <= sigma <= 15 deg - are the angles in degrees?"
        )
    y = tau.copy()
    if link_inertia_kgm2 > 0.0:
        if link_rad is None:
            raise IdentificationError("link_inertia_kgm2 needs link_rad (eq. 15: M q'')")
        q = _as_1d("link_rad", link_rad)
        y = y + link_inertia_kgm2 * np.gradient(np.gradient(q, t), t)
    s = _directions(phi, np.gradient(phi, t), min_speed_rad_s, reversal_band_rad)
    n_pos, n_neg = _check_motion(s, min_speed_rad_s, min_samples, min_per_direction)
    used = s != 0.0
    n_used = n_pos + n_neg
    m = data_matrix(phi[used], sig[used], s[used], b_exp)
    p, se, resid, r2, cond = _least_squares(m, y[used])
    return QaJointFit(
        a_s_nm=float(p[0]),
        b_s_nm=float(p[1]),
        a_f_nm=float(p[2]),
        b_f_nm=float(p[3]),
        b_exp_per_rad=float(b_exp),
        std_errors_nm=(float(se[0]), float(se[1]), float(se[2]), float(se[3])),
        n_total=n,
        n_used=n_used,
        n_loading=n_pos,
        n_unloading=n_neg,
        residual_rms_nm=float(np.sqrt(np.mean(resid**2))),
        residual_max_nm=float(np.max(np.abs(resid))),
        r_squared=r2,
        condition_number=cond,
    )
