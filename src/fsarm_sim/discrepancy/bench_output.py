"""A bench diagnosis's output besides the verdict: the residual signature of a fit
(:func:`residual_signature`), the held-out NRMSE per measured channel (:func:`channel_nrmse`) and
the plots (:func:`write_plots`). The bench as a setup is :mod:`.bench_setup`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import (
    candidate_structure,
    core,
    replay,
)
from fsarm_sim.discrepancy.report import plot_channel_nrmse
from fsarm_sim.discrepancy.residuals import (
    nrmse,
    nrmse_floor,
    signature,
)
from fsarm_sim.discrepancy.unexplained import Signals
from fsarm_sim.discrepancy.unexplained import plot as plot_signature


def residual_signature(
    diag: core.Diagnosis[candidate_structure.Fit], fit: candidate_structure.Fit
) -> dict[str, Any]:
    ctx = diag.ctx
    inp = ctx.inp
    s = inp.theta_s if inp.inertia_load and inp.theta_s is not None else inp.s
    x = inp.u - s
    xd = np.gradient(x, inp.h)
    return signature(inp.y, fit.yhat, x, xd, inp.phi, inp.t, ctx.sigma_y).as_dict()


def channel_nrmse(diag: core.Diagnosis[candidate_structure.Fit]) -> dict[str, dict[str, float]]:
    """Held-out NRMSE per measured channel for the catalogue, refit nominal and final models."""
    ctx = diag.ctx
    inp = ctx.inp
    main = diag.dataset.output_column
    fits = (("catalogue", diag.catalogue), ("nominal", diag.nominal), ("final", diag.final))
    out: dict[str, dict[str, float]] = {main: {}}
    for name, fit in fits:
        out[main][name] = nrmse(inp.y, fit.yhat, ctx.held)
    if inp.inertia_load and inp.theta_s is not None:
        out["theta_s"] = {}
        for name, fit in fits:
            th = replay.replay(fit.model, inp)["theta_s"]
            out["theta_s"][name] = nrmse(inp.theta_s, th, ctx.held)
    return out


def _plot_timeseries(
    plt: Any, diag: core.Diagnosis[candidate_structure.Fit], path: Path, unit: str
) -> Path:
    """The first held-out block (a few seconds): input, measured and replayed output,
    residuals before and after."""
    ctx = diag.ctx
    inp = ctx.inp
    ds = diag.dataset
    idx = np.flatnonzero(ctx.held)
    i0 = int(idx[0]) if idx.size else 0
    i1 = min(inp.n, i0 + round(4.0 / inp.h))
    sl = slice(i0, i1)
    fig, ax = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    ax[0].plot(inp.t[sl], inp.u[sl], color="k", lw=1)
    ax[0].set_ylabel(f"{ds.input_column} [rad]")
    ax[0].set_title(f"{ds.path.name}: held-out window")
    ax[1].plot(inp.t[sl], inp.y[sl], color="k", lw=1, label="measured")
    ax[1].plot(inp.t[sl], diag.nominal.yhat[sl], color="tab:red", lw=1, label="nominal (refit)")
    ax[1].plot(
        inp.t[sl], diag.final.yhat[sl], color="tab:blue", lw=1, ls="--", label=diag.final.label
    )
    ax[1].set_ylabel(f"{ds.output_column} [{unit}]")
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(
        inp.t[sl], (inp.y - diag.nominal.yhat)[sl], color="tab:red", lw=0.8, label="residual before"
    )
    ax[2].plot(
        inp.t[sl], (inp.y - diag.final.yhat)[sl], color="tab:blue", lw=0.8, label="residual after"
    )
    for k in (-2, 2):
        ax[2].axhline(k * ctx.sigma_y, color="grey", ls=":", lw=0.8)
    ax[2].set_ylabel(f"residual [{unit}]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_loops(
    plt: Any, diag: core.Diagnosis[candidate_structure.Fit], path: Path, unit: str
) -> Path:
    """Torque-deflection loops, measured and replayed, before and after."""
    inp = diag.ctx.inp
    s = inp.theta_s if inp.inertia_load and inp.theta_s is not None else inp.s
    x = inp.u - s
    step = max(1, inp.n // 8000)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    for a, fit, title in (
        (ax[0], diag.nominal, "before (nominal refit)"),
        (ax[1], diag.final, "after (final model)"),
    ):
        a.plot(x[::step], inp.y[::step], ".", ms=1.5, color="k", alpha=0.4, label="measured")
        a.plot(
            x[::step],
            fit.yhat[::step],
            ".",
            ms=1.5,
            color="tab:blue" if fit is diag.final else "tab:red",
            label="replay",
        )
        a.set_title(title)
        a.set_xlabel("deflection (input - output angle) [rad]")
        a.legend(loc="upper left", fontsize=8, markerscale=6)
    ax[0].set_ylabel(f"{diag.dataset.output_column} [{unit}]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_plots(
    diag: core.Diagnosis[candidate_structure.Fit],
    folder: str | Path,
    signal_set: Callable[[candidate_structure.Fit], Signals] | None = None,
) -> list[Path]:
    """Time series and loops before/after, NRMSE per channel; with ``signal_set`` (the bench
    setup's :meth:`~.bench_setup.BenchSetup.signal_set`) the residual signature too."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    ctx = diag.ctx
    unit = "N·m"
    files = [
        _plot_timeseries(plt, diag, out / "timeseries.png", unit),
        _plot_loops(plt, diag, out / "loops.png", unit),
    ]
    # what the final model leaves: spectrum, drift, dependence, where
    sig = diag.extras.get("residual_signature")
    if signal_set is not None and sig is not None:
        files.append(plot_signature(sig, signal_set(diag.final), out / "residual_signature.png"))
    floor = nrmse_floor(ctx.inp.y, ctx.sigma_y, ctx.held)
    files.append(
        plot_channel_nrmse(
            channel_nrmse(diag),
            out / "nrmse.png",
            floor=(floor, f"noise floor ({diag.dataset.output_column})"),
        )
    )
    return files
