"""A campaign written out: tables, JSON and figures (series and parallel loops, eq. 3 / eq. 4
surfaces, error maps).
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.plant.shaft import (
    Catalogue,
)
from fsarm_sim.studies.campaign_bench import Array, ParallelFit, SeriesFit
from fsarm_sim.studies.campaign_surface import CampaignResult, SurfaceFit, eq3_design, eq4_design


def write_series_test(result: CampaignResult, name: str, folder: Path) -> Path:
    """One shaft's series test into ``folder``: its table (CSV) and its Fig. 6 loops."""
    folder.mkdir(parents=True, exist_ok=True)
    write_csv(folder / f"series_table_{name}.csv", series_table_rows(result.series[name]))
    loops = {f"φ_B = {t.split('/')[2]}°": lp for t, lp in result.loops.items()}
    plot_series_loops(
        loops, f"{name}: series test (Fig. 6)", folder / f"fig6_series_loops_{name}.png"
    )
    return folder


def write_parallel_test(result: CampaignResult, name: str, folder: Path) -> Path:
    """One shaft's parallel test into ``folder``: its table (CSV) and its Fig. 9 loop."""
    fits = result.parallel[name]
    folder.mkdir(parents=True, exist_ok=True)
    write_csv(folder / f"parallel_table_{name}.csv", [asdict(f) for f in fits])
    loops = {t.split("/")[2]: lp for t, lp in result.loops.items()}
    plot_parallel_loops(
        loops, fits, f"{name}: parallel test (Fig. 9)", folder / f"fig9_parallel_loop_{name}.png"
    )
    return folder


def series_table_rows(fits: Sequence[SeriesFit]) -> list[dict[str, float]]:
    """Table I-like rows: bend, K_sp, K_sn, RMSE_p, RMSE_n (eq. 8) and the eq. 1 terms."""
    return [
        {
            "bend_deg": f.bend_deg,
            "K_sp": f.k_pos,
            "K_sn": f.k_neg,
            "RMSE_p": f.rmse_pos,
            "RMSE_n": f.rmse_neg,
            "eq1_J": f.eq1_j,
            "eq1_B_p": f.eq1_b_pos,
            "eq1_B_n": f.eq1_b_neg,
            "eq1_RMSE_p": f.eq1_rmse_pos,
            "eq1_RMSE_n": f.eq1_rmse_neg,
        }
        for f in fits
    ]


def write_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> Path:
    """``rows`` as a CSV table (columns: the first row's keys); no rows: an empty file."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        if rows:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return path


def write_campaign(result: CampaignResult, catalogue: Catalogue, out_dir: str | Path) -> list[Path]:
    """Tables (CSV), results.json and figures into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    by_name = {s.name: s for s in result.shafts}
    for name, fits in result.series.items():
        files.append(write_csv(out / f"series_table_{name}.csv", series_table_rows(fits)))
    prows = [
        {"shaft": n, "D_mm": by_name[n].diameter_mm, "L_mm": by_name[n].length_mm, **asdict(f)}
        for n, fits in result.parallel.items()
        for f in fits
    ]
    if prows:
        files.append(write_csv(out / "parallel_table.csv", prows))
    crow = []
    for eq, c in result.comparisons.items():
        for nm, cat_v, fit_v, rel in zip(
            result.fits[eq].names, c.catalogue, c.refit, c.coefficient_rel_error, strict=True
        ):
            crow.append(
                {
                    "equation": eq,
                    "coefficient": nm,
                    "catalogue": cat_v,
                    "refit": fit_v,
                    "rel_error": rel,
                }
            )
    if crow:
        files.append(write_csv(out / "refit_coefficients.csv", crow))
    doc = {
        "catalogue": result.catalogue_source,
        "settings": asdict(result.settings),
        "shafts": [asdict(s) for s in result.shafts],
        "series": {n: [asdict(f) for f in fits] for n, fits in result.series.items()},
        "bend_trends": {n: asdict(t) for n, t in result.trends.items()},
        "parallel": {n: [asdict(f) for f in fits] for n, fits in result.parallel.items()},
        "fits": {k: asdict(v) for k, v in result.fits.items()},
        "comparisons": {k: asdict(v) for k, v in result.comparisons.items()},
        "errors": result.errors,
    }
    path = out / "campaign.json"
    path.write_text(json.dumps(doc, indent=2, allow_nan=True), "utf-8")
    files.append(path)
    files += plot_campaign(result, catalogue, out)
    result.files = files
    return files


def new_figure(size: tuple[float, float] = (7.0, 4.5)) -> Any:
    """A matplotlib figure on its own Agg canvas (headless, no pyplot state); ``size`` in inches."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, dpi=110)
    FigureCanvasAgg(fig)
    return fig


def plot_series_loops(
    loops: Mapping[str, Mapping[str, Sequence[float]]], title: str, path: Path
) -> Path:
    """Fig. 6-like: torque vs twist, one loop per bend angle."""
    fig = new_figure()
    ax = fig.add_subplot(1, 1, 1)
    for label, lp in loops.items():
        ax.plot(np.degrees(lp["twist"]), lp["tau_s"], lw=0.8, label=label)
    ax.set_xlabel("twist Δθ [deg]")
    ax.set_ylabel("shaft torque τ [N·m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_parallel_loops(
    loops: Mapping[str, Mapping[str, Sequence[float]]],
    fits: Sequence[ParallelFit],
    title: str,
    path: Path,
) -> Path:
    """Fig. 9-like: bending moment vs bend angle, with and without torsion, and the linear fit."""
    fig = new_figure()
    ax = fig.add_subplot(1, 1, 1)
    for label, lp in loops.items():
        ax.plot(np.degrees(lp["phi_b"]), lp["m_b"], lw=1.0, label=label)
    for f in fits:
        if not f.torsion:
            x = np.linspace(-math.pi / 2, math.pi / 2, 50)
            ax.plot(
                np.degrees(x),
                f.kb_linear * x,
                "k--",
                lw=0.8,
                label=f"eq. 2 fit K_b = {f.kb_linear:.3g}",
            )
    ax.set_xlabel("bend φ_B [deg]")
    ax.set_ylabel("bending moment M [N·m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_eq3_surfaces(
    fits: Mapping[str, SurfaceFit],
    points: Array,
    catalogue: Catalogue,
    path: Path,
) -> Path:
    """Fig. 8-like: refit eq. 3 surfaces K(D, L) at 0 and 90 deg per sign, with the data."""
    fig = new_figure((11.0, 8.0))
    d = np.linspace(*catalogue.diameter_range, 30)
    ell = np.linspace(*catalogue.length_range, 30)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    i = 1
    for side, col in (("positive", 3), ("negative", 4)):
        fit = fits.get(f"eq3 {side}")
        for bend in (0.0, 90.0):
            ax = fig.add_subplot(2, 2, i, projection="3d")
            i += 1
            if fit is not None:
                X = eq3_design(
                    D.ravel(),
                    Lg.ravel(),
                    np.full(D.size, math.radians(bend)),
                    catalogue.series_reference_length_mm,
                )
                K = (X @ np.asarray(fit.coefficients)).reshape(D.shape)
                ax.plot_surface(D, Lg, K, cmap="viridis", alpha=0.7, linewidth=0)
            sel = np.isclose(points[:, 2], math.radians(bend))
            ax.scatter(points[sel, 0], points[sel, 1], points[sel, col], color="r", s=12)
            ax.set_xlabel("D [mm]")
            ax.set_ylabel("L [mm]")
            ax.set_zlabel("K [N·m/rad]")
            ax.set_title(f"K_s{'p' if side == 'positive' else 'n'} at φ_B = {bend:g}°", fontsize=9)
    fig.suptitle("eq. 3 re-fitted from the simulated bench campaign (red: per-shaft fits)")
    fig.savefig(path)
    return path


def plot_eq4_surface(
    fit: SurfaceFit | None, points: Array, catalogue: Catalogue, path: Path
) -> Path:
    """Fig. 10-like: refit eq. 4 surface K_b(D, L) with the per-shaft fits."""
    fig = new_figure((7.0, 5.5))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    d = np.linspace(*catalogue.diameter_range, 30)
    ell = np.linspace(*catalogue.length_range, 30)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    if fit is not None:
        K = (eq4_design(D.ravel(), Lg.ravel()) @ np.asarray(fit.coefficients)).reshape(D.shape)
        ax.plot_surface(D, Lg, K, cmap="plasma", alpha=0.7, linewidth=0)
    ax.scatter(points[:, 0], points[:, 1], points[:, 2], color="k", s=14)
    ax.set_xlabel("D [mm]")
    ax.set_ylabel("L [mm]")
    ax.set_zlabel("K_b [N·m/rad]")
    ax.set_title("eq. 4 re-fitted (black: per-shaft linear K_b)")
    fig.savefig(path)
    return path


def plot_error_maps(result: CampaignResult, catalogue: Catalogue, path: Path) -> Path:
    """Heat maps of the refit's relative error against the catalogue over (D, L)."""
    d = np.linspace(*catalogue.diameter_range, 46)
    ell = np.linspace(*catalogue.length_range, 31)
    D, Lg = np.meshgrid(d, ell, indexing="ij")
    panels = []
    for eq in ("eq3 positive", "eq3 negative"):
        if eq in result.fits:
            for bend in (0.0, 90.0):
                X = eq3_design(
                    D.ravel(),
                    Lg.ravel(),
                    np.full(D.size, math.radians(bend)),
                    catalogue.series_reference_length_mm,
                )
                ref = catalogue.p_pos if eq.endswith("positive") else catalogue.p_neg
                panels.append((f"{eq}, φ_B = {bend:g}°", X, ref, result.fits[eq]))
    for eq in ("eq4", "eq4 (cubic K_b)"):
        if eq in result.fits:
            panels.append(
                (eq, eq4_design(D.ravel(), Lg.ravel()), catalogue.q_bend, result.fits[eq])
            )
    fig = new_figure((4.0 * max(1, min(3, len(panels))), 3.4 * math.ceil(max(1, len(panels)) / 3)))
    cols = max(1, min(3, len(panels)))
    rows = math.ceil(max(1, len(panels)) / cols)
    for i, (title, X, ref, fit) in enumerate(panels):
        ax = fig.add_subplot(rows, cols, i + 1)
        k_ref = X @ np.asarray(ref)
        rel = 100.0 * (X @ np.asarray(fit.coefficients) - k_ref) / np.abs(k_ref)
        im = ax.pcolormesh(d, ell, rel.reshape(D.shape).T, shading="auto", cmap="RdBu_r")
        fig.colorbar(im, ax=ax, label="refit − catalogue [%]")
        ax.set_xlabel("D [mm]")
        ax.set_ylabel("L [mm]")
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_campaign(result: CampaignResult, catalogue: Catalogue, out: Path) -> list[Path]:
    files = []
    by_name = {s.name: s for s in result.shafts}
    names = {tag.split("/")[0] for tag in result.loops}
    for name in sorted(names):
        series = {
            f"φ_B = {tag.split('/')[2]}°": lp
            for tag, lp in result.loops.items()
            if tag.startswith(f"{name}/series/")
        }
        if series:
            files.append(
                plot_series_loops(
                    series, f"{name}: series test (Fig. 6)", out / f"fig6_series_loops_{name}.png"
                )
            )
        par = {
            tag.split("/")[2]: lp
            for tag, lp in result.loops.items()
            if tag.startswith(f"{name}/parallel/")
        }
        if par:
            files.append(
                plot_parallel_loops(
                    par,
                    result.parallel.get(name, []),
                    f"{name}: parallel test (Fig. 9)",
                    out / f"fig9_parallel_loop_{name}.png",
                )
            )
    pts = [
        (by_name[n].diameter_mm, by_name[n].length_mm, math.radians(f.bend_deg), f.k_pos, f.k_neg)
        for n, fits in result.series.items()
        for f in fits
    ]
    if pts:
        files.append(
            plot_eq3_surfaces(
                result.fits, np.asarray(pts), catalogue, out / "fig8_eq3_surfaces.png"
            )
        )
    kb = [
        (by_name[n].diameter_mm, by_name[n].length_mm, f.kb_linear)
        for n, fits in result.parallel.items()
        for f in fits
        if not f.torsion
    ]
    if kb:
        files.append(
            plot_eq4_surface(
                result.fits.get("eq4"), np.asarray(kb), catalogue, out / "fig10_eq4_surface.png"
            )
        )
    if result.fits:
        files.append(plot_error_maps(result, catalogue, out / "refit_error_maps.png"))
    return files
