"""Uncertainty bands beside the paper values of ``fsarm reproduce --uncertainty N`` (issue 32).

For the claims whose value is a simulation of the arm with the catalogue's shaft (seed 000's
fig14-sine tracking, estimate error, hysteresis share, rated-payload tracking and the static relief
of joint 2), the same quantity is recomputed on ``N`` samples of the coefficient file's declared
ranges (:mod:`fsarm_sim.studies.uncertainty`: scrambled Sobol, 2 threads) and its 5-95 % band is
reported beside the paper's value and ours. The sampled shaft is the plant; the controller keeps
the catalogue's eq. 8 (``--uncertainty-controller nominal`` of ``fsarm run``: a shaft used as
catalogued).

The bands are a report only: they are computed after every claim has been judged, from the
claims' results, and nothing here reaches a verdict (``tests/test_reproduce_bands.py`` runs the
command with and without bands and finds the same verdicts). Claims whose value does not come
from such a simulation (fits, transcriptions, benches, other papers) get no band; the report
lists them as not banded.

Each quantity is computed as the claim's own measurement (``studies/reproduce/measure000.py``)
computes it, with the sample's shaft; with the nominal catalogue it equals the claim's value
(tested), so the band and the number beside it are the same quantity.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from fsarm_sim.plant.shaft import Catalogue

if TYPE_CHECKING:
    from fsarm_sim.engine.callbacks import Backend

LOADED_PAYLOAD_KG = 15.0  # seed 000 Table III's rated payload, as measure000.fig14_loaded
QUICK_S = 4.0  # the quick runs' length, as measure000


@dataclass(frozen=True)
class Banded:
    """The quantity of one claim (by its ``measure`` name) on a sampled catalogue."""

    runs: tuple[str, ...]  # the simulations it needs (shared between claims of one sample)
    value: Callable[[Mapping[str, Any]], float | list[float]]


def _rmse_q3(res: Any) -> float:
    return float(res.metrics["rmse_deg"]["q3"])


def _estimate_share(runs: Mapping[str, Any]) -> float:
    m = runs["fig14"].metrics
    peak = float(m["peak_shaft_torque_nm"])
    return float(m["tau_estimate_rmse_nm"]) / peak if peak > 0.0 else 0.0


def _hysteresis_share(runs: Mapping[str, Any]) -> float:
    without = _rmse_q3(runs["fig14_no_slip"])
    return _rmse_q3(runs["fig14"]) / without if without > 0.0 else math.inf


BANDED: dict[str, Banded] = {
    "fig14_tracking": Banded(("fig14",), lambda r: _rmse_q3(r["fig14"])),
    "fig14_estimate_error": Banded(("fig14",), _estimate_share),
    "fig14_hysteresis_share": Banded(("fig14", "fig14_no_slip"), _hysteresis_share),
    "fig14_loaded": Banded(
        ("fig14", "fig14_loaded"), lambda r: [_rmse_q3(r["fig14"]), _rmse_q3(r["fig14_loaded"])]
    ),
    "static_relief_on_arm": Banded(("relief",), lambda r: float(r["relief"])),
}
PAPER = "000"  # every banded claim is seed 000's (the arm of Sec. IV)


def banded_claims(claims: Sequence[Any]) -> list[Any]:
    """The claims of ``claims`` that get a band (measured, paper 000, quantity known here)."""
    return [c for c in claims if c.paper == PAPER and c.measure in BANDED]


def _run(name: str, config: Any, quick: bool, backend: Backend) -> Any:
    from fsarm_sim.sim.simulation import run_scenario

    duration = QUICK_S if quick else None
    if name == "fig14":
        return run_scenario("fig14-sine", config, duration_s=duration, backend=backend)
    if name == "fig14_no_slip":
        off = config.with_(effects=replace(config.effects, slip=False))
        return run_scenario("fig14-sine", off, duration_s=duration, backend=backend)
    if name == "fig14_loaded":
        return run_scenario(
            "fig14-sine",
            config,
            duration_s=duration,
            payload_kg=LOADED_PAYLOAD_KG,
            backend=backend,
        )
    assert name == "relief"
    from fsarm_sim.studies.reproduce.measure000 import relief_hold_tau2

    tau2 = relief_hold_tau2(config, backend)
    return abs(tau2["without"]) - abs(tau2["with"])


def claim_values(
    catalogue: Catalogue,
    *,
    measures: tuple[str, ...],
    nominal: Catalogue,
    quick: bool,
    backend: Backend = "native",
) -> dict[str, Any]:
    """The quantities of the claims ``measures`` with ``catalogue``'s prototype shaft as the plant
    and ``nominal``'s as the controller's model: the metric the bands sample."""
    from fsarm_sim.engine.model import SimConfig

    config = SimConfig(shaft=catalogue.shaft(), controller_shaft=nominal.shaft())
    needed = sorted({r for m in measures for r in BANDED[m].runs})
    runs = {name: _run(name, config, quick, backend) for name in needed}
    out: dict[str, Any] = {}
    for m in measures:
        value = BANDED[m].value(runs)
        out[m] = value if not isinstance(value, list) else dict(enumerate(map(float, value)))
    return out


def claim_bands(
    results: Sequence[Any], n: int, *, quick: bool, backend: Backend = "native"
) -> dict[str, Any]:
    """The band of every banded claim among ``results`` (judged claims; :class:`Result`), as a
    JSON-ready report: per claim id its paper value and text, ours, the 5/50/95 % values, and
    the claims left without a band. Reads the results, never changes them."""
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.studies import uncertainty as unc

    unc.check_samples(n)
    nominal = load_catalogue()
    measured = [r for r in results if r.claim.measure is not None and not r.failed]
    mine = {c.id for c in banded_claims([r.claim for r in measured])}
    measures = tuple(sorted({r.claim.measure for r in measured if r.claim.id in mine}))
    out: dict[str, Any] = {
        "samples": n,
        "band_percent": list(unc.BAND),
        "controller": "nominal (the catalogue's eq. 8; the sampled shaft is the plant)",
        "used_by_verdicts": False,
        "claims": {},
        "not_banded": [r.claim.id for r in measured if r.claim.id not in mine],
    }
    if not measures:
        return out
    metric = functools.partial(
        claim_values, measures=measures, nominal=nominal, quick=quick, backend=backend
    )
    prop = unc.propagate(metric, nominal, n)
    out.update(
        failed=prop.failed, errors=list(prop.errors), groups=list(prop.groups), seed=prop.seed
    )
    out["wall_s"] = round(prop.wall_s, 2)
    for r in measured:
        c = r.claim
        if c.id not in mine:
            continue
        keys = sorted(k for k in prop.bands if k == c.measure or k.startswith(c.measure + "."))
        out["claims"][c.id] = {
            "paper_value": c.paper_value,
            "paper_text": c.paper_text,
            "unit": c.unit,
            "ours": r.ours,
            "ours_text": r.ours_text,
            "band": [prop.bands[k].as_dict() for k in keys],
        }
    return out
