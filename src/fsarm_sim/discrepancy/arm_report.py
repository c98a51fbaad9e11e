"""Output of an arm diagnosis: the JSON result, the model file, the plots and the CLI print-out.

JSON keys as for the benches (:mod:`.report`): ``named_effects``, ``gap_before``, ``gap_after``
(held-out NRMSE of ``q3``, the arm's main channel, as fractions), ``gap_catalogue``,
``nothing_missing``, ``verdict``, ``confidence`` (per added effect: runner-up, held-out BIC
margin, probability, look-alike flag), ``steps`` (every candidate's scores; ``mse_teach`` /
``mse_held`` are the weighted MSEs, noise-variance units), ``fitted_parameters``,
``nominal_refit``, ``unused_columns`` (columns of the record the diagnosis does not read),
``undeclared_columns`` (of those, the ones neither the setup nor the sidecar defines),
``transmission`` (joint 3's, from the sidecar), ``noise_floor`` (per channel), ``nrmse`` (per channel q3, theta_m, q2, twist:
catalogue / nominal / final), ``gap_over_noise`` (held-out residual RMS in noise-floor units,
channel average, before / after), ``bic``, ``signatures`` (q3 and twist residuals, before /
after), ``runtime_s``, ``simulations``, ``model_file``, ``method``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import arm as A
from fsarm_sim.discrepancy import arm_modelfile as MF
from fsarm_sim.discrepancy.report import (
    confidence,
    confidence_line,
    json_clean,
    plot_bic_steps,
    plot_channel_nrmse,
)
from fsarm_sim.discrepancy.residuals import bic, effective_n, nrmse
from fsarm_sim.discrepancy.selection import BIC_THRESHOLD, MIN_EXPLAINED, MIN_GAIN
from fsarm_sim.outputs import SafeWriter

CHANNELS = ("q3", "theta_m", "q2", "twist")


def _channel(diag: A.ArmDiagnosis, fit: A.ArmFit, ch: str) -> tuple[np.ndarray, np.ndarray]:
    ctx = diag.ctx
    if ch in A.RAW:
        return ctx.raw[ch], fit.raw[ch]
    return ctx.y[ch], fit.pred[ch]


def channel_nrmse(diag: A.ArmDiagnosis) -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {}
    for ch in CHANNELS:
        out[ch] = {}
        for name, fit in (
            ("catalogue", diag.catalogue),
            ("nominal", diag.nominal),
            ("final", diag.final),
        ):
            y, yhat = _channel(diag, fit, ch)
            out[ch][name] = nrmse(y, yhat, diag.ctx.held)
    return out


def _params(m: A.ArmModel) -> dict[str, Any]:
    return {"nominal": m.nominal(), "effects": [e.as_dict() for e in m.effects()]}


def result_dict(diag: A.ArmDiagnosis, model_file: Path | None = None) -> dict[str, Any]:
    ctx = diag.ctx
    ds = diag.dataset
    conf = confidence(diag.steps)
    r = np.concatenate([(ctx.y[c] - diag.final.pred[c]) / ctx.sigma[c] for c in A.BASIS])
    n_h = effective_n(r, np.tile(ctx.held, len(A.BASIS)))
    res: dict[str, Any] = {
        "dataset": str(ds.path),
        "setup": "arm",
        "scenario": ds.sidecar.get("scenario"),
        "samples": ds.n,
        "rate_hz": 1.0 / ctx.run.h,
        "duration_s": float(ctx.run.t[-1]),
        "main_channel": A.MAIN,
        "transmission": ctx.run.transmission,
        "unused_columns": list(ds.unused_columns),
        "undeclared_columns": list(ds.undeclared_columns),
        "named_effects": list(diag.named),
        "gap_before": diag.gap_before,
        "gap_after": diag.gap_after,
        "gap_catalogue": nrmse(ctx.y[A.MAIN], diag.catalogue.pred[A.MAIN], ctx.held),
        "gap_over_noise": {
            "catalogue": diag.gap_over_noise(diag.catalogue),
            "before": diag.gap_over_noise(diag.nominal),
            "after": diag.gap_over_noise(diag.final),
        },
        "nothing_missing": not diag.named,
        "verdict": diag.verdict,
        "confidence": conf,
        "steps": [s.as_dict() for s in diag.steps],
        "fitted_parameters": _params(diag.final.model),
        "nominal_refit": {
            "refit_parameters": A.nominal_keys(ctx),
            "catalogue": diag.catalogue.model.nominal(),
            "refit": diag.nominal.model.nominal(),
            "final": diag.final.model.nominal(),
        },
        "noise_floor": dict(ctx.sigma),
        "nrmse": channel_nrmse(diag),
        "bic": {
            "n_eff_held": n_h,
            "nominal": bic(diag.nominal.w(ctx), n_h, diag.nominal.k),
            "final": bic(diag.final.w(ctx), n_h, diag.final.k),
            "k_nominal": diag.nominal.k,
            "k_final": diag.final.k,
        },
        "signatures": {
            "before": {
                "q3": A.residual_signature(diag, diag.nominal, "q3"),
                "twist": A.residual_signature(diag, diag.nominal, "twist"),
            },
            "after": {
                "q3": A.residual_signature(diag, diag.final, "q3"),
                "twist": A.residual_signature(diag, diag.final, "twist"),
            },
        },
        "runtime_s": diag.runtime_s,
        "simulations": diag.extras.get("simulations"),
        "reference": diag.extras.get("reference"),
        "model_file": str(model_file) if model_file is not None else None,
        "method": {
            "replay": "closed loop: the project's simulator (native callbacks) with the recorded "
            "references and the run's controller (stated shaft and payload)",
            "channels": "q3, twist = theta_m - i_G2 q3, q2; residuals weighted by each channel's "
            "noise floor",
            "split": "12 contiguous blocks, every third held out (first 1 % of samples in neither)",
            "bic": "n_eff ln(W) + k ln(n_eff), W = channel-mean of MSE_c / sigma_c^2, n_eff from "
            "the weighted residual's autocorrelation time",
            "bic_threshold": BIC_THRESHOLD,
            "min_heldout_gain": MIN_GAIN,
            "min_explained_fraction_of_noise_variance": MIN_EXPLAINED,
            "nrmse": "RMSE / (max - min) of the measured channel on the held-out samples",
        },
    }
    return dict(json_clean(res))


def write_json(diag: A.ArmDiagnosis, path: str | Path, model_file: Path | None = None) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(result_dict(diag, model_file), indent=2) + "\n", "utf-8")
    return p


def write_model(diag: A.ArmDiagnosis, path: str | Path) -> Path:
    return MF.save_arm_model(diag.ctx.run, diag.final.model, path)


def write_plots(diag: A.ArmDiagnosis, folder: str | Path) -> list[Path]:
    """Time series before/after (held-out window), twist-q3 loops, NRMSE per channel, BIC."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    ctx = diag.ctx
    t = ctx.run.t
    files: list[Path] = []
    idx = np.flatnonzero(ctx.held)
    i0 = int(idx[0]) if idx.size else 0
    i1 = min(t.size, i0 + round(4.0 / ctx.run.h))
    sl = slice(i0, i1)
    nom, fin = diag.nominal, diag.final

    fig, ax = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    ax[0].plot(t[sl], ctx.y["q3"][sl], color="k", lw=1, label="q3 measured")
    ax[0].plot(t[sl], ctx.ds.columns["q3_ref"][sl], color="grey", lw=0.8, ls=":", label="q3_ref")
    ax[0].set_ylabel("q3 [rad]")
    ax[0].set_title(f"{ctx.ds.path.name}: held-out window")
    ax[0].legend(loc="upper right", fontsize=8)
    for a, ch, unit in ((ax[1], "q3", "rad"), (ax[2], "twist", "rad"), (ax[3], "q2", "rad")):
        a.plot(t[sl], (ctx.y[ch] - nom.pred[ch])[sl], color="tab:red", lw=0.8, label="before")
        a.plot(t[sl], (ctx.y[ch] - fin.pred[ch])[sl], color="tab:blue", lw=0.8, label="after")
        for k in (-2, 2):
            a.axhline(k * ctx.sigma[ch], color="grey", ls=":", lw=0.8)
        a.set_ylabel(f"{ch} residual [{unit}]")
        a.legend(loc="upper right", fontsize=8)
    ax[3].set_xlabel("t [s]")
    fig.tight_layout()
    files.append(out / "timeseries.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    step = max(1, t.size // 8000)
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    for a, fit, title in ((axs[0], nom, "before (nominal refit)"), (axs[1], fin, "after")):
        a.plot(
            ctx.y["q3"][::step], ctx.y["twist"][::step], ".", ms=1.5, color="k", label="measured"
        )
        a.plot(
            fit.pred["q3"][::step],
            fit.pred["twist"][::step],
            ".",
            ms=1.5,
            color="tab:blue" if fit is fin else "tab:red",
            label="replay",
        )
        a.set_title(title)
        a.set_xlabel("q3 [rad]")
        a.legend(loc="upper left", fontsize=8, markerscale=6)
    axs[0].set_ylabel("shaft twist theta_m - i_G2 q3 [rad] (~ shaft torque / K)")
    fig.tight_layout()
    files.append(out / "loops.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    files.append(plot_channel_nrmse(channel_nrmse(diag), out / "nrmse.png", log=True))

    if diag.steps:
        files.append(plot_bic_steps(diag.steps, out / "bic.png"))
    return files


def write_report(diag: A.ArmDiagnosis, folder: str | Path) -> dict[str, Path]:
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    model = write_model(diag, out / "model.json")
    res = write_json(diag, out / "result.json", model)
    plots = write_plots(diag, out)
    return {"result": res, "model": model, **{p.stem: p for p in plots}}


def run_cli(
    ds: Any,
    console: Any,
    *,
    json_file: Path | None,
    report: Path | None,
    model_file: Path | None,
    max_effects: int,
    writes: SafeWriter | None = None,
) -> A.ArmDiagnosis:
    """``fsarm diagnose`` for an arm record: diagnose, print the steps, write what was asked
    (through ``writes``: a failed write goes to a rescue folder instead of being lost)."""
    from rich.markup import escape
    from rich.table import Table

    diag = A.diagnose_arm(ds, max_effects=max_effects)
    for st in diag.steps:
        t = Table(title=escape(f"step {st.index}: {st.reason}"), title_justify="left")
        for col in (
            "candidate",
            "k",
            "held-out W",
            "ΔBIC teach",
            "ΔBIC held-out",
            "gain %",
            "earns",
        ):
            t.add_column(col, justify="right" if col != "candidate" else "left")
        for sc in st.scores:
            t.add_row(
                escape(sc.label),
                str(sc.k),
                f"{sc.mse_held:.4g}",
                f"{sc.d_bic_teach:+.1f}",
                f"{sc.d_bic_held:+.1f}",
                f"{100 * sc.gain_held:.1f}",
                "yes" if sc.earns_place else "no",
            )
        console.print(t)
        line = confidence_line(st)
        if line:
            console.print(line, markup=False)
    console.print(f"nominal refit alone: {diag.nominal.model.nominal()}", markup=False)
    console.print(f"final nominal parameters: {diag.final.model.nominal()}", markup=False)
    console.print(f"named effects: {diag.named or 'none'}", markup=False)
    for e in diag.final.model.effects():
        console.print(f"  {e.label}: {e.params}", markup=False)
    console.print(
        f"held-out NRMSE of q3: nominal {100 * diag.gap_before:.4f} % -> final "
        f"{100 * diag.gap_after:.4f} %; residual / noise floor {diag.gap_over_noise(diag.nominal):.3g}"
        f" -> {diag.gap_over_noise(diag.final):.3g}",
        markup=False,
    )
    console.print(diag.verdict, markup=False)
    for line in ds.column_notes():
        console.print(line, markup=False)
    console.print(
        f"runtime {diag.runtime_s:.1f} s ({diag.extras.get('simulations')} closed-loop runs)",
        markup=False,
    )
    w = writes if writes is not None else SafeWriter()
    written: Path | None = None
    if model_file is not None:
        written = w.write(model_file, lambda p: write_model(diag, p), "the final model (--model)")
        if written is not None:
            console.print(f"model: {written}", markup=False)
    if report is not None:
        files = w.write(
            report, lambda d: write_report(diag, d), "the report (--report)", folder=True
        )
        if files is not None:
            written = written or files["model"]
            where = files["result"].parent
            console.print(
                f"report: {where} ({', '.join(p.name for p in files.values())})", markup=False
            )
    if json_file is not None:
        res = w.write(json_file, lambda p: write_json(diag, p, written), "the result (--json)")
        if res is not None:
            console.print(f"result: {res}", markup=False)
    if writes is None:
        w.finish()
    if written is not None:
        console.print(
            "load the final model: fsarm_sim.discrepancy.arm_modelfile.load_arm_config(MODEL) -> SimConfig",
            markup=False,
        )
    return diag
