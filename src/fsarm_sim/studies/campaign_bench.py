"""Seed 000 Sec. III bench tests on one shaft: the series test (eq. 8, eq. 1 fits, bend trend) and
the parallel test (eq. 2 moment loop).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.shaft import (
    Catalogue,
    ShaftParams,
    load_catalogue,
    parse_catalogue,
)
from fsarm_sim.studies import bench

Array = npt.NDArray[np.float64]
BEND_STEPS_DEG: tuple[float, ...] = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)  # Sec. III-A
SENSOR_RANGE_NM = 20.0  # DBRK-20 torque sensor, seed 000 Sec. III-A
LOOP_POINTS = 1200  # samples kept per loop for figures
SERIES_LOOP_S = 2.5  # series loops in figures: the chirp's first seconds (slow, ~0.5-1 Hz)
EQ3_NAMES = ("p0", "p1", "p2", "p3", "p4", "p5", "p6")
EQ4_NAMES = ("q0", "q1", "q2", "q3", "q4")


class CampaignError(FsarmError, ValueError):
    """A bench experiment or surface fit cannot be done with the data or settings given."""


# ----------------------------------------------------------------------------------------------
# settings


@dataclass(frozen=True)
class BenchSettings:
    """How the simulated bench experiments are run (defaults: seed 000 Sec. III-A where stated)."""

    chirp_s: float = 10.0  # estimate: long enough for ~100 cycles of each twist sign
    f_start_hz: float = 0.5  # Sec. III-A
    f_stop_hz: float = 20.0  # Sec. III-A
    amplitude_fraction: float = 0.8  # of the rating ("amplitudes based on their nominal torque")
    bend_period_s: float = 8.0  # parallel test, one cycle (estimate: Fig. 9's slow bending)
    bend_cycles: int = 2  # the first cycle settles the conduit; fits use the last one
    bend_amplitude_deg: float = 90.0  # Sec. III-A: bend capability up to 90 deg
    torsion_fraction: float = 0.5  # "with torsion": held twist torque / rating (estimate)
    series_hysteresis: bool | None = None  # Maxwell-slip elements; None: the catalogue's setting
    backend: str = "native"

    def validate(self) -> None:
        for name in ("chirp_s", "f_start_hz", "f_stop_hz", "amplitude_fraction", "bend_period_s"):
            v = getattr(self, name)
            if (
                isinstance(v, bool)
                or not isinstance(v, int | float)
                or not math.isfinite(v)
                or v <= 0
            ):
                raise CampaignError(f"bench setting {name} must be a finite number > 0, got {v!r}")
        if self.f_start_hz >= self.f_stop_hz:
            raise CampaignError(
                f"chirp needs f_start < f_stop, got {self.f_start_hz:g} >= {self.f_stop_hz:g} Hz"
            )
        if (
            isinstance(self.bend_cycles, bool)
            or not isinstance(self.bend_cycles, int)
            or self.bend_cycles < 1
        ):
            raise CampaignError(
                f"bend_cycles must be a whole number >= 1, got {self.bend_cycles!r}"
            )
        if not 0.0 < self.bend_amplitude_deg <= 120.0:
            raise CampaignError(
                f"bend amplitude must be in (0, 120] deg, got {self.bend_amplitude_deg!r}"
            )
        if not 0.0 <= self.torsion_fraction <= 1.0:
            raise CampaignError(
                f"torsion_fraction must be in [0, 1], got {self.torsion_fraction!r}"
            )
        if self.amplitude_fraction > 1.0:
            raise CampaignError(
                f"amplitude_fraction above 1 overloads the shaft, got {self.amplitude_fraction!r}"
            )
        if self.backend not in ("python", "native"):
            raise CampaignError(f"backend must be 'python' or 'native', got {self.backend!r}")


def _shaft(catalogue: Catalogue, d: float, ell: float, s: BenchSettings) -> ShaftParams:
    return catalogue.shaft(d, ell, series_hysteresis=s.series_hysteresis)


# ----------------------------------------------------------------------------------------------
# series test


def chirp_amplitude_nm(shaft: ShaftParams, s: BenchSettings) -> float:
    """Chirp amplitude: a fraction of the rating, never beyond the sensor range."""
    return min(s.amplitude_fraction * shaft.rating_nm, 0.9 * SENSOR_RANGE_NM)


def series_test(shaft: ShaftParams, bend_rad: float, s: BenchSettings) -> dict[str, Array]:
    """One chirp into the bench's torque controller at a held bend; the bench's columns."""
    dt = bench.TorqueLoopGains().ctrl_dt_s
    t = np.arange(round(s.chirp_s / dt) + 1, dtype=np.float64) * dt
    rate = (s.f_stop_hz - s.f_start_hz) / s.chirp_s
    tau_d = chirp_amplitude_nm(shaft, s) * np.sin(
        2.0 * math.pi * (s.f_start_hz * t + 0.5 * rate * t * t)
    )
    b = bench.build_series_bench(shaft, bench.BLOCKED, bend_rad, backend=s.backend)  # type: ignore[arg-type]
    return b.run_torque_control(tau_d, t)


@dataclass(frozen=True)
class SeriesFit:
    """Fits of one series test (N*m/rad, N*m*s/rad, kg*m^2, N*m)."""

    bend_deg: float
    k_pos: float  # eq. 8, twist >= 0
    k_neg: float  # eq. 8, twist < 0
    rmse_pos: float
    rmse_neg: float
    eq1_j: float  # eq. 1 (J shared, B and K per sign)
    eq1_b_pos: float
    eq1_b_neg: float
    eq1_k_pos: float
    eq1_k_neg: float
    eq1_rmse_pos: float
    eq1_rmse_neg: float
    n_pos: int
    n_neg: int
    max_torque_nm: float


def fit_series(cols: Mapping[str, Array], bend_deg: float) -> SeriesFit:
    """Eq. 8 and eq. 1 per twist sign from a series test's columns."""
    t = np.asarray(cols["t"], dtype=np.float64)
    twist = np.asarray(cols["theta_m"], dtype=np.float64) - np.asarray(cols["theta_s"])
    tau = np.asarray(cols["tau_s"], dtype=np.float64)
    pos, neg = twist >= 0.0, twist < 0.0
    if np.count_nonzero(pos) < 10 or np.count_nonzero(neg) < 10:
        raise CampaignError(
            "a series fit needs both twist signs (>= 10 samples each); the chirp did not twist "
            "the shaft both ways"
        )

    def through_origin(sel: npt.NDArray[np.bool_]) -> tuple[float, float]:
        x, y = twist[sel], tau[sel]
        k = float(np.dot(x, y) / np.dot(x, x))
        return k, float(np.sqrt(np.mean((y - k * x) ** 2)))

    k_pos, r_pos = through_origin(pos)
    k_neg, r_neg = through_origin(neg)
    rate = np.gradient(twist, t)
    acc = np.gradient(rate, t)
    p, n = pos.astype(float), neg.astype(float)
    X = np.column_stack((acc, rate * p, rate * n, twist * p, twist * n))
    scale = np.linalg.norm(X, axis=0)
    scale[scale == 0.0] = 1.0
    coef, *_ = np.linalg.lstsq(X / scale, tau, rcond=None)
    coef = coef / scale
    res = tau - X @ coef
    return SeriesFit(
        bend_deg=bend_deg,
        k_pos=k_pos,
        k_neg=k_neg,
        rmse_pos=r_pos,
        rmse_neg=r_neg,
        eq1_j=float(coef[0]),
        eq1_b_pos=float(coef[1]),
        eq1_b_neg=float(coef[2]),
        eq1_k_pos=float(coef[3]),
        eq1_k_neg=float(coef[4]),
        eq1_rmse_pos=float(np.sqrt(np.mean(res[pos] ** 2))),
        eq1_rmse_neg=float(np.sqrt(np.mean(res[neg] ** 2))),
        n_pos=int(np.count_nonzero(pos)),
        n_neg=int(np.count_nonzero(neg)),
        max_torque_nm=float(np.max(np.abs(tau))),
    )


@dataclass(frozen=True)
class BendTrend:
    """K(phi) = k0 + slope |phi| per sign (eq. 8's f_p(phi) = 1 + slope/k0 |phi|), phi in rad."""

    k0_pos: float
    slope_pos: float
    k0_neg: float
    slope_neg: float
    rmse_pos: float
    rmse_neg: float


def fit_bend_trend(fits: Sequence[SeriesFit]) -> BendTrend:
    if len(fits) < 2:
        raise CampaignError("the bend trend needs series fits at >= 2 bend angles")
    phi = np.radians([abs(f.bend_deg) for f in fits])
    if np.ptp(phi) == 0.0:
        raise CampaignError("the bend trend needs series fits at >= 2 different bend angles")
    out = []
    for ks in ([f.k_pos for f in fits], [f.k_neg for f in fits]):
        slope, k0 = np.polyfit(phi, ks, 1)
        out.append((float(k0), float(slope), float(np.sqrt(np.mean((k0 + slope * phi - ks) ** 2)))))
    return BendTrend(out[0][0], out[0][1], out[1][0], out[1][1], out[0][2], out[1][2])


# ----------------------------------------------------------------------------------------------
# parallel test


def parallel_test(shaft: ShaftParams, torsion: bool, s: BenchSettings) -> dict[str, Array]:
    """``bend_cycles`` bending cycles 0 -> +A -> 0 -> -A -> 0 on the parallel bench; the
    returned columns hold the last cycle only (the conduit has settled into its loop)."""
    dt = bench.DEFAULT_MAX_TIMESTEP_S
    per = round(s.bend_period_s / dt)
    t = np.arange(per * s.bend_cycles + 1, dtype=np.float64) * dt
    phi = math.radians(s.bend_amplitude_deg) * np.sin(2.0 * math.pi * t / s.bend_period_s)
    twist = 0.0
    if torsion:
        twist = s.torsion_fraction * shaft.rating_nm / shaft.k_series(0.0, 1)
    cols = bench.simulate_parallel_bench(phi, t, shaft, twist_rad=twist, backend=s.backend)  # type: ignore[arg-type]
    start = per * (s.bend_cycles - 1)
    return {k: np.asarray(v)[start:] for k, v in cols.items()}


@dataclass(frozen=True)
class ParallelFit:
    """Fits of one bending cycle (N*m/rad, 1/rad^2, N*m, J)."""

    torsion: bool
    kb_linear: float  # eq. 2: M = K_b phi over the whole loop
    rmse_linear: float
    kb_pos_bend: float  # eq. 2 on phi >= 0 only
    kb_neg_bend: float  # eq. 2 on phi < 0 only
    kb_cubic: float  # M = K_b (phi + beta phi^3)
    beta_cubic: float
    rmse_cubic: float
    loop_energy_j: float  # closed-loop integral of M dphi (dissipated per cycle)
    moment_at_max_bend_nm: float  # mean of the moments at the largest bend


def fit_parallel(cols: Mapping[str, Array], torsion: bool) -> ParallelFit:
    phi = np.asarray(cols["phi_b"], dtype=np.float64)
    m = np.asarray(cols["m_b"], dtype=np.float64)
    if np.count_nonzero(phi > 0) < 10 or np.count_nonzero(phi < 0) < 10:
        raise CampaignError("a parallel fit needs bends in both directions (>= 10 samples each)")

    def slope(sel: npt.NDArray[np.bool_]) -> tuple[float, float]:
        x, y = phi[sel], m[sel]
        k = float(np.dot(x, y) / np.dot(x, x))
        return k, float(np.sqrt(np.mean((y - k * x) ** 2)))

    every = np.ones(phi.size, dtype=bool)
    kb, r_lin = slope(every)
    kb_p, _ = slope(phi >= 0.0)
    kb_n, _ = slope(phi < 0.0)
    X = np.column_stack((phi, phi**3))
    (a, b), *_ = np.linalg.lstsq(X, m, rcond=None)
    r_cub = float(np.sqrt(np.mean((m - X @ np.array([a, b])) ** 2)))
    top = np.abs(phi) >= 0.999 * np.max(np.abs(phi))
    return ParallelFit(
        torsion=torsion,
        kb_linear=kb,
        rmse_linear=r_lin,
        kb_pos_bend=kb_p,
        kb_neg_bend=kb_n,
        kb_cubic=float(a),
        beta_cubic=float(b / a) if a != 0.0 else math.nan,
        rmse_cubic=r_cub,
        loop_energy_j=float(abs(np.sum(0.5 * (m[1:] + m[:-1]) * np.diff(phi)))),
        moment_at_max_bend_nm=float(np.mean(np.abs(m[top]))),
    )


# ----------------------------------------------------------------------------------------------
# tasks (one bench run each; module-level so process pools and Dask can pickle them)


def _decimate(x: Array, n: int = LOOP_POINTS) -> list[float]:
    step = max(1, x.size // n)
    return [float(v) for v in x[::step]]


def bench_task(task: Mapping[str, Any]) -> dict[str, Any]:
    """Run one bench test described by a plain dict and return its fit (and a decimated loop).

    Keys: ``test`` ("series" | "parallel"), ``diameter_mm``, ``length_mm``, ``bend_deg``
    (series) or ``torsion`` (parallel), ``settings`` (BenchSettings fields), ``catalogue_toml``
    (the coefficient file's text; None: default catalogue), ``loop`` (bool: return the loop).
    """
    text = task.get("catalogue_toml")
    cat = (
        load_catalogue()
        if text is None
        else parse_catalogue(tomllib.loads(text), str(task.get("catalogue_source", "catalogue")))
    )
    s = BenchSettings(**task.get("settings", {}))
    sh = _shaft(cat, float(task["diameter_mm"]), float(task["length_mm"]), s)
    out: dict[str, Any] = {"test": task["test"]}
    if task["test"] == "series":
        bend_deg = float(task["bend_deg"])
        cols = series_test(sh, math.radians(bend_deg), s)
        out["fit"] = asdict(fit_series(cols, bend_deg))
        if task.get("loop", False):  # the slow start of the chirp, undecimated in time
            first = cols["t"] - cols["t"][0] <= SERIES_LOOP_S
            out["loop"] = {
                "twist": _decimate((cols["theta_m"] - cols["theta_s"])[first]),
                "tau_s": _decimate(cols["tau_s"][first]),
            }
    elif task["test"] == "parallel":
        torsion = bool(task["torsion"])
        cols = parallel_test(sh, torsion, s)
        out["fit"] = asdict(fit_parallel(cols, torsion))
        if task.get("loop", False):
            out["loop"] = {"phi_b": _decimate(cols["phi_b"]), "m_b": _decimate(cols["m_b"])}
    else:
        raise CampaignError(f"unknown bench test {task['test']!r}: 'series' or 'parallel'")
    return out
