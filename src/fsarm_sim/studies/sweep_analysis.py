"""The analysis of a finished sweep: eq. 3/4 re-fitted from its points, and its plots."""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim._version import __version__
from fsarm_sim.plant.shaft import Catalogue, load_catalogue, parse_catalogue
from fsarm_sim.records.store import ResultStore
from fsarm_sim.studies import sweep_table

# ----------------------------------------------------------------------------------------------
# analysis of a finished sweep

PLOT_METRICS = (
    "q3_rmse_deg",
    "torque_bandwidth_hz",
    "static_relief_nm",
    "peak_motor_torque_nm",
    "peak_motor_speed_rad_s",
    "k_sp",
    "k_sn",
    "kb",
)
AXES = ("diameter_mm", "length_mm", "bend_deg", "payload_kg")


@dataclass
class SweepAnalysis:
    n_points: int
    fits: dict[str, Any] = field(default_factory=dict)  # SurfaceFit per equation
    comparisons: dict[str, Any] = field(default_factory=dict)
    skipped: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)


def _write_points(df: Any, out: Path, res: SweepAnalysis) -> None:
    """The points as ``points.csv`` and ``points.parquet``."""
    csv_path = out / "points.csv"
    df.to_csv(csv_path, index=False)
    res.files.append(csv_path)
    try:
        pq = out / "points.parquet"
        df.to_parquet(pq, index=False)
        res.files.append(pq)
    except (ImportError, ValueError) as exc:  # pragma: no cover - pyarrow is a dependency
        res.skipped.append(f"parquet export: {exc}")


def _stored_catalogue(
    df: Any, cat_texts: dict[str, str | None], res: SweepAnalysis
) -> Catalogue | None:
    """The one catalogue the points were computed with (None when several or not stored)."""
    cats = df["catalogue_sha256"].unique()
    if len(cats) != 1:
        res.skipped.append("points come from several catalogues: no comparison with one")
        return None
    text = cat_texts.get(str(cats[0]))
    if text == "default":
        return load_catalogue()
    if text:
        return parse_catalogue(tomllib.loads(text), "stored shaft file")
    return None


def analyze(store_path: str | Path, out_dir: str | Path, sweep: str | None = None) -> SweepAnalysis:
    """Re-fit eq. 3 (per sign) and eq. 4 to the stored stiffnesses; write tables and plots."""
    from fsarm_sim.studies.campaign import (
        CampaignError,
        compare_surface,
        fit_eq3,
        fit_eq4,
    )

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with ResultStore(store_path) as store:
        df = store.frame(sweep)
        cat_texts = {
            k.split(":", 1)[1]: store.meta(k)
            for k in [
                f"catalogue:{s}" for s in (df["catalogue_sha256"].unique() if len(df) else [])
            ]
        }
    res = SweepAnalysis(n_points=len(df))
    if len(df) == 0:
        res.skipped.append("no finished points in the store")
        return res
    _write_points(df, out, res)
    catalogue = _stored_catalogue(df, cat_texts, res)
    src = df["stiffness_source"].iloc[0] if "stiffness_source" in df else ""
    series = df.drop_duplicates(subset=["diameter_mm", "length_mm", "bend_deg"])
    for side, col in (("positive", "k_sp"), ("negative", "k_sn")):
        try:
            fit = fit_eq3(
                series["diameter_mm"].to_numpy(float),
                series["length_mm"].to_numpy(float),
                np.radians(series["bend_deg"].to_numpy(float)),
                series[col].to_numpy(float),
                side,
                # the stored catalogue's length law; several catalogues: eq. 3 as printed
                catalogue.series_reference_length_mm if catalogue is not None else 0.0,
            )
        except CampaignError as exc:
            res.skipped.append(f"eq. 3 {side}: {exc}")
            continue
        res.fits[fit.equation] = fit
        if catalogue is not None:
            res.comparisons[fit.equation] = compare_surface(
                fit, catalogue, math.radians(float(np.max(np.abs(series["bend_deg"]))))
            )
    shafts = df.drop_duplicates(subset=["diameter_mm", "length_mm"])
    try:
        fit4 = fit_eq4(
            shafts["diameter_mm"].to_numpy(float),
            shafts["length_mm"].to_numpy(float),
            shafts["kb"].to_numpy(float),
        )
        res.fits["eq4"] = fit4
        if catalogue is not None:
            res.comparisons["eq4"] = compare_surface(fit4, catalogue)
    except CampaignError as exc:
        res.skipped.append(f"eq. 4: {exc}")
    summary = {
        "points": len(df),
        "stiffness_source": src,
        "fits": {k: dataclasses.asdict(v) for k, v in res.fits.items()},
        "comparisons": {k: dataclasses.asdict(v) for k, v in res.comparisons.items()},
        "skipped": res.skipped,
        "version": __version__,
    }
    jpath = out / "analysis.json"
    jpath.write_text(json.dumps(summary, indent=2), "utf-8")
    res.files.append(jpath)
    res.files += _plots(df, res, catalogue, out)
    return res


def _varied(df: Any) -> list[str]:
    return [a for a in AXES if a in df and df[a].nunique() > 1]


def _plots(df: Any, res: SweepAnalysis, catalogue: Catalogue | None, out: Path) -> list[Path]:
    from fsarm_sim.studies.campaign_output import new_figure, plot_eq3_surfaces, plot_eq4_surface

    files: list[Path] = []
    axes = _varied(df)
    for metric in PLOT_METRICS:
        if metric not in df or df[metric].isna().all():
            continue
        fig = new_figure((6.4, 4.6))
        ax = fig.add_subplot(1, 1, 1)
        if len(axes) >= 2:
            x, y = axes[0], axes[1]
            table = df.pivot_table(index=y, columns=x, values=metric, aggfunc="mean")
            z = table.to_numpy(float)
            im = ax.imshow(z, origin="lower", aspect="auto", cmap="viridis")
            ax.set_xticks(range(z.shape[1]), [f"{v:g}" for v in table.columns])
            ax.set_yticks(range(z.shape[0]), [f"{v:g}" for v in table.index])
            if z.size <= 100:
                for (r, c), v in np.ndenumerate(z):
                    ax.text(c, r, f"{v:.3g}", ha="center", va="center", fontsize=7, color="w")
            fig.colorbar(im, ax=ax, label=sweep_table.label(metric))
            ax.set_xlabel(sweep_table.label(x))
            ax.set_ylabel(sweep_table.label(y))
            others = [sweep_table.label(a) for a in axes[2:]]
            ax.set_title(
                sweep_table.label(metric) + (f" (mean over {', '.join(others)})" if others else ""),
                fontsize=9,
            )
        elif len(axes) == 1:
            x = axes[0]
            g = df.groupby(x)[metric].mean()
            ax.plot(g.index.to_numpy(float), g.to_numpy(float), "o-")
            ax.set_xlabel(sweep_table.label(x))
            ax.set_ylabel(sweep_table.label(metric))
            ax.grid(True, alpha=0.3)
        else:
            continue
        fig.tight_layout()
        path = out / f"map_{metric}.png"
        fig.savefig(path)
        files.append(path)
    if catalogue is not None and res.fits:
        if "eq3 positive" in res.fits or "eq3 negative" in res.fits:
            pts = (
                df[["diameter_mm", "length_mm", "bend_deg", "k_sp", "k_sn"]].to_numpy(float).copy()
            )
            pts[:, 2] = np.radians(pts[:, 2])
            files.append(plot_eq3_surfaces(res.fits, pts, catalogue, out / "fig8_eq3_surfaces.png"))
        if "eq4" in res.fits:
            shafts = df.drop_duplicates(subset=["diameter_mm", "length_mm"])
            pts4 = shafts[["diameter_mm", "length_mm", "kb"]].to_numpy(float)
            files.append(
                plot_eq4_surface(res.fits["eq4"], pts4, catalogue, out / "fig10_eq4_surface.png")
            )
    return files
