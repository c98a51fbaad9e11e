"""Confidence intervals of a bench model's fitted parameters, from the Fisher information.

Method (said in the result): the replayed main output's sensitivity to every fitted parameter
(Jacobian ``J`` by central differences of the replay, :func:`.replay.replay`, step
:data:`REL_STEP` of the value), the Gauss-Newton Fisher information ``J^T J / sigma^2`` on the
teaching samples with ``sigma^2`` the teaching residual's variance, and the covariance
``sigma^2 tau (J^T J)^-1`` inflated by the residual's integrated autocorrelation time ``tau``
(:func:`.residuals.tau_int`: a coloured residual carries fewer independent samples). Intervals
are normal, 95 % (``value +- 1.96 sd``), clipped to the parameter's bounds where it has them.

The replay's own error (``sd_method``): the replay drives the model with the recorded angles
smoothed and differentiated by Savitzky-Golay filters (:func:`.replay_inputs.prepare_inputs`), which
round off what the physical motion does (an acceleration estimate through a 31 ms window loses
a few % at 10 Hz) - the fitted parameters absorb that error (a link inertia a few sd off on
noise-free synthetic records). It is estimated by halving every window: the parameters' shift
``(J^T J)^-1 J^T (yhat_half - yhat)`` (one more replay, the same Jacobian) times
:data:`RICHARDSON` (the filters' error falls at least as the window squared, so the full
window's error is at most 4/3 of the shift), and it is added in quadrature to the Fisher sd
(a correction not applied, counted with an uncertainty of its own size).

What they do not hold: the error of a law that only approximates the truth (a fixed element
grid, a polynomial for a measured curve) - the inflation by ``tau`` widens them by what such a
misfit leaves correlated, not by its bias. Parameters whose Jacobian column is zero (an element
that never slips) get an infinite interval (``sd`` None in the JSON).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import replay, replay_inputs
from fsarm_sim.discrepancy.benchmodel import BenchModel
from fsarm_sim.discrepancy.residuals import tau_int
from fsarm_sim.plant.effects import registry

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

LEVEL = 0.95
Z = 1.959963984540054  # two-sided 95 % normal quantile
REL_STEP = 1e-3
ABS_STEP = 1e-7
FIXED = frozenset({"x_ref_rad"})  # reference values of a law, not fitted
RICHARDSON = 4.0 / 3.0  # full-window error / (full - half window) shift, at most (docstring)
METHOD = (
    "Fisher information: Jacobian of the replayed main output by central differences of the "
    "replay, sigma^2 from the teaching residual, covariance sigma^2 tau (J^T J)^-1 inflated by "
    "the residual's integrated autocorrelation time tau; the replay's smoothing / "
    "differentiation error (parameter shift with every filter window halved, x 4/3) added in "
    "quadrature; 95 % normal intervals"
)


def nominal_keys(model: BenchModel, multi_bend: bool) -> list[str]:
    """The nominal parameters the diagnosis refits (:func:`.candidate_structure.n_params`)."""
    if model.setup == "series_bench":
        keys = ["k_pos", "k_neg"] + (["s_pos", "s_neg"] if multi_bend else [])
        return keys + (["j_load"] if model.inertia_load else [])
    return ["kb", "j_link"]


Getter = Callable[[BenchModel], float]
Setter = Callable[[BenchModel, float], None]


def _slots(
    model: BenchModel, multi_bend: bool
) -> list[tuple[str, Getter, Setter, tuple[float, float]]]:
    """(name, get, set, bounds) of every fitted parameter of ``model``."""
    out: list[tuple[str, Getter, Setter, tuple[float, float]]] = []
    for k in nominal_keys(model, multi_bend):
        if k not in model.nominal:
            continue
        lo = 0.0 if k.startswith(("k_", "kb", "j_")) else -math.inf

        def get_n(m: BenchModel, k: str = k) -> float:
            return float(m.nominal[k])

        def set_n(m: BenchModel, v: float, k: str = k) -> None:
            m.nominal[k] = v

        out.append((f"nominal.{k}", get_n, set_n, (lo, math.inf)))
    for i, e in enumerate(model.effects):
        try:
            bounds = {
                p.name: (p.lower, p.upper) for p in registry.get(e.name).variant(e.variant).params
            }
        except (KeyError, ValueError):
            bounds = {}
        for key, val in e.params.items():
            if key in FIXED:
                continue
            b = bounds.get(key, (-math.inf, math.inf))
            if isinstance(val, list):
                for j in range(len(val)):

                    def get_l(m: BenchModel, i: int = i, key: str = key, j: int = j) -> float:
                        return float(m.effects[i].params[key][j])

                    def set_l(
                        m: BenchModel, v: float, i: int = i, key: str = key, j: int = j
                    ) -> None:
                        lst = list(m.effects[i].params[key])
                        lst[j] = v
                        m.effects[i].params[key] = lst

                    out.append((f"{e.label}.{key}[{j}]", get_l, set_l, b))
            elif isinstance(val, int | float):

                def get_s(m: BenchModel, i: int = i, key: str = key) -> float:
                    return float(m.effects[i].params[key])

                def set_s(m: BenchModel, v: float, i: int = i, key: str = key) -> None:
                    m.effects[i].params[key] = v

                out.append((f"{e.label}.{key}", get_s, set_s, b))
    return out


def intervals(
    model: BenchModel,
    inp: replay_inputs.ReplayInputs,
    rows: BoolArray,
    yhat: FloatArray,
    multi_bend: bool = False,
    half: replay_inputs.ReplayInputs | None = None,
) -> dict[str, Any]:
    """``{"method", "level", "parameters": [{name, value, sd, sd_fisher, sd_method, lower,
    upper}, ...]}`` of every fitted parameter of ``model`` (module docstring); ``rows``: the
    teaching samples; ``half``: the record's inputs prepared with every filter window halved
    (None: no replay-error term)."""
    slots = _slots(model, multi_bend)
    r = (inp.y - yhat)[rows]
    sigma2 = float(np.mean(r * r))
    tau = tau_int(r)
    cols = []
    for _, get, put, _b in slots:
        v = get(model)
        dv = max(REL_STEP * abs(v), ABS_STEP)
        plus, minus = model.copy(), model.copy()
        put(plus, v + dv)
        put(minus, v - dv)
        yp = replay.replay(plus, inp)["y"][rows]
        ym = replay.replay(minus, inp)["y"][rows]
        col = (yp - ym) / (2 * dv)
        cols.append(np.where(np.isfinite(col), col, 0.0))
    params = []
    if cols:
        j = np.column_stack(cols)
        scale = np.sqrt(np.sum(j * j, axis=0))
        ok = scale > 0
        cov = np.full((len(slots), len(slots)), math.inf)
        shift = np.zeros(len(slots))
        if ok.any():
            js = j[:, ok] / scale[ok]
            inv = np.linalg.pinv(js.T @ js) / np.outer(scale[ok], scale[ok])
            cov[np.ix_(ok, ok)] = inv * sigma2 * tau
            if half is not None:
                dy = (yhat - replay.replay(model, half)["y"])[rows]
                if np.all(np.isfinite(dy)):
                    shift[ok] = inv @ (j[:, ok].T @ dy)
        for i, (name, get, _p, (lo, hi)) in enumerate(slots):
            v = get(model)
            sd_f = math.sqrt(cov[i, i]) if math.isfinite(cov[i, i]) and cov[i, i] >= 0 else math.inf
            sd_m = RICHARDSON * abs(float(shift[i]))
            sd = math.hypot(sd_f, sd_m)
            params.append(
                {
                    "name": name,
                    "value": v,
                    "sd_fisher": sd_f,
                    "sd_method": sd_m,
                    "sd": sd,
                    "lower": max(v - Z * sd, lo),
                    "upper": min(v + Z * sd, hi),
                }
            )
    return {
        "method": METHOD,
        "level": LEVEL,
        "tau_int": tau,
        "parameters": params,
    }


def interval_lines(ci: dict[str, Any] | None) -> list[str]:
    """The print-out of the fitted parameters' confidence intervals."""
    if not ci or not ci.get("parameters"):
        return []
    out = [
        f"fitted parameters, {100 * ci['level']:.0f} % intervals ({ci['method'].split(':')[0]}):"
    ]
    for p in ci["parameters"]:
        out.append(f"  {p['name']:<44} {p['value']:.5g}  [{p['lower']:.5g}, {p['upper']:.5g}]")
    return out
