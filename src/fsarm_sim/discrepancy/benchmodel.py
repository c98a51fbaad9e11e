"""A bench model: the nominal model of a setup plus named effects with their parameters.

This is what ``fsarm diagnose`` writes as its final model and what ``fsarm synth`` (and the replay
engine) load: a JSON file ::

    {"format": "fsarm-bench-model", "version": 1,
     "setup": "series_bench", "load": {"type": "blocked"},
     "shaft": {"diameter_mm": 9.0, "length_mm": 450.0},
     "nominal": {"k_pos": 15.0, "s_pos": -2.9, "k_neg": 12.0, "s_neg": -2.2},
     "effects": [{"name": "coulomb_friction", "variant": "shaft", "params": {"f_c_nm": 0.2}}]}

Nominal parameters (SI): series bench ``k_pos, s_pos, k_neg, s_neg`` (eq. 3/8: K = k + s |phi_B|
per twist sign) and ``j_load`` (inertia load only); parallel bench ``kb`` (eq. 2: M = K_b phi)
and ``j_link`` (inertia of the bending link about the joint, seen by the torque sensor).
Effect parameters: see :mod:`fsarm_sim.plant.effects.registry` (hysteresis takes lists, one value per
element or branch; nonlinear stiffness also stores its reference deflection ``x_ref_rad``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fsarm_sim.discrepancy import variants
from fsarm_sim.errors import FsarmError
from fsarm_sim.paths import read_json_file
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.shaft import ShaftParams

if TYPE_CHECKING:
    from fsarm_sim.records.measured import Dataset

FORMAT = "fsarm-bench-model"
VERSION = 1
NOMINAL_KEYS = {
    "series_bench": ("k_pos", "s_pos", "k_neg", "s_neg", "j_load"),
    "parallel_bench": ("kb", "j_link"),
}
MAX_ELEMENTS = 8  # hysteresis elements / branches a model may hold (replay kernel arrays)


class ModelFileError(FsarmError, ValueError):
    """A bench-model file (or dict) is malformed."""


@dataclass
class EffectInstance:
    name: str
    variant: str
    params: dict[str, Any]

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "variant": self.variant, "params": dict(self.params)}

    @property
    def label(self) -> str:
        return f"{self.name}[{self.variant}]"


@dataclass
class BenchModel:
    setup: str
    nominal: dict[str, float]
    effects: list[EffectInstance] = field(default_factory=list)
    load_inertia_kgm2: float | None = None  # series: None = blocked; the *stated* inertia
    shaft: dict[str, float] = field(default_factory=dict)

    @property
    def inertia_load(self) -> bool:
        return self.setup == "series_bench" and self.load_inertia_kgm2 is not None

    def with_effect(self, eff: EffectInstance) -> BenchModel:
        return BenchModel(
            self.setup,
            dict(self.nominal),
            [*self.effects, eff],
            self.load_inertia_kgm2,
            dict(self.shaft),
        )

    def copy(self) -> BenchModel:
        return BenchModel(
            self.setup,
            dict(self.nominal),
            [EffectInstance(e.name, e.variant, dict(e.params)) for e in self.effects],
            self.load_inertia_kgm2,
            dict(self.shaft),
        )

    def effect(self, name: str, variant: str | None = None) -> EffectInstance | None:
        for e in self.effects:
            if e.name == name and (variant is None or e.variant == variant):
                return e
        return None

    def as_dict(self) -> dict[str, Any]:
        load: dict[str, Any] = {"type": "blocked"}
        if self.load_inertia_kgm2 is not None:
            load = {"type": "inertia", "inertia_kgm2": self.load_inertia_kgm2}
        return {
            "format": FORMAT,
            "version": VERSION,
            "setup": self.setup,
            "load": load,
            "shaft": dict(self.shaft),
            "nominal": dict(self.nominal),
            "effects": [e.as_dict() for e in self.effects],
        }


def nominal_from_shaft(
    setup: str, shaft: ShaftParams, load_inertia_kgm2: float | None = None, j_link: float = 0.0
) -> BenchModel:
    """The nominal model with the catalogue's (stated) parameters, before any refit."""
    dims = {"diameter_mm": shaft.diameter_mm, "length_mm": shaft.length_mm}
    if setup == "series_bench":
        nom = {
            "k_pos": shaft.k_pos,
            "s_pos": shaft.s_pos,
            "k_neg": shaft.k_neg,
            "s_neg": shaft.s_neg,
        }
        if load_inertia_kgm2 is not None:
            nom["j_load"] = load_inertia_kgm2
        return BenchModel(setup, nom, [], load_inertia_kgm2, dims)
    if setup == "parallel_bench":
        return BenchModel(setup, {"kb": shaft.kb, "j_link": j_link}, [], None, dims)
    raise ModelFileError(
        f"no bench model for setup {setup!r} (bench setups: series_bench, parallel_bench)"
    )


POLY_KEYS = ("poly", "poly_per_sign")  # its variants in r = x / x_ref (registry)


def uses_x_ref(name: str, variant: str) -> bool:
    """The effect's law is a polynomial in x / x_ref: the model stores ``x_ref_rad``."""
    return name == variants.NONLINEAR and variant in POLY_KEYS


def element_wise(var: registry.Variant) -> bool:
    """The variant's parameters come one per element (lists: the registry's "(each)")."""
    return bool(var.params) and all("(each)" in p.meaning for p in var.params)


def stated_model(ds: Dataset) -> BenchModel:
    """The nominal model of a dataset's setup with the catalogue's / sidecar's parameters."""
    return nominal_from_shaft(ds.setup, ds.shaft, ds.load_inertia_kgm2, j_link=0.0)


def _check_number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ModelFileError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _check_effect(setup: str, inertia: bool, raw: Any, i: int) -> EffectInstance:
    if not isinstance(raw, dict) or "name" not in raw or "variant" not in raw:
        raise ModelFileError(f"effects[{i}] must be an object with 'name', 'variant', 'params'")
    try:
        eff = registry.get(str(raw["name"]))
        var = eff.variant(str(raw["variant"]))
    except KeyError as exc:
        raise ModelFileError(f"effects[{i}]: {exc.args[0]}") from None
    if setup not in var.setups or (var.needs_inertia_load and not inertia):
        raise ModelFileError(
            f"effects[{i}]: {eff.name}[{var.key}] does not act in a {setup}"
            + (" with a blocked output" if var.needs_inertia_load else "")
        )
    params = raw.get("params", {})
    if not isinstance(params, dict):
        raise ModelFileError(f"effects[{i}].params must be an object")
    out: dict[str, Any] = {}
    for p in var.params:
        if p.name not in params:
            raise ModelFileError(f"effects[{i}] ({eff.name}[{var.key}]) needs parameter '{p.name}'")
        v = params[p.name]
        vals = v if isinstance(v, list) else [v]
        if element_wise(var) and not isinstance(v, list):
            raise ModelFileError(f"effects[{i}].params.{p.name} must be a list (one per element)")
        if len(vals) > MAX_ELEMENTS:
            raise ModelFileError(f"effects[{i}].params.{p.name}: at most {MAX_ELEMENTS} elements")
        checked = []
        for j, x in enumerate(vals):
            xv = _check_number(x, f"effects[{i}].params.{p.name}[{j}]")
            if not p.lower <= xv <= p.upper:
                raise ModelFileError(
                    f"effects[{i}].params.{p.name} = {xv:g} {p.unit} is outside "
                    f"[{p.lower:g}, {p.upper:g}] ({p.meaning})"
                )
            checked.append(xv)
        out[p.name] = checked if isinstance(v, list) else checked[0]
    if element_wise(var) and len({len(params[p.name]) for p in var.params}) > 1:
        raise ModelFileError(f"effects[{i}]: {eff.name} parameter lists differ in length")
    if uses_x_ref(eff.name, var.key):
        out["x_ref_rad"] = _check_number(params.get("x_ref_rad", 1.0), f"effects[{i}].x_ref_rad")
        if out["x_ref_rad"] <= 0:
            raise ModelFileError(f"effects[{i}].params.x_ref_rad must be > 0")
    for extra in ("note", "masterflex08_scale"):
        if extra in params:
            out[extra] = params[extra]
    return EffectInstance(eff.name, var.key, out)


def model_from_dict(data: Any, source: str = "model") -> BenchModel:
    """Validate a parsed model file."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ModelFileError(f"{source}: not an {FORMAT} file (missing 'format': '{FORMAT}')")
    setup = data.get("setup")
    if setup not in NOMINAL_KEYS:
        raise ModelFileError(
            f"{source}: 'setup' must be one of {list(NOMINAL_KEYS)}, got {setup!r}"
        )
    load = data.get("load", {"type": "blocked"})
    inertia: float | None = None
    if setup == "series_bench" and isinstance(load, dict) and load.get("type") == "inertia":
        inertia = _check_number(load.get("inertia_kgm2"), f"{source}: load.inertia_kgm2")
    nominal_raw = data.get("nominal", {})
    if not isinstance(nominal_raw, dict):
        raise ModelFileError(f"{source}: 'nominal' must be an object")
    nominal = {}
    for k, v in nominal_raw.items():
        if k not in NOMINAL_KEYS[setup]:
            raise ModelFileError(f"{source}: unknown nominal parameter {k!r} for {setup}")
        nominal[k] = _check_number(v, f"{source}: nominal.{k}")
    need = ("k_pos", "k_neg") if setup == "series_bench" else ("kb",)
    for k in need:
        if k not in nominal:
            raise ModelFileError(f"{source}: nominal.{k} is required")
    nominal.setdefault("s_pos", 0.0) if setup == "series_bench" else nominal.setdefault(
        "j_link", 0.0
    )
    if setup == "series_bench":
        nominal.setdefault("s_neg", 0.0)
        if inertia is not None:
            nominal.setdefault("j_load", inertia)
    effects_raw = data.get("effects", [])
    if not isinstance(effects_raw, list):
        raise ModelFileError(f"{source}: 'effects' must be a list")
    effects = [_check_effect(setup, inertia is not None, e, i) for i, e in enumerate(effects_raw)]
    shaft = data.get("shaft", {})
    return BenchModel(
        setup, nominal, effects, inertia, dict(shaft) if isinstance(shaft, dict) else {}
    )


def load_model(path: str | Path) -> BenchModel:
    p = Path(path)
    data = read_json_file(p, "model file", ModelFileError, "cannot read model file {p}: {exc}")
    return model_from_dict(data, str(p))


def save_model(model: BenchModel, path: str | Path) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(model.as_dict(), indent=2) + "\n", "utf-8")
    return p
