"""The controller's Maxwell-slip model of the shaft (``Gains.hysteresis_model``): names, checks,
and the identified default.

Twelve numbers in this order (``controllers/joint3_hysteresis.py``, ``layout.P_HM``):
``k_pos, s_pos, k_neg, s_neg`` (the model's spring per twist sign, straight and slope in |phi_B|),
``k1, k2, k3`` (element stiffnesses), ``f1, f2, f3`` (straight winding-side slip torques),
``unwinding_ratio`` and ``bend_friction_per_rad``.

The default, used when ``Gains.hysteresis_model`` is empty, is **identified** - never read from
the plant: ``scripts/identify_hysteresis_model.py`` runs seed 000's series test on the simulated
bench of the catalogue's prototype (9 x 450 mm, bends 0/45/90 deg), fits the model to those
records (:func:`fsarm_sim.studies.hysteresis_id.identify`) and writes the result into
``data/hysteresis_model.toml`` as fractions: stiffnesses of the shaft's straight eq. 3 winding
stiffness, slip torques of its rating. For another shaft the fractions are scaled by that shaft's
eq. 3 and rating (the controller's own shaft model, ``SimConfig.controller_shaft``), as the
catalogue scales its plant elements; for a shaft whose hysteresis is known to differ, identify
from its own bench records (``fsarm identify-hysteresis``) and pass the twelve numbers.
"""

from __future__ import annotations

import functools
import math
import tomllib
from importlib import resources
from pathlib import Path

from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.shaft import ShaftParams

NAMES: tuple[str, ...] = (
    "k_pos",
    "s_pos",
    "k_neg",
    "s_neg",
    "k1",
    "k2",
    "k3",
    "f1",
    "f2",
    "f3",
    "unwinding_ratio",
    "bend_friction_per_rad",
)
UNITS: tuple[str, ...] = (
    "N*m/rad",
    "N*m/rad^2",
    "N*m/rad",
    "N*m/rad^2",
    "N*m/rad",
    "N*m/rad",
    "N*m/rad",
    "N*m",
    "N*m",
    "N*m",
    "-",
    "1/rad",
)
DATA_FILE = "hysteresis_model.toml"
BEND_LIMIT_RAD = 2.0 * math.pi / 3.0  # seed 000 Sec. IV-C: phi_B in [-2pi/3, 2pi/3]


class HysteresisModelError(InvalidParameterError):
    """Bad parameters of the controller's hysteresis model (the message names which and why)."""


def check(values: tuple[float, ...]) -> None:
    """Raise :class:`HysteresisModelError` unless ``values`` is a valid model (or empty)."""
    if len(values) == 0:
        return
    if len(values) != len(NAMES):
        raise HysteresisModelError(
            f"hysteresis_model needs {len(NAMES)} numbers ({', '.join(NAMES)}) or none (the "
            f"identified default), got {len(values)}"
        )
    v = dict(zip(NAMES, (float(x) for x in values), strict=True))
    for name, x in v.items():
        if not math.isfinite(x):
            raise HysteresisModelError(f"hysteresis_model.{name} must be finite, got {x!r}")
    for side in ("pos", "neg"):
        k, s = v[f"k_{side}"], v[f"s_{side}"]
        if k <= 0.0 or k + min(s, 0.0) * BEND_LIMIT_RAD <= 0.0:
            raise HysteresisModelError(
                f"hysteresis_model spring k_{side} = {k!r} N*m/rad with slope s_{side} = {s!r} "
                f"N*m/rad^2 must stay > 0 up to the largest bend {BEND_LIMIT_RAD:.4g} rad"
            )
    for i in (1, 2, 3):
        k, f = v[f"k{i}"], v[f"f{i}"]
        if k < 0.0 or f < 0.0:
            raise HysteresisModelError(
                f"hysteresis_model element {i}: stiffness k{i} = {k!r} and slip torque f{i} = "
                f"{f!r} must be >= 0"
            )
        if k > 0.0 and f <= 0.0:
            raise HysteresisModelError(
                f"hysteresis_model element {i} has stiffness {k!r} N*m/rad but slip torque "
                f"{f!r} N*m: an element with k > 0 needs f > 0"
            )
    if v["unwinding_ratio"] <= 0.0:
        raise HysteresisModelError(
            f"hysteresis_model.unwinding_ratio must be > 0, got {v['unwinding_ratio']!r}"
        )
    if v["bend_friction_per_rad"] < 0.0:
        raise HysteresisModelError(
            "hysteresis_model.bend_friction_per_rad must be >= 0, got "
            f"{v['bend_friction_per_rad']!r}"
        )


@functools.cache
def default_fractions() -> dict[str, float]:
    """The identified default as fractions (``data/hysteresis_model.toml``, ``[fractions]``)."""
    text = resources.files("fsarm_sim.data").joinpath(DATA_FILE).read_text("utf-8")
    raw = tomllib.loads(text)["fractions"]
    return {k: float(raw[k]) for k in NAMES}


def scaled(fractions: dict[str, float], shaft: ShaftParams) -> tuple[float, ...]:
    """The twelve numbers for ``shaft``: stiffnesses x its straight eq. 3 winding stiffness,
    slip torques x its rating, the two ratios as they are."""
    k0, rating = shaft.k_pos, shaft.rating_nm
    out = []
    for name in NAMES:
        x = fractions[name]
        if name.startswith(("k", "s")):
            x *= k0
        elif name in ("f1", "f2", "f3"):
            x *= rating
        out.append(x)
    return tuple(out)


def fractions_of(values: tuple[float, ...], shaft: ShaftParams) -> dict[str, float]:
    """:func:`scaled` inverted: a model of ``shaft`` as fractions."""
    k0, rating = shaft.k_pos, shaft.rating_nm
    out = {}
    for name, x in zip(NAMES, values, strict=True):
        if name.startswith(("k", "s")):
            x /= k0
        elif name in ("f1", "f2", "f3"):
            x /= rating
        out[name] = float(x)
    return out


def resolve(values: tuple[float, ...], shaft: ShaftParams) -> tuple[float, ...]:
    """The model a run uses: ``values`` if given, else the identified default for ``shaft``."""
    check(values)
    return tuple(float(x) for x in values) if values else scaled(default_fractions(), shaft)


def model_toml(values: tuple[float, ...], comment: str = "") -> str:
    """A model file's text: ``[model]`` with the twelve numbers by name (:func:`load_file`)."""
    check(values)
    head = [f"# {line}" for line in comment.splitlines()]
    body = [f"{k} = {float(v)!r}  # {u}" for k, v, u in zip(NAMES, values, UNITS, strict=True)]
    return "\n".join([*head, "[model]", *body]) + "\n"


def load_file(path: str | Path) -> tuple[float, ...]:
    """The twelve numbers of a model file (``[model]``, every name of :data:`NAMES` once);
    :class:`HysteresisModelError` naming the file and what is wrong otherwise."""
    p = Path(path)
    try:
        raw = tomllib.loads(p.read_text("utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise HysteresisModelError(f"hysteresis model file {p}: cannot read it ({exc})") from None
    model = raw.get("model")
    if not isinstance(model, dict) or set(raw) != {"model"}:
        raise HysteresisModelError(
            f"hysteresis model file {p}: needs exactly one table [model] with {', '.join(NAMES)}"
        )
    missing = [k for k in NAMES if k not in model]
    unknown = [k for k in model if k not in NAMES]
    if missing or unknown:
        raise HysteresisModelError(
            f"hysteresis model file {p}: "
            + (f"missing {', '.join(missing)}" if missing else "")
            + ("; " if missing and unknown else "")
            + (f"unknown {', '.join(unknown)}" if unknown else "")
            + f"; allowed: {', '.join(NAMES)}"
        )
    values = []
    for k in NAMES:
        v = model[k]
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise HysteresisModelError(
                f"hysteresis model file {p}: {k} must be a number, got {v!r}"
            )
        values.append(float(v))
    out = tuple(values)
    try:
        check(out)
    except HysteresisModelError as exc:
        raise HysteresisModelError(f"hysteresis model file {p}: {exc}") from None
    return out
