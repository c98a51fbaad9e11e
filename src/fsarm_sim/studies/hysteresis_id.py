"""Identify the controller's Maxwell-slip model of the shaft from series-bench records.

The records are seed 000's series test (:func:`fsarm_sim.studies.campaign.series_test`: a chirp
into the blocked bench's torque loop at a held bend; ``fsarm bench series``), each with the
columns ``theta_m``, ``theta_s``, ``phi_b`` and the bench's torque sensor ``tau_s`` - the bench
has the sensor the arm lacks. The model (``controllers/joint3_hysteresis.py``, twelve numbers,
:data:`fsarm_sim.engine.hysteresis_model.NAMES`) is

    tau = K(side, phi) x + sum_i k_i z_i(x; d_i, r, mu),   f_i = k_i d_i

where ``z_i`` is element i's play on the twist with the band ``[-r g d_i, g d_i]``,
``g = exp(mu |phi|)``. For given slip deflections ``d_i``, ratio ``r`` and bend growth ``mu`` the
torque is linear in the spring (k_pos, s_pos, k_neg, s_neg) and the element stiffnesses k_i >= 0,
so the fit is a variable projection: bounded linear least squares inside
(:func:`scipy.optimize.lsq_linear`), the five nonlinear parameters outside
(:func:`scipy.optimize.least_squares`) from a few starts. The linear part starts from the
paper's own eq. 8 fit of the same records (:func:`fsarm_sim.studies.campaign.fit_series`,
:func:`~fsarm_sim.studies.campaign.fit_bend_trend`), which this reports beside the new fit.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
from scipy import optimize

from fsarm_sim.controllers.joint3_hysteresis import element_step
from fsarm_sim.engine import hysteresis_model as hm
from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.studies import campaign

Array = npt.NDArray[np.float64]
DEFAULT_BENDS_DEG = (0.0, 45.0, 90.0)  # held bends of the identification (seed 000 Fig. 6 range)
DEFAULT_CHIRP_S = 8.0  # estimate: 0.2-3 Hz in 8 s gives ~13 loops per bend
# A slower chirp than seed 000's 0.5-20 Hz: the arm's joint 3 moves at fractions of a hertz, and
# above a few hertz the simulated bench's explicit slip elements overshoot their bands by one
# step's twist increment (the known model's own error on the bench grows from 0.010 N*m RMS at
# 0.5-4 Hz to 0.035 N*m at 17-20 Hz, 9 x 450 mm straight), which a fit there would learn.
DEFAULT_F_START_HZ = 0.2
DEFAULT_F_STOP_HZ = 3.0


class IdentificationError(FsarmError, ValueError):
    """The records cannot identify the hysteresis model (the message says why)."""


@dataclass(frozen=True)
class IdentifiedModel:
    """A fitted controller model and how well it and eq. 8 explain the records (N*m)."""

    values: tuple[float, ...]  # twelve numbers, engine.hysteresis_model.NAMES
    rmse_nm: float  # the model's torque error over all records
    eq8_rmse_nm: float  # eq. 8 (linear per side with its bend trend) on the same records
    samples: int
    bends_deg: tuple[float, ...]
    notes: tuple[str, ...] = ()  # what the records could not identify, and what was assumed

    def as_dict(self) -> dict[str, float]:
        return dict(zip(hm.NAMES, self.values, strict=True))


def play(x: Array, bend: Array, d: float, r: float, mu: float) -> Array:
    """One element's deflection along a record (``element_step`` with k = 1, f = d): the play
    operator with the band ``[-r g d, g d]``, starting at 0."""
    z = 0.0
    prev = float(x[0])
    out = np.empty_like(x)
    g = np.exp(mu * np.abs(bend))
    for i in range(x.shape[0]):
        xi = float(x[i])
        z = element_step(z, xi - prev, 1.0, d, r, float(g[i]))
        prev = xi
        out[i] = z
    return out


def model_torque(values: Sequence[float], x: Array, bend: Array) -> Array:
    """The model's torque along a twist record from rest (z = 0 at the start)."""
    hm.check(tuple(values))
    v = dict(zip(hm.NAMES, values, strict=True))
    ab = np.abs(bend)
    tau = np.where(x >= 0.0, (v["k_pos"] + v["s_pos"] * ab) * x, (v["k_neg"] + v["s_neg"] * ab) * x)
    for i in (1, 2, 3):
        k = v[f"k{i}"]
        if k > 0.0:
            d = v[f"f{i}"] / k
            tau = tau + k * play(x, bend, d, v["unwinding_ratio"], v["bend_friction_per_rad"])
    return np.asarray(tau, dtype=np.float64)


def _columns(records: Sequence[Mapping[str, Array]]) -> tuple[Array, Array, Array, list[int]]:
    xs, bs, ts, lengths = [], [], [], []
    for i, rec in enumerate(records):
        missing = [c for c in ("theta_m", "theta_s", "phi_b", "tau_s") if c not in rec]
        if missing:
            raise IdentificationError(f"record {i} lacks the column(s) {', '.join(missing)}")
        x = np.asarray(rec["theta_m"], dtype=np.float64) - np.asarray(rec["theta_s"])
        b = np.asarray(rec["phi_b"], dtype=np.float64) * np.ones_like(x)
        t = np.asarray(rec["tau_s"], dtype=np.float64)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(b)) and np.all(np.isfinite(t))):
            raise IdentificationError(f"record {i} holds NaN or infinite values")
        if x.size < 100 or np.count_nonzero(x > 0) < 10 or np.count_nonzero(x < 0) < 10:
            raise IdentificationError(
                f"record {i} must twist the shaft both ways over >= 100 samples"
            )
        xs.append(x)
        bs.append(b)
        ts.append(t)
        lengths.append(x.size)
    if not records:
        raise IdentificationError("identification needs at least one series-bench record")
    return np.concatenate(xs), np.concatenate(bs), np.concatenate(ts), lengths


def _design(
    xs: list[Array], bs: list[Array], d: Sequence[float] | Array, r: float, mu: float
) -> Array:
    """Columns: x+, |phi| x+, x-, |phi| x-, z_1..z_3 (per record from rest, stacked)."""
    blocks = []
    for x, b in zip(xs, bs, strict=True):
        p, n, ab = (x >= 0.0) * x, (x < 0.0) * x, np.abs(b)
        cols = [p, ab * p, n, ab * n] + [play(x, b, di, r, mu) for di in d]
        blocks.append(np.column_stack(cols))
    return np.vstack(blocks)


_LOWER = np.array([1e-9, -np.inf, 1e-9, -np.inf, 0.0, 0.0, 0.0])
_UPPER = np.full(7, np.inf)


_ONE_BEND = np.array([0, 2, 4, 5, 6])  # columns kept when the records hold one bend only


def _inner(A: Array, tau: Array, one_bend: bool = False) -> tuple[Array, Array]:
    """Bounded linear least squares of the seven stiffnesses (the two bend slopes held at 0
    when ``one_bend``); returns all seven and the residual."""
    keep = _ONE_BEND if one_bend else np.arange(7)
    B = A[:, keep]
    scale = np.linalg.norm(B, axis=0)
    scale[scale == 0.0] = 1.0
    lower = _LOWER[keep] * scale
    res = optimize.lsq_linear(B / scale, tau, bounds=(lower, _UPPER[keep]), method="bvls")
    coef = np.zeros(7)
    coef[keep] = res.x / scale
    return coef, tau - A @ coef


def identify(
    records: Sequence[Mapping[str, Array]], *, starts: int = 3, max_nfev: int = 100
) -> IdentifiedModel:
    """Fit the twelve numbers to series-bench records (module docstring)."""
    x_all, b_all, tau_all, lengths = _columns(records)
    edges = np.cumsum([0, *lengths])
    xs = [x_all[a:b] for a, b in itertools.pairwise(edges)]
    bs = [b_all[a:b] for a, b in itertools.pairwise(edges)]
    amp = float(np.max(np.abs(x_all)))
    # one held bend cannot tell the bend dependence: slopes and growth held at 0 (K at that bend)
    one_bend = float(np.ptp(np.abs(b_all))) < 1e-3
    notes = (
        (
            "the records hold one bend only: the spring's bend slopes and the slip torques' bend "
            "growth are not identifiable and were set to 0 (the model is that bend's)",
        )
        if one_bend
        else ()
    )

    def residual(p: Array) -> Array:
        d = np.exp(p[:3]) * amp
        r, mu = math.exp(p[3]), 0.0 if one_bend else max(float(p[4]), 0.0)
        return _inner(_design(xs, bs, d, r, mu), tau_all, one_bend)[1]

    best: tuple[float, Array] | None = None
    for s in range(starts):
        spread = (
            (0.01, 0.03, 0.1) if s == 0 else (0.005, 0.02, 0.06) if s == 1 else (0.02, 0.06, 0.2)
        )
        p0 = np.array([*np.log(spread), math.log(0.8), 0.2])
        sol = optimize.least_squares(
            residual,
            p0,
            bounds=([-12, -12, -12, math.log(0.1), 0.0], [0.0, 0.0, 0.0, math.log(3.0), 2.0]),
            diff_step=1e-3,
            max_nfev=max_nfev,
        )
        cost = float(np.mean(sol.fun**2))
        if best is None or cost < best[0]:
            best = (cost, sol.x)
    assert best is not None
    p = best[1]
    d = np.exp(p[:3]) * amp
    r, mu = math.exp(p[3]), 0.0 if one_bend else max(float(p[4]), 0.0)
    coef, res = _inner(_design(xs, bs, d, r, mu), tau_all, one_bend)
    k = coef[4:7]
    values = (
        *[float(c) for c in coef[:4]],
        *[float(c) for c in k],
        *[float(ki * di) for ki, di in zip(k, d, strict=True)],
        r,
        mu,
    )
    values = tuple(float(v) for v in values)
    hm.check(values)
    return IdentifiedModel(
        values=values,
        rmse_nm=float(np.sqrt(np.mean(res**2))),
        eq8_rmse_nm=_eq8_rmse(records),
        samples=int(x_all.size),
        bends_deg=tuple(float(np.degrees(np.mean(b))) for b in bs),
        notes=notes,
    )


def _eq8_rmse(records: Sequence[Mapping[str, Array]]) -> float:
    """Eq. 8 fitted the paper's way (per record, per side) on the same records: its RMSE."""
    sq, n = 0.0, 0
    for rec in records:
        bend = float(np.degrees(np.mean(np.asarray(rec["phi_b"], dtype=np.float64))))
        fit = campaign.fit_series(rec, bend)
        sq += fit.rmse_pos**2 * fit.n_pos + fit.rmse_neg**2 * fit.n_neg
        n += fit.n_pos + fit.n_neg
    return math.sqrt(sq / n)


def bench_records(
    shaft: ShaftParams,
    bends_deg: Sequence[float] = DEFAULT_BENDS_DEG,
    *,
    chirp_s: float = DEFAULT_CHIRP_S,
    f_start_hz: float = DEFAULT_F_START_HZ,
    f_stop_hz: float = DEFAULT_F_STOP_HZ,
    backend: str = "native",
) -> list[dict[str, Array]]:
    """Seed 000's series test of ``shaft`` on the simulated bench, one record per held bend
    (:func:`fsarm_sim.studies.campaign.series_test`, the records ``fsarm bench series`` runs),
    with a slower chirp by default (:data:`DEFAULT_F_STOP_HZ`)."""
    s = campaign.BenchSettings(
        chirp_s=chirp_s, f_start_hz=f_start_hz, f_stop_hz=f_stop_hz, backend=backend
    )
    s.validate()
    out = []
    for b in bends_deg:
        cols = campaign.series_test(shaft, math.radians(b), s)
        out.append({k: np.asarray(v, dtype=np.float64) for k, v in cols.items()})
    return out


def identify_shaft(
    shaft: ShaftParams,
    bends_deg: Sequence[float] = DEFAULT_BENDS_DEG,
    *,
    chirp_s: float = DEFAULT_CHIRP_S,
    backend: str = "native",
) -> IdentifiedModel:
    """:func:`identify` on ``shaft``'s simulated series-bench records (:func:`bench_records`)."""
    return identify(bench_records(shaft, bends_deg, chirp_s=chirp_s, backend=backend))


def identify_files(paths: Sequence[str | Path]) -> IdentifiedModel:
    """:func:`identify` on series-bench datasets (``setup: series_bench``, records/measured.py)."""
    from fsarm_sim.records.measured import load_dataset

    return identify([load_dataset(p, expect_setup="series_bench").columns for p in paths])


def fractions_toml(model: IdentifiedModel, shaft: ShaftParams, how: str) -> str:
    """``data/hysteresis_model.toml``'s text for ``model`` identified on ``shaft``."""
    fr = hm.fractions_of(model.values, shaft)
    lines = [
        "# The controller's Maxwell-slip model of the shaft (engine/hysteresis_model.py),",
        "# IDENTIFIED, not copied from the plant: written by scripts/identify_hysteresis_model.py.",
        f"# {how}",
        f"# Fit RMSE {model.rmse_nm:.4g} N*m over {model.samples} samples (eq. 8 on the same "
        f"records: {model.eq8_rmse_nm:.4g} N*m).",
        "# Fractions: stiffnesses (k_*, s_*, k1-k3) of the shaft's straight eq. 3 winding",
        "# stiffness K_sp(0), slip torques (f1-f3) of its rating; the ratios as they are.",
        "[fractions]",
        *(f"{k} = {v!r}" for k, v in fr.items()),
    ]
    return "\n".join(lines) + "\n"
