"""Simulated bench experiments of seed 000 Sec. III and the nine-shaft campaign.

Series test (Sec. III-A, Fig. 6-7, Table I): on the series bench (:mod:`fsarm_sim.studies.bench`, blocked
output) a chirp 0.5-20 Hz is fed to the torque controller, amplitude by the shaft's nominal
rating (capped by the DBRK-20 sensor range), at bend angles 0-90 deg in 15 deg steps. Per twist
sign and bend angle, eq. 8 (``tau = K * twist``) and eq. 1 (``tau = J twist'' + B twist' +
K twist``, J shared by both signs) are fitted by least squares; RMSE per sign = a Table I-like
table. The bend trend per sign (eq. 8's ``f_p(phi_B)``) is fitted as ``K(phi) = K0 + s |phi|``.

Parallel test (Sec. III-B2, Fig. 9): on the parallel bench the joint bends the shaft through one
cycle ``0 -> +A -> 0 -> -A -> 0`` (both directions), without and with torsion (input held at a
twist of ``torsion_fraction`` of the rating). Fits of the moment loop M(phi): eq. 2 linear
``M = K_b phi`` (the paper's "linear fit for approximation"), per bending direction, and
``M = K_b (phi + beta phi^3)``; the loop area is the energy the conduit dissipates per cycle.

Campaign (Sec. III-B, Fig. 8, Fig. 10): both tests for every shaft of the catalogue, then eq. 3
(per sign, from the 7 bend angles x N shafts) and eq. 4 (from the N shafts' K_b) are re-fitted by
nonlinear least squares (``scipy.optimize.least_squares``) and compared with the coefficients the
simulator was given: coefficient by coefficient and as surfaces over the validity box. Eq. 3 is
re-fitted with the catalogue's length law (``series.length_law``: with "inverse" p4 is 0 and not
fitted).

Every bench run is an independent task (:func:`bench_task`), run through
:func:`fsarm_sim.executors.run_tasks`, so campaigns use all cores or a Dask cluster.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.executors import Outcome, run_tasks
from fsarm_sim.paths import named_os_errors
from fsarm_sim.plant.shaft import (
    Catalogue,
    CatalogueShaft,
    load_catalogue,
)
from fsarm_sim.studies.campaign_bench import BEND_STEPS_DEG as BEND_STEPS_DEG
from fsarm_sim.studies.campaign_bench import SENSOR_RANGE_NM as SENSOR_RANGE_NM
from fsarm_sim.studies.campaign_bench import BenchSettings as BenchSettings
from fsarm_sim.studies.campaign_bench import CampaignError as CampaignError
from fsarm_sim.studies.campaign_bench import ParallelFit, SeriesFit, bench_task
from fsarm_sim.studies.campaign_bench import fit_bend_trend as fit_bend_trend
from fsarm_sim.studies.campaign_bench import fit_parallel as fit_parallel
from fsarm_sim.studies.campaign_bench import fit_series as fit_series
from fsarm_sim.studies.campaign_bench import parallel_test as parallel_test
from fsarm_sim.studies.campaign_bench import series_test as series_test
from fsarm_sim.studies.campaign_surface import CampaignResult as CampaignResult
from fsarm_sim.studies.campaign_surface import SurfaceFit
from fsarm_sim.studies.campaign_surface import compare_surface as compare_surface
from fsarm_sim.studies.campaign_surface import eq3_design as eq3_design
from fsarm_sim.studies.campaign_surface import fit_eq3 as fit_eq3
from fsarm_sim.studies.campaign_surface import fit_eq4 as fit_eq4

# ----------------------------------------------------------------------------------------------
# bench experiments for one shaft, and the campaign


def _catalogue_text(path: str | Path | None) -> str | None:
    if path is None:
        return None
    with named_os_errors("coefficient file", path, CampaignError):
        return Path(path).read_text("utf-8")


def _task(
    test: str, shaft: CatalogueShaft, s: BenchSettings, catalogue_toml: str | None, loop: bool
) -> tuple[dict[str, Any], dict[str, Any]]:
    """A bench task's keys before its own (the test, the shaft) and after them (the settings,
    the catalogue, the loop figure)."""
    head = {
        "test": test,
        "name": shaft.name,
        "diameter_mm": shaft.diameter_mm,
        "length_mm": shaft.length_mm,
    }
    return head, {"settings": asdict(s), "catalogue_toml": catalogue_toml, "loop": loop}


def series_tasks(
    shaft: CatalogueShaft,
    bends_deg: Sequence[float],
    s: BenchSettings,
    catalogue_toml: str | None,
    loop: bool,
) -> list[dict[str, Any]]:
    head, tail = _task("series", shaft, s, catalogue_toml, loop)
    return [{**head, "bend_deg": float(b), **tail} for b in bends_deg]


def parallel_tasks(
    shaft: CatalogueShaft, s: BenchSettings, catalogue_toml: str | None, loop: bool
) -> list[dict[str, Any]]:
    head, tail = _task("parallel", shaft, s, catalogue_toml, loop)
    return [{**head, "torsion": torsion, **tail} for torsion in (False, True)]


def run_bench_tasks(
    tasks: Sequence[Mapping[str, Any]],
    *,
    executor: str = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    on_done: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    return run_tasks(
        bench_task,
        list(tasks),
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        on_done=on_done,
    )


def collect(result: CampaignResult, outcomes: Sequence[Outcome]) -> None:
    """Sort task outcomes into the result (fits per shaft, loops, errors)."""
    for o in sorted(outcomes, key=lambda o: o.index):
        task = o.task
        name = task["name"]
        if o.error is not None or o.result is None:
            what = (
                f"{task['test']} bend {task.get('bend_deg')}"
                if task["test"] == "series"
                else (f"parallel torsion={task.get('torsion')}")
            )
            result.errors.append(f"{name} {what}: {o.error}")
            continue
        fit = o.result["fit"]
        if task["test"] == "series":
            result.series.setdefault(name, []).append(SeriesFit(**fit))
            tag = f"{name}/series/{fit['bend_deg']:g}"
        else:
            result.parallel.setdefault(name, []).append(ParallelFit(**fit))
            tag = f"{name}/parallel/{'torsion' if fit['torsion'] else 'plain'}"
        if "loop" in o.result:
            result.loops[tag] = o.result["loop"]
    for name, fits in result.series.items():
        fits.sort(key=lambda f: f.bend_deg)
        if len(fits) >= 2:
            result.trends[name] = fit_bend_trend(fits)


def refit(result: CampaignResult, catalogue: Catalogue) -> None:
    """Eq. 3 per sign and eq. 4 (linear and cubic K_b) from the collected fits; compare."""
    by_name = {s.name: s for s in result.shafts}
    rows = [
        (by_name[n].diameter_mm, by_name[n].length_mm, math.radians(f.bend_deg), f.k_pos, f.k_neg)
        for n, fits in result.series.items()
        for f in fits
    ]
    if rows:
        a = np.asarray(rows)
        for side, col in (("positive", 3), ("negative", 4)):
            try:
                fit = fit_eq3(
                    a[:, 0], a[:, 1], a[:, 2], a[:, col], side, catalogue.series_reference_length_mm
                )
            except CampaignError as exc:
                result.errors.append(str(exc))
                continue
            result.fits[fit.equation] = fit
            result.comparisons[fit.equation] = compare_surface(
                fit, catalogue, max(r[2] for r in rows)
            )
    plain = [
        (by_name[n].diameter_mm, by_name[n].length_mm, f.kb_linear, f.kb_cubic)
        for n, fits in result.parallel.items()
        for f in fits
        if not f.torsion
    ]
    if plain:
        b = np.asarray(plain)
        for label, col in (("eq4", 2), ("eq4 (cubic K_b)", 3)):
            try:
                fit = fit_eq4(b[:, 0], b[:, 1], b[:, col])
            except CampaignError as exc:
                result.errors.append(str(exc))
                continue
            fit = SurfaceFit(**{**asdict(fit), "equation": label})
            result.fits[label] = fit
            result.comparisons[label] = compare_surface(fit, catalogue)


def run_campaign(
    catalogue_path: str | Path | None = None,
    *,
    shafts: Sequence[CatalogueShaft] | None = None,
    bends_deg: Sequence[float] = BEND_STEPS_DEG,
    settings: BenchSettings | None = None,
    executor: str = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    loops_for: Sequence[str] | None = None,
    on_done: Callable[[Outcome], None] | None = None,
) -> CampaignResult:
    """Both bench tests for every shaft, then the eq. 3/4 refits and their comparison.

    ``loops_for``: shaft names whose loops are kept for figures (default: the prototype's,
    ``MF09-450``, or the first shaft)."""
    s = settings or BenchSettings()
    s.validate()
    cat = load_catalogue(catalogue_path)
    text = _catalogue_text(catalogue_path)
    chosen = list(shafts if shafts is not None else cat.shafts)
    if not chosen:
        raise CampaignError(f"{cat.source} lists no shafts to test")
    for b in bends_deg:
        if not math.isfinite(b) or not 0.0 <= b <= math.degrees(cat.bend_range[1]):
            raise CampaignError(
                f"bend angle {b!r} deg is outside [0, {math.degrees(cat.bend_range[1]):.0f}] deg"
            )
    for sh in chosen:
        cat.check_range(sh.diameter_mm, sh.length_mm)
    if loops_for is None:
        names = [x.name for x in chosen]
        loops_for = ["MF09-450"] if "MF09-450" in names else names[:1]
    tasks: list[dict[str, Any]] = []
    for sh in chosen:
        keep = sh.name in loops_for
        tasks += series_tasks(sh, bends_deg, s, text, keep)
        tasks += parallel_tasks(sh, s, text, keep)
    for tk in tasks:
        tk["catalogue_source"] = cat.source
    result = CampaignResult(settings=s, catalogue_source=cat.source, shafts=chosen)
    outcomes = run_bench_tasks(
        tasks, executor=executor, workers=workers, scheduler=scheduler, on_done=on_done
    )
    collect(result, outcomes)
    refit(result, cat)
    return result


# ----------------------------------------------------------------------------------------------
# writing: tables, JSON, figures


def run_one_shaft(
    catalogue: Catalogue,
    diameter_mm: float,
    length_mm: float,
    shaft_file: str | Path | None,
    settings: BenchSettings,
    make_tasks: Callable[[CatalogueShaft, str | None], list[dict[str, Any]]],
    workers: int | None = None,
) -> tuple[str, CampaignResult]:
    """One shaft's bench tasks (``make_tasks(shaft, coefficient_text)``, e.g. :func:`series_tasks`)
    run and collected; the shaft's name and the result. The first failure is a CampaignError."""
    name = f"D{diameter_mm:g}-L{length_mm:g}"
    sh = CatalogueShaft(name, diameter_mm, length_mm)
    result = CampaignResult(settings=settings, catalogue_source=catalogue.source, shafts=[sh])
    collect(result, run_bench_tasks(make_tasks(sh, _catalogue_text(shaft_file)), workers=workers))
    if result.errors:
        raise CampaignError("; ".join(result.errors))
    return name, result


def check_bends(bends_deg: Sequence[float], catalogue: Catalogue) -> tuple[float, ...]:
    """Validate a list of bend angles (deg) for the series test."""
    if not bends_deg:
        raise InvalidParameterError("give at least one bend angle")
    hi = math.degrees(catalogue.bend_range[1])
    out = []
    for b in bends_deg:
        if not math.isfinite(b) or not 0.0 <= b <= hi:
            raise InvalidParameterError(f"bend angle {b!r} deg is outside [0, {hi:.0f}] deg")
        out.append(float(b))
    return tuple(out)
