"""Render a datasheet (:func:`fsarm_sim.studies.datasheet.datasheet`) as one page: a matplotlib
figure saved as PDF and PNG, and an HTML page with the PNG embedded and every number in a table
with its unit, source and band."""

from __future__ import annotations

import base64
import functools
import html
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fsarm_sim.studies.datasheet import series_of


def _fmt(v: float) -> str:
    return "n/a" if not math.isfinite(v) else f"{v:.4g}"


def _band_of(sheet: Mapping[str, Any], head: str, bends: list[float]) -> tuple[list[float], ...]:
    lo, hi = [], []
    for b in bends:
        e = sheet["numbers"].get(f"{head}.{b:g}deg", {})
        band = e.get("band")
        lo.append(band["p05"] if band else math.nan)
        hi.append(band["p95"] if band else math.nan)
    return lo, hi


def _panel(
    sheet: Mapping[str, Any],
    ax: Any,
    heads: list[tuple[str, str, list[float]]],
    title: str,
    unit: str,
) -> None:
    """One panel of the figure: each head's series vs bend, its band shaded where given."""
    for head, label, xs in heads:
        ys = series_of(sheet, head, xs)
        if all(not math.isfinite(y) for y in ys):
            continue
        style = "x--" if "(sim)" in label else "o-"  # simulated: dashed over the catalogue
        (line,) = ax.plot(xs, ys, style, label=label)
        lo, hi = _band_of(sheet, head, xs)
        if any(math.isfinite(v) for v in lo):
            ax.fill_between(xs, lo, hi, color=line.get_color(), alpha=0.2)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("bend angle [deg]", fontsize=8)
    ax.set_ylabel(unit, fontsize=8)
    ax.grid(alpha=0.3)
    ax.tick_params(labelsize=7)
    if ax.lines:
        ax.legend(fontsize=7)


def _tracking_bars(ax: Any, sheet: Mapping[str, Any]) -> None:
    """The last panel: q3's tracking RMSE per run (with its band as error bars when given)."""
    runs = [k for k in sheet["numbers"] if k.startswith("track.") and k.endswith(".q3_rmse_deg")]
    if runs:
        labels = [k.split(".")[1] + "\n" + k.split(".")[2] for k in runs]
        vals = [sheet["numbers"][k]["value"] for k in runs]
        bands = [sheet["numbers"][k].get("band") for k in runs]
        err = None
        if all(b is not None for b in bands):
            err = [
                [max(v - b["p05"], 0.0) for v, b in zip(vals, bands, strict=True)],
                [max(b["p95"] - v, 0.0) for v, b in zip(vals, bands, strict=True)],
            ]
        ax.bar(range(len(vals)), vals, yerr=err, capsize=4)
        ax.set_xticks(range(len(vals)), labels, fontsize=7)
        ax.set_ylabel("deg", fontsize=8)
        ax.set_title("q3 tracking RMSE (default controller)", fontsize=9)
        ax.tick_params(labelsize=7)
    else:
        ax.axis("off")


def figure(sheet: Mapping[str, Any], pdf: Path, png: Path) -> None:
    """The one-page figure: six panels vs bend / per run, the band shaded where given."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = sheet["shaft"]
    bends = list(sheet["settings"]["bends_deg"])
    bench_bends = list(sheet["settings"]["bench_bends_deg"])
    fig, axes = plt.subplots(3, 2, figsize=(8.27, 11.0))  # A4 portrait
    fig.suptitle(
        f"{s['name']}: D = {s['diameter_mm']:g} mm, L = {s['length_mm']:g} mm "
        f"(rating {sheet['numbers']['rating_nm']['value']:.2f} N*m)\n{s['catalogue']}",
        fontsize=10,
    )
    panel = functools.partial(_panel, sheet)
    panel(
        axes[0, 0],
        [
            ("k_sp", "K_sp eq. 3", bends),
            ("k_sn", "K_sn eq. 3", bends),
            ("bench_k_sp", "K_sp series test (sim)", bench_bends),
            ("bench_k_sn", "K_sn series test (sim)", bench_bends),
        ],
        "series stiffness per side",
        "N*m/rad",
    )
    panel(
        axes[0, 1],
        [
            ("loop_width_nm", "loop height at full slip", bends),
            ("bench_rmse_p_nm", "series-test RMSE + (sim)", bench_bends),
            ("bench_rmse_n_nm", "series-test RMSE - (sim)", bench_bends),
        ],
        "series hysteresis",
        "N*m",
    )
    panel(axes[1, 0], [("relief_nm", "static relief", bends)], "joint-2 relief (bending)", "N*m")
    bw = series_of(sheet, "bandwidth_hz", bends)
    missing = [f"{b:g}" for b, v in zip(bends, bw, strict=True) if not math.isfinite(v)]
    panel(
        axes[1, 1],
        [("bandwidth_hz", "-3 dB", bends)],
        "torque-loop bandwidth"
        + (
            f"\n(none below 40 Hz, the analysed band, at {', '.join(missing)} deg)"
            if missing
            else ""
        ),
        "Hz",
    )
    panel(
        axes[2, 0],
        [("impedance_low_nm_per_rad", "|Z| low f", bends)],
        "output impedance (zero-torque command)",
        "N*m/rad",
    )
    _tracking_bars(axes[2, 1], sheet)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(pdf)
    fig.savefig(png, dpi=90)
    plt.close(fig)


def html_page(sheet: Mapping[str, Any], png: Path) -> str:
    """The page: title, the figure (embedded PNG), the numbers table, the paper's number."""
    s = sheet["shaft"]
    img = base64.b64encode(png.read_bytes()).decode()
    has_band = any("band" in e for e in sheet["numbers"].values())
    head = "<tr><th>quantity</th><th>value</th><th>unit</th><th>source</th>" + (
        "<th>5 %</th><th>95 %</th></tr>" if has_band else "</tr>"
    )
    rows = []
    for e in sheet["numbers"].values():
        cells = [
            html.escape(e["label"]),
            _fmt(e["value"]),
            html.escape(e["unit"]),
            html.escape(e["source"]),
        ]
        if has_band:
            b = e.get("band")
            cells += [_fmt(b["p05"]), _fmt(b["p95"])] if b else ["", ""]
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    paper = "".join(
        f"<li>{html.escape(k)}: {_fmt(v['value'])} ({html.escape(v['source'])})</li>"
        for k, v in sheet["paper"].items()
    )
    unc = sheet.get("uncertainty")
    unc_text = (
        f"<p>Bands: 5-95 % over {unc['samples']} samples of the coefficient file's "
        f"[uncertainty] ranges ({html.escape(', '.join(unc['groups']))}; {unc['sampler']}, "
        f"seed {unc['seed']}; {unc['failed']} failed).</p>"
        if unc
        else "<p>No bands: run with <code>--uncertainty N</code> to sample the coefficient "
        "ranges.</p>"
    )
    title = html.escape(f"{s['name']}: D = {s['diameter_mm']:g} mm, L = {s['length_mm']:g} mm")
    return (
        "<!doctype html><html><head><meta charset='utf-8'>"
        f"<title>{title}</title><style>body{{font-family:sans-serif;max-width:60em;margin:auto}}"
        "table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #ccc;"
        "padding:2px 6px}td:nth-child(2),td:nth-child(5),td:nth-child(6){text-align:right}"
        "</style></head><body>"
        f"<h1>{title}</h1><p>Coefficients: {html.escape(s['catalogue'])}. Every coefficient of "
        "it is an estimate (seed 000 Table I scrambled, Table II missing); the sources say which "
        "number is the catalogue's, which the simulator's, which the paper's.</p>"
        f"{unc_text}<img style='width:100%' src='data:image/png;base64,{img}'>"
        f"<h2>Numbers</h2><table>{head}{''.join(rows)}</table>"
        + (f"<h2>Paper</h2><ul>{paper}</ul>" if paper else "")
        + "</body></html>"
    )


def write(sheet: Mapping[str, Any], folder: Path, stem: str) -> dict[str, Path]:
    """Write ``<stem>.json``, ``.pdf``, ``.png`` and ``.html`` into ``folder``."""
    import json

    folder.mkdir(parents=True, exist_ok=True)
    paths = {ext: folder / f"{stem}.{ext}" for ext in ("json", "pdf", "png", "html")}
    paths["json"].write_text(json.dumps(_no_nan(sheet), indent=2), "utf-8")
    figure(sheet, paths["pdf"], paths["png"])
    paths["html"].write_text(html_page(sheet, paths["png"]), "utf-8")
    return paths


def _no_nan(value: Any) -> Any:
    """NaN (no -3 dB point, say) as JSON null: strict JSON has no NaN."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Mapping):
        return {k: _no_nan(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_no_nan(v) for v in value]
    return value
