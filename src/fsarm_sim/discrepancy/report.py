"""Diagnosis output for every setup: the JSON result, the final model file, the plots and the
``fsarm diagnose`` print-out.

JSON keys (``specs/measured-data.md`` names first), common to all setups: ``named_effects``,
``gap_before``, ``gap_after`` (held-out NRMSE of the setup's main channel, fractions),
``gap_catalogue`` (nominal model as stated, no refit), ``unexplained`` (the final model leaves
the held-out residual clearly above the noise floor: what lies above the noise at least as large
as the noise), ``nothing_missing`` (no effect named *and* not ``unexplained``),
``residual_signature`` (what the final model leaves: spectral lines, drift, dependence on a
signal, where it concentrates - :mod:`.unexplained`; the arm's per channel under ``channels``,
:mod:`.arm_expert`), ``confidence_intervals`` (every fitted parameter's 95 % interval and the
method - :mod:`.uncertainty`, the arm's :mod:`.arm_expert`), ``verdict``,
``confidence`` (per added effect: runner-up, BIC margin, probability, look-alike flag), ``steps``
(every candidate's scores per step; ``mse_teach`` / ``mse_held`` in the setup's cost units; a
joint step has ``joint`` true and its ``added_effects``),
``fitted_parameters`` (nominal + effects), ``nominal_refit``, ``noise_floor``, ``nrmse`` (per
channel: catalogue / nominal / final), ``bic``, ``signatures`` (residual before / after),
``unused_columns`` (columns of the record the diagnosis does not read), ``undeclared_columns``
(of those, the ones neither the setup nor the sidecar defines), ``runtime_s``, ``model_file``,
``method`` (split, BIC, thresholds).

Benches (:mod:`.bench_setup`) add ``load``, ``noise_floor_nrmse`` (the estimated noise floor in
NRMSE units: a perfect model's gap), ``gap_excess_before``, ``gap_excess_after`` (the gaps above
the noise floor, ``sqrt(max(gap^2 - floor^2, 0))``), ``noise_floor_inputs_nrmse`` (the output
error that the recorded inputs' own errors - encoder quantisation, noise - cause through the
final model, estimated by re-measuring them; reported, not used for naming),
``noise_floor_total_nrmse`` (both floors together) and ``residual_over_noise`` (held-out residual
RMS / noise floor, nominal and final). The arm (:mod:`.arm`) adds ``scenario``, ``transmission``
(joint 3's), ``gap_over_noise`` (held-out residual RMS in noise-floor units, channel average),
``simulations`` and ``reference``; its ``mse_*`` are the noise-weighted MSEs.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import selection
from fsarm_sim.discrepancy.core import Diagnosis
from fsarm_sim.discrepancy.residuals import bic, effective_n
from fsarm_sim.discrepancy.selection import Step
from fsarm_sim.outputs import SafeWriter


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


UNEXPLAINED = math.sqrt(2.0)  # a setup without its own test: held-out residual RMS / noise


def unexplained(diag: Diagnosis[Any]) -> bool:
    """True when the final model leaves the residual clearly above the noise floor: the setup's
    own test (``extras["unexplained"]``, e.g. the benches', which counts the recorded inputs'
    errors too), else a held-out residual RMS above :data:`UNEXPLAINED` x the noise floor (what
    lies above the noise at least as large as the noise)."""
    if "unexplained" in diag.extras:
        return bool(diag.extras["unexplained"])
    nv = diag.setup.noise_var
    return bool(nv > 0 and diag.gap_over_noise(diag.final) > UNEXPLAINED)


def result_dict(diag: Diagnosis[Any], model_file: Path | None = None) -> dict[str, Any]:
    """The JSON result of a diagnosis (module docstring)."""
    setup = diag.setup
    ds = diag.dataset
    parts = setup.report(diag)
    r, _, held = setup.residual(diag.final)
    n_h = effective_n(r, held)
    res: dict[str, Any] = {
        "dataset": str(ds.path),
        **parts.head,
        "unused_columns": list(ds.unused_columns),
        "undeclared_columns": list(ds.undeclared_columns),
        "named_effects": list(diag.named),
        "stand_ins": list(diag.extras.get("stand_ins", [])),
        "gap_before": diag.gap_before,
        "gap_after": diag.gap_after,
        **parts.gaps,
        "unexplained": unexplained(diag),
        "nothing_missing": not diag.named and not unexplained(diag),
        "residual_signature": diag.extras.get("residual_signature"),
        "verdict": diag.verdict,
        "confidence": confidence(diag.steps),
        "steps": [s.as_dict() for s in diag.steps],
        "fitted_parameters": setup.parameters(diag.final.model),
        "confidence_intervals": diag.extras.get("confidence_intervals"),
        "realness": diag.extras.get("realness"),
        "nominal_refit": parts.nominal_refit,
        "noise_floor": parts.noise_floor,
        "nrmse": parts.nrmse,
        "bic": {
            "n_eff_held": n_h,
            "nominal": bic(setup.cost(diag.nominal)[1], n_h, diag.nominal.k),
            "final": bic(setup.cost(diag.final)[1], n_h, diag.final.k),
            "k_nominal": diag.nominal.k,
            "k_final": diag.final.k,
        },
        "signatures": parts.signatures,
        "runtime_s": diag.runtime_s,
        **parts.tail,
        "model_file": str(model_file) if model_file is not None else None,
        "method": {
            **parts.method,
            "split": "12 contiguous blocks, every third held out (first 1 % of samples in neither)",
            "bic_threshold": selection.BIC_THRESHOLD,
            "min_heldout_gain": selection.MIN_GAIN,
            "min_explained_fraction_of_noise_variance": selection.MIN_EXPLAINED,
            "extra_effect_min_explained_fraction_of_noise_variance": selection.MIN_EXPLAINED_EXTRA,
            "extra_effect_min_share_of_named_effects_explained": selection.MIN_SHARE_EXTRA,
            "nrmse": "RMSE / (max - min) of the measured channel on the held-out samples",
        },
    }
    return dict(json_clean(res))


def write_json(diag: Diagnosis[Any], path: str | Path, model_file: Path | None = None) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(result_dict(diag, model_file), indent=2) + "\n", "utf-8")
    return p


def write_model(diag: Diagnosis[Any], path: str | Path) -> Path:
    """The final model file (the setup's format)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    return diag.setup.save_model(diag.final.model, p)


def write_plots(diag: Diagnosis[Any], folder: str | Path) -> list[Path]:
    """The setup's plots (time series, loops, NRMSE per channel) and the candidates' BIC per
    step."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    files = diag.setup.plots(diag, out)
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
        a.axvline(-selection.BIC_THRESHOLD, color="k", ls=":", lw=0.8)
        a.set_xscale("symlog", linthresh=10)
        a.invert_yaxis()
        a.set_title(f"step {st.index}: added {st.added or 'nothing'}", fontsize=9)
        a.set_xlabel("held-out BIC change")
        a.tick_params(axis="y", labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


REPORT_FILES = {  # the files write_report may put in the folder
    "result.json": "the result",
    "model.json": "the final model",
    "timeseries.png": "the time-series plot",
    "loops.png": "the loop plot",
    "nrmse.png": "the NRMSE plot",
    "bic.png": "the BIC plot",
    "residual_signature.png": "the plot of what the final model leaves",
}


def write_report(diag: Diagnosis[Any], folder: str | Path) -> dict[str, Path]:
    """Everything into one folder: result.json, model.json and the plots."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    model = write_model(diag, out / "model.json")
    res = write_json(diag, out / "result.json", model)
    plots = write_plots(diag, out)
    return {"result": res, "model": model, **{p.stem: p for p in plots}}


def print_diagnosis(diag: Diagnosis[Any], console: Any) -> None:
    """The steps (one table each, with the confidence of an added effect) and the setup's
    summary lines."""
    from rich.markup import escape
    from rich.table import Table

    head, cell = diag.setup.score_cell
    for st in diag.steps:
        t = Table(title=escape(f"step {st.index}: {st.reason}"), title_justify="left")
        for col in ("candidate", "k", head, "ΔBIC teach", "ΔBIC held-out", "gain %", "earns place"):
            t.add_column(col, justify="right" if col != "candidate" else "left")
        for sc in st.scores:
            t.add_row(
                escape(sc.label),
                str(sc.k),
                cell(sc),
                f"{sc.d_bic_teach:+.1f}",
                f"{sc.d_bic_held:+.1f}",
                f"{100 * sc.gain_held:.1f}",
                "yes" if sc.earns_place else "no",
            )
        console.print(t)
        line = confidence_line(st)
        if line:
            console.print(line, markup=False)
    for line in diag.setup.summary_lines(diag):
        console.print(line, markup=False)


def emit(
    diag: Diagnosis[Any],
    console: Any,
    *,
    json_file: Path | None = None,
    report: Path | None = None,
    model_file: Path | None = None,
    writes: SafeWriter | None = None,
) -> None:
    """``fsarm diagnose``'s output: print the diagnosis and write what was asked (through
    ``writes``: a failed write goes to a rescue folder instead of being lost)."""
    print_diagnosis(diag, console)
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
        console.print(diag.setup.load_hint, markup=False)
