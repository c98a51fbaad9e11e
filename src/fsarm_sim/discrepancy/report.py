"""Diagnosis output: the JSON result, the final model file and the plots.

JSON keys (``specs/measured-data.md`` names first): ``named_effects``, ``gap_before``,
``gap_after`` (held-out NRMSE of the main output channel, fractions), ``noise_floor_nrmse`` (the
estimated noise floor in the same units: a perfect model's gap), ``gap_excess_before``,
``gap_excess_after`` (the gaps above the noise floor, ``sqrt(max(gap^2 - floor^2, 0))``),
``noise_floor_inputs_nrmse`` (the output error that the recorded inputs' own errors - encoder
quantisation, noise - cause through the final model, estimated by re-measuring them; reported,
not used for naming) and ``noise_floor_total_nrmse`` (both floors together),
``residual_over_noise`` (held-out residual RMS / noise floor, nominal and final), ``gap_catalogue``
(nominal model with the catalogue's parameters, no refit), ``nothing_missing``, ``verdict``,
``confidence`` (per added effect: runner-up, BIC margin, probability, look-alike flag),
``steps`` (every candidate's scores per step), ``fitted_parameters`` (nominal + effects),
``nominal_refit`` (catalogue vs refit nominal parameters), ``noise_floor``, ``nrmse`` (per
channel: catalogue / nominal / final), ``bic``, ``signatures`` (residual before / after),
``runtime_s``, ``model_file``, ``method`` (thresholds).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import replay as R
from fsarm_sim.discrepancy.benchmodel import BenchModel, save_model
from fsarm_sim.discrepancy.residuals import bic, effective_n, noise_floor, nrmse
from fsarm_sim.discrepancy.selection import (
    BIC_THRESHOLD,
    MIN_EXPLAINED,
    MIN_EXPLAINED_EXTRA,
    MIN_GAIN,
    MIN_SHARE_EXTRA,
    Diagnosis,
    Step,
    residual_signature,
)


def json_clean(x: Any) -> Any:
    """JSON-safe: numpy scalars to floats, non-finite to None, recursively."""
    if isinstance(x, dict):
        return {str(k): json_clean(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [json_clean(v) for v in x]
    if isinstance(x, np.ndarray):
        return [json_clean(v) for v in x.tolist()]
    if isinstance(x, bool | np.bool_):
        return bool(x)
    if isinstance(x, int | np.integer):
        return int(x)
    if isinstance(x, float | np.floating):
        v = float(x)
        return v if math.isfinite(v) else None
    return x


def _params(model: BenchModel) -> dict[str, Any]:
    return {
        "nominal": dict(model.nominal),
        "effects": [e.as_dict() for e in model.effects],
    }


def _over_noise(mse: float, sigma: float) -> float:
    return math.sqrt(mse) / sigma if sigma > 0 else math.inf


def channel_nrmse(diag: Diagnosis) -> dict[str, dict[str, float]]:
    """Held-out NRMSE per measured channel for the catalogue, refit nominal and final models."""
    ctx = diag.ctx
    inp = ctx.inp
    main = diag.dataset.output_column
    out: dict[str, dict[str, float]] = {main: {}}
    for name, fit in (
        ("catalogue", diag.catalogue),
        ("nominal", diag.nominal),
        ("final", diag.final),
    ):
        out[main][name] = nrmse(inp.y, fit.yhat, ctx.held)
    if inp.inertia_load and inp.theta_s is not None:
        out["theta_s"] = {}
        for name, fit in (
            ("catalogue", diag.catalogue),
            ("nominal", diag.nominal),
            ("final", diag.final),
        ):
            th = R.replay(fit.model, inp)["theta_s"]
            out["theta_s"][name] = nrmse(inp.theta_s, th, ctx.held)
    return out


def confidence(steps: list[Step]) -> list[dict[str, Any]]:
    """How sure each added effect is against its runner-up (held-out BIC margin)."""
    return [
        {
            "step": s.index,
            "added": s.added,
            "runner_up": s.runner_up,
            "bic_margin": s.bic_margin,
            "probability": s.probability,
            "look_alike": s.look_alike,
        }
        for s in steps
        if s.added is not None
    ]


def confidence_line(st: Step) -> str | None:
    """One printable line on an added effect's confidence, or None."""
    if st.added is None or st.bic_margin is None:
        return None
    return (
        f"  confidence: {st.added} over {st.runner_up} by a held-out BIC margin of "
        f"{st.bic_margin:.1f} (p = {st.probability:.3g})"
        + ("  [look-alikes]" if st.look_alike else "")
    )


def result_dict(diag: Diagnosis, model_file: Path | None = None) -> dict[str, Any]:
    ctx = diag.ctx
    inp = ctx.inp
    ds = diag.dataset
    conf = confidence(diag.steps)
    n_h = effective_n(inp.y - diag.final.yhat, ctx.held)
    res: dict[str, Any] = {
        "dataset": str(ds.path),
        "setup": ds.setup,
        "load": "inertia"
        if inp.inertia_load
        else ("blocked" if ds.setup == "series_bench" else None),
        "samples": inp.n,
        "rate_hz": 1.0 / inp.h,
        "duration_s": float(inp.t[-1] - inp.t[0]),
        "main_channel": ds.output_column,
        "unused_columns": list(ds.unused_columns),
        "undeclared_columns": list(ds.undeclared_columns),
        "named_effects": list(diag.named),
        "gap_before": diag.gap_before,
        "gap_after": diag.gap_after,
        "noise_floor_nrmse": diag.noise_floor_nrmse,
        "noise_floor_inputs_nrmse": diag.noise_floor_inputs_nrmse,
        "noise_floor_total_nrmse": diag.noise_floor_total_nrmse,
        "gap_excess_before": diag.gap_excess_before,
        "gap_excess_after": diag.gap_excess_after,
        "residual_over_noise": {
            "nominal": _over_noise(diag.nominal.mse_held, ctx.sigma_y),
            "final": _over_noise(diag.final.mse_held, ctx.sigma_y),
        },
        "gap_catalogue": nrmse(inp.y, diag.catalogue.yhat, ctx.held),
        "nothing_missing": not diag.named,
        "verdict": diag.verdict,
        "confidence": conf,
        "steps": [s.as_dict() for s in diag.steps],
        "fitted_parameters": _params(diag.final.model),
        "nominal_refit": {
            "catalogue": dict(diag.catalogue.model.nominal),
            "refit": dict(diag.nominal.model.nominal),
        },
        "noise_floor": {
            ds.output_column: ctx.sigma_y,
            f"{ds.input_column} (smoothed)": ctx.sigma_u,
            f"{ds.output_column} from the recorded inputs' errors (propagated)": diag.sigma_inputs,
            **(
                {"theta_s": noise_floor(inp.theta_s)}
                if inp.inertia_load and inp.theta_s is not None
                else {}
            ),
        },
        "nrmse": channel_nrmse(diag),
        "bic": {
            "n_eff_held": n_h,
            "nominal": bic(diag.nominal.mse_held, n_h, diag.nominal.k),
            "final": bic(diag.final.mse_held, n_h, diag.final.k),
            "k_nominal": diag.nominal.k,
            "k_final": diag.final.k,
        },
        "signatures": {
            "before": residual_signature(diag, diag.nominal),
            "after": residual_signature(diag, diag.final),
        },
        "runtime_s": diag.runtime_s,
        "model_file": str(model_file) if model_file is not None else None,
        "method": {
            "split": "12 contiguous blocks, every third held out (first 1 % of samples in neither)",
            "bic": "n_eff ln(MSE) + k ln(n_eff), n_eff from the residual autocorrelation time",
            "bic_threshold": BIC_THRESHOLD,
            "min_heldout_gain": MIN_GAIN,
            "min_explained_fraction_of_noise_variance": MIN_EXPLAINED,
            "extra_effect_min_explained_fraction_of_noise_variance": MIN_EXPLAINED_EXTRA,
            "extra_effect_min_share_of_named_effects_explained": MIN_SHARE_EXTRA,
            "noise_floor": "4th-difference MAD estimate of the main channel's white noise; "
            "noise_floor_nrmse = that / (max - min) of the channel on the held-out samples",
            "noise_floor_inputs": "the recorded angles re-measured (their encoder grid at a "
            "random phase, or their white noise) and the final model replayed on both: RMS "
            "output difference on the held-out samples",
            "nrmse": "RMSE / (max - min) of the measured channel on the held-out samples",
            "inertia_load_replay": f"segments of {R.SEGMENT_S:g} s started from the measured load state",
        },
    }
    return json_clean(res)


def write_json(diag: Diagnosis, path: str | Path, model_file: Path | None = None) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(result_dict(diag, model_file), indent=2) + "\n", "utf-8")
    return p


def write_model(diag: Diagnosis, path: str | Path) -> Path:
    return save_model(diag.final.model, path)


def write_plots(diag: Diagnosis, folder: str | Path) -> list[Path]:
    """time series and loops before/after, NRMSE per channel, candidate BIC per step."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    ctx = diag.ctx
    inp = ctx.inp
    ds = diag.dataset
    unit = "N·m"
    files: list[Path] = []

    # 1. time series in the first held-out block (a few seconds)
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
    files.append(out / "timeseries.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    # 2. torque-deflection loops
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
    ax[0].set_ylabel(f"{ds.output_column} [{unit}]")
    fig.tight_layout()
    files.append(out / "loops.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    # 3. NRMSE per channel
    ch = channel_nrmse(diag)
    files.append(
        plot_channel_nrmse(
            ch,
            out / "nrmse.png",
            floor=(diag.noise_floor_nrmse, f"noise floor ({ds.output_column})"),
        )
    )

    # 4. candidate BIC per step
    if diag.steps:
        files.append(plot_bic_steps(diag.steps, out / "bic.png"))
    return files


def plot_channel_nrmse(
    per_channel: dict[str, dict[str, float]],
    path: Path,
    *,
    floor: tuple[float, str] | None = None,
    log: bool = False,
) -> Path:
    """Held-out NRMSE per channel for the catalogue, nominal-refit and final models (bars),
    with an optional noise-floor line ``(value, label)``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    names = list(per_channel)
    w = 0.25
    for j, key in enumerate(("catalogue", "nominal", "final")):
        ax.bar(
            np.arange(len(names)) + (j - 1) * w,
            [100 * per_channel[c][key] for c in names],
            w,
            label=key,
        )
    if floor is not None:
        ax.axhline(100 * floor[0], color="k", ls=":", lw=1, label=floor[1])
    ax.set_xticks(np.arange(len(names)), names)
    if log:
        ax.set_yscale("log")
    ax.set_ylabel("held-out NRMSE [%]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_bic_steps(steps: list[Step], path: Path) -> Path:
    """One panel per step: each candidate's held-out BIC change, green where it earns its place."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, len(steps), figsize=(5 * len(steps), 4), squeeze=False)
    for a, st in zip(axs[0], steps, strict=True):
        a.barh(
            [sc.label for sc in st.scores],
            [sc.d_bic_held for sc in st.scores],
            color=["tab:green" if sc.earns_place else "tab:grey" for sc in st.scores],
        )
        a.axvline(-BIC_THRESHOLD, color="k", ls=":", lw=0.8)
        a.set_xscale("symlog", linthresh=10)
        a.invert_yaxis()
        a.set_title(f"step {st.index}: added {st.added or 'nothing'}", fontsize=9)
        a.set_xlabel("held-out BIC change")
        a.tick_params(axis="y", labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


REPORT_FILES = {  # the files write_report (and arm_report.write_report) may put in the folder
    "result.json": "the result",
    "model.json": "the final model",
    "timeseries.png": "the time-series plot",
    "loops.png": "the loop plot",
    "nrmse.png": "the NRMSE plot",
    "bic.png": "the BIC plot",
}


def write_report(diag: Diagnosis, folder: str | Path) -> dict[str, Path]:
    """Everything into one folder: result.json, model.json and the plots."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    model = write_model(diag, out / "model.json")
    res = write_json(diag, out / "result.json", model)
    plots = write_plots(diag, out)
    return {"result": res, "model": model, **{p.stem: p for p in plots}}
