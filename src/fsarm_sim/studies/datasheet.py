"""A datasheet per shaft (issue 32): every number an actuator engineer asks for, with its source.

:func:`measure` computes the datasheet's numbers for one shaft of a catalogue as a flat
``{key: value}`` dict (so :mod:`fsarm_sim.studies.uncertainty` can band every one of them);
:func:`datasheet` adds the layout: label, unit, source and, when given, the 5-95 % band.

Sources, as the datasheet states them:

* ``catalogue estimate``: eq. 3 / eq. 4 / the rating law / the Maxwell-slip and bending
  parameters of the coefficient file (estimates: seed 000 Table I is scrambled and Table II
  missing; each coefficient's reason is in the file);
* ``simulation``: the seed 000 series test on the simulated bench (eq. 8 fit per sign: what
  ``fsarm bench series`` prints), the held-arm torque-loop bandwidth and output impedance (what
  ``fsarm transparency`` prints) and the standard scenarios (what ``fsarm run`` prints), with the
  default controller;
* ``paper``: the one number seed 000 gives for a shaft, the about 8 N*m joint-2 relief of the
  9 x 450 mm prototype (Sec. V), shown beside the catalogue's value for that shaft only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from fsarm_sim.errors import FsarmError
from fsarm_sim.plant.shaft import (
    PROTOTYPE_DIAMETER_MM,
    PROTOTYPE_LENGTH_MM,
    Catalogue,
    ShaftParams,
)

STEEL_DENSITY_KG_M3 = 7850.0  # plain carbon steel (handbook value)
PAPER_RELIEF_NM = 8.0  # seed 000 Sec. V: "about 8 N*m less static torque on joint 2" (prototype)
CATALOGUE = "catalogue estimate"
SIMULATION = "simulation"


class DatasheetError(FsarmError, ValueError):
    """Bad datasheet options (which shaft, which settings)."""


@dataclass(frozen=True)
class Settings:
    """What the datasheet evaluates (defaults: the fast datasheet, a few seconds per shaft)."""

    bends_deg: tuple[float, ...] = (0.0, 30.0, 60.0, 90.0, 120.0)
    bench_bends_deg: tuple[float, ...] = (0.0, 30.0, 60.0, 90.0)  # Table I's bends
    scenarios: tuple[str, ...] = ("fig14-sine", "p2p-payload")
    payloads_kg: tuple[float, ...] = (0.0, 15.0)
    duration_s: float | None = None  # None: each scenario's own
    chirp_s: float = 4.0  # torque-bandwidth chirp (fsarm transparency's default)
    simulate: bool = True  # False: catalogue numbers only (tests, quick looks)
    backend: str = "native"


def _b(deg: float) -> str:
    return f"{deg:g}deg"


def steel_core_inertia_kgm2(diameter_mm: float, length_mm: float) -> float:
    """Axial inertia of a solid steel core of the shaft's D and L, rho pi D^4 L / 32: an upper
    bound (a wound core has gaps)."""
    d, ell = diameter_mm * 1e-3, length_mm * 1e-3
    return STEEL_DENSITY_KG_M3 * math.pi * d**4 * ell / 32.0


def measure(
    catalogue: Catalogue,
    *,
    diameter_mm: float,
    length_mm: float,
    settings: Settings = Settings(),
    extrapolate: bool = False,
    controller_shaft: ShaftParams | None = None,
) -> dict[str, float]:
    """The datasheet's numbers for one shaft (flat keys, SI units with the unit in the label).
    ``controller_shaft``: the controller's eq. 8 model when it is not the shaft itself (the
    nominal shaft while ``catalogue`` is a sampled one, ``--uncertainty-controller nominal``)."""
    shaft = catalogue.shaft(diameter_mm, length_mm, extrapolate=extrapolate)
    out: dict[str, float] = {
        "rating_nm": shaft.rating_nm,
        "kb_eq4_nm_per_rad": shaft.kb_eq4,
        "inertia_eq1_kgm2": shaft.inertia_kgm2,
        "inertia_steel_core_kgm2": steel_core_inertia_kgm2(diameter_mm, length_mm),
    }
    slip_total = sum(shaft.slip_f)
    for deg in settings.bends_deg:
        rad = math.radians(deg)
        out[f"k_sp.{_b(deg)}"] = shaft.k_series(rad, 1)
        out[f"k_sn.{_b(deg)}"] = shaft.k_series(rad, -1)
        grow = math.exp(shaft.bend_friction_per_rad * abs(rad))
        # full-slip loop height: winding-side slip torque up plus unwinding-side down
        out[f"loop_width_nm.{_b(deg)}"] = slip_total * (1.0 + shaft.slip_unwinding_ratio) * grow
        out[f"relief_nm.{_b(deg)}"] = shaft.static_relief_nm(rad)
    if not settings.simulate:
        return out
    out.update(_simulated(shaft, settings, controller_shaft))
    return out


def _simulated(
    shaft: ShaftParams, settings: Settings, controller_shaft: ShaftParams | None
) -> dict[str, float]:
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim.simulation import run_scenario
    from fsarm_sim.studies.arm_metrics import torque_bandwidth
    from fsarm_sim.studies.campaign import BenchSettings, fit_series, series_test
    from fsarm_sim.studies.transparency import output_impedance

    out: dict[str, float] = {}
    backend: Any = settings.backend
    bench = BenchSettings(backend=settings.backend)
    for deg in settings.bench_bends_deg:
        fit = fit_series(series_test(shaft, math.radians(deg), bench), deg)
        out[f"bench_k_sp.{_b(deg)}"] = fit.k_pos
        out[f"bench_k_sn.{_b(deg)}"] = fit.k_neg
        out[f"bench_rmse_p_nm.{_b(deg)}"] = fit.rmse_pos
        out[f"bench_rmse_n_nm.{_b(deg)}"] = fit.rmse_neg
    cfg = SimConfig(shaft=shaft, controller_shaft=controller_shaft)
    for deg in settings.bends_deg:
        rad = math.radians(deg)
        bw = torque_bandwidth(cfg, rad, backend=backend, chirp_s=settings.chirp_s)
        z = output_impedance(cfg, rad, backend=backend)
        out[f"bandwidth_hz.{_b(deg)}"] = bw.bandwidth_hz
        out[f"impedance_low_nm_per_rad.{_b(deg)}"] = z.low_freq_nm_per_rad
    for sc in settings.scenarios:
        for kg in settings.payloads_kg:
            m = run_scenario(
                sc, cfg, duration_s=settings.duration_s, payload_kg=kg, backend=backend
            ).metrics
            rmse, mx = m["rmse_deg"], m["max_abs_err_deg"]
            assert isinstance(rmse, dict) and isinstance(mx, dict)
            key = f"track.{sc}.{kg:g}kg"
            out[f"{key}.q3_rmse_deg"] = rmse["q3"]
            out[f"{key}.q3_max_abs_err_deg"] = mx["q3"]
            for name in ("peak_motor_torque_nm", "motor_energy_j", "peak_shaft_torque_over_rating"):
                value = m[name]
                assert isinstance(value, float)
                out[f"{key}.{name}"] = value
    return out


# label, unit, source of every key (the part before the first '.' for the per-bend/-run keys)
FIELDS: dict[str, tuple[str, str, str]] = {
    "rating_nm": ("nominal torque rating (tau = c D^3)", "N*m", CATALOGUE),
    "kb_eq4_nm_per_rad": ("bending stiffness K_b (eq. 4)", "N*m/rad", CATALOGUE),
    "inertia_eq1_kgm2": ("shaft inertia in the model (eq. 1 J)", "kg*m^2", CATALOGUE),
    "inertia_steel_core_kgm2": (
        "shaft inertia, solid steel core bound (rho pi D^4 L / 32)",
        "kg*m^2",
        "estimate (steel 7850 kg/m^3; a wound core is lighter)",
    ),
    "k_sp": ("series stiffness, winding side (eq. 3)", "N*m/rad", CATALOGUE),
    "k_sn": ("series stiffness, unwinding side (eq. 3)", "N*m/rad", CATALOGUE),
    "loop_width_nm": (
        "series hysteresis loop height at full slip (Maxwell-slip)",
        "N*m",
        CATALOGUE,
    ),
    "relief_nm": ("static joint-2 relief (bending moment)", "N*m", CATALOGUE),
    "bench_k_sp": ("series test eq. 8 fit, K_sp", "N*m/rad", SIMULATION + " (fsarm bench series)"),
    "bench_k_sn": ("series test eq. 8 fit, K_sn", "N*m/rad", SIMULATION + " (fsarm bench series)"),
    "bench_rmse_p_nm": (
        "series test fit RMSE, + side",
        "N*m",
        SIMULATION + " (fsarm bench series)",
    ),
    "bench_rmse_n_nm": (
        "series test fit RMSE, - side",
        "N*m",
        SIMULATION + " (fsarm bench series)",
    ),
    "bandwidth_hz": ("torque-loop bandwidth (-3 dB)", "Hz", SIMULATION + " (fsarm transparency)"),
    "impedance_low_nm_per_rad": (
        "output impedance |Z| at low frequency",
        "N*m/rad",
        SIMULATION + " (fsarm transparency)",
    ),
    "track": ("tracking", "", SIMULATION + " (fsarm run)"),
}


def describe(key: str) -> tuple[str, str, str]:
    """(label, unit, source) of a datasheet key."""
    head = key.split(".", 1)[0]
    label, unit, source = FIELDS[head]
    if head == "track":
        _, sc, kg, name = key.split(".", 3)
        unit = {"q3_rmse_deg": "deg", "q3_max_abs_err_deg": "deg", "motor_energy_j": "J"}.get(
            name, "N*m" if name.endswith("_nm") else ""
        )
        return f"{sc} at {kg}: {name}", unit, source
    if "." in key:
        return f"{label} at {key.split('.', 1)[1].replace('deg', ' deg')}", unit, source
    return label, unit, source


def datasheet(
    catalogue: Catalogue,
    *,
    diameter_mm: float,
    length_mm: float,
    name: str | None = None,
    settings: Settings = Settings(),
    values: Mapping[str, float] | None = None,
    bands: Mapping[str, Mapping[str, float]] | None = None,
    uncertainty: Mapping[str, Any] | None = None,
    extrapolate: bool = False,
) -> dict[str, Any]:
    """The datasheet as JSON-ready data: the shaft, and every number with label, unit, source and
    (with ``bands``) its 5-95 % band."""
    vals = (
        dict(values)
        if values is not None
        else measure(
            catalogue,
            diameter_mm=diameter_mm,
            length_mm=length_mm,
            settings=settings,
            extrapolate=extrapolate,
        )
    )
    entries = {}
    for key, value in vals.items():
        label, unit, source = describe(key)
        entry: dict[str, Any] = {"value": value, "label": label, "unit": unit, "source": source}
        if bands is not None and key in bands:
            entry["band"] = {k: bands[key][k] for k in ("p05", "p50", "p95")}
        entries[key] = entry
    is_prototype = (diameter_mm, length_mm) == (PROTOTYPE_DIAMETER_MM, PROTOTYPE_LENGTH_MM)
    paper = (
        {
            "relief_nm.90deg": {
                "value": PAPER_RELIEF_NM,
                "source": "paper (seed 000 Sec. V: 'about 8 N*m', the 9 x 450 mm prototype)",
            }
        }
        if is_prototype
        else {}
    )
    return {
        "shaft": {
            "name": name or f"D{diameter_mm:g}-L{length_mm:g}",
            "diameter_mm": diameter_mm,
            "length_mm": length_mm,
            "catalogue": catalogue.source,
        },
        "settings": {
            "bends_deg": list(settings.bends_deg),
            "bench_bends_deg": list(settings.bench_bends_deg) if settings.simulate else [],
            "scenarios": list(settings.scenarios) if settings.simulate else [],
            "payloads_kg": list(settings.payloads_kg) if settings.simulate else [],
            "duration_s": settings.duration_s,
            "controller": "default (SimConfig(); gain-scheduled torque loop)",
        },
        "numbers": entries,
        "paper": paper,
        "uncertainty": dict(uncertainty) if uncertainty is not None else None,
    }


def series_of(sheet: Mapping[str, Any], head: str, bends: Sequence[float]) -> list[float]:
    """The per-bend values of one quantity, in the order of ``bends``."""
    nums = sheet["numbers"]
    return [nums.get(f"{head}.{_b(b)}", {"value": math.nan})["value"] for b in bends]


def picks(
    catalogue: Catalogue,
    names: Sequence[str],
    *,
    every: bool = False,
    diameter_mm: float | None = None,
    length_mm: float | None = None,
    extrapolate: bool = False,
) -> list[tuple[str | None, float, float]]:
    """The shafts to describe, (name or None, D, L): catalogue shafts by name, ``every`` one of
    them, and a D/L pair; each checked against the catalogue's validity before the first is
    computed."""
    out: list[tuple[str | None, float, float]] = []
    known = {s.name: s for s in catalogue.shafts}
    for wanted in names:
        if wanted not in known:
            raise DatasheetError(
                f"--shaft {wanted!r} is not in {catalogue.source}; its shafts: {', '.join(known)}"
            )
        out.append((wanted, known[wanted].diameter_mm, known[wanted].length_mm))
    if every:
        out += [(s.name, s.diameter_mm, s.length_mm) for s in catalogue.shafts]
    if (diameter_mm is None) != (length_mm is None):
        raise DatasheetError("give both --diameter-mm and --length-mm (or a --shaft)")
    if diameter_mm is not None and length_mm is not None:
        out.append((None, diameter_mm, length_mm))
    if not out:
        raise DatasheetError(
            "say which shaft: --shaft NAME, --all, or --diameter-mm D --length-mm L"
        )
    for _, d, ell in out:
        catalogue.shaft(d, ell, extrapolate=extrapolate)
    return out


def sheet_for(
    catalogue: Catalogue,
    pick: tuple[str | None, float, float],
    settings: Settings,
    *,
    samples: int = 0,
    controller: str = "nominal",
    extrapolate: bool = False,
) -> dict[str, Any]:
    """The datasheet of one pick (:func:`picks`), with ``samples`` > 0 every number's 5-95 %
    band over the catalogue's coefficient ranges (``controller``: "nominal" keeps the
    catalogue shaft in the controller, "matched" gives it each sample's)."""
    import functools

    from fsarm_sim.studies import uncertainty as unc

    name, d, ell = pick
    metric = functools.partial(
        measure, diameter_mm=d, length_mm=ell, settings=settings, extrapolate=extrapolate
    )
    values = metric(catalogue)
    bands, report = None, None
    if samples:
        if controller == "nominal":
            metric = functools.partial(
                metric, controller_shaft=catalogue.shaft(d, ell, extrapolate=extrapolate)
            )
        prop = unc.propagate(metric, catalogue, samples)
        report = unc.to_json(prop, controller=controller)
        bands = report.pop("metrics")
    return datasheet(
        catalogue,
        diameter_mm=d,
        length_mm=ell,
        name=name,
        settings=settings,
        values=values,
        bands=bands,
        uncertainty=report,
        extrapolate=extrapolate,
    )
