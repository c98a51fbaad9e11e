"""The arm's final-model file: what ``fsarm diagnose`` writes for an arm record, and loading it
back as a :class:`~fsarm_sim.engine.model.SimConfig` the simulator runs (``load_arm_config``).

Format ``fsarm-arm-model`` (JSON): the stated setup (shaft - D/L and, for the model of a record
of ``fsarm run``, its exact ``shaft_params`` -, payload, control period, gains;
``transmission`` and ``integrator`` when not the defaults), the nominal refit (stiffness scales, K_b scale, payload), the named effects with their fitted
parameters, and - for reading by eye - the resulting plant. Recording effects (channel offsets,
delays) are kept in the file; :func:`fsarm_sim.discrepancy.arm.apply_measurement` adds them to
a run's columns.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import arm_fit, arm_model, arm_run, arm_screen, variants
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import FsarmError
from fsarm_sim.paths import read_json_file
from fsarm_sim.plant import transmissions
from fsarm_sim.records.measured import resolve_shaft
from fsarm_sim.records.sidecar import as_record, shaft_params_entry


def model_dict(run: arm_run.ArmRun, m: arm_model.ArmModel) -> dict[str, Any]:
    """The model file: stated setup, nominal refit, named effects, and the resulting plant."""
    cfg = arm_model.to_config(run, m)
    g = dataclasses.asdict(run.gains)
    stated: dict[str, Any] = {}
    if not run.flexible_shaft:
        stated["transmission"] = {
            "name": run.transmission,
            "params": dict(run.transmission_params),
            "controller_params": dict(
                run.controller_transmission_params or run.transmission_params
            ),
        }
    if run.integrator is not None:
        stated["integrator"] = run.integrator
    return {
        "format": arm_fit.MODEL_FORMAT,
        "version": arm_fit.MODEL_VERSION,
        "setup": "arm",
        "shaft": {"diameter_mm": run.shaft.diameter_mm, "length_mm": run.shaft.length_mm},
        **({"shaft_params": shaft_params_entry(run.shaft)} if run.exact_shaft else {}),
        "payload_kg": run.payload_kg,
        "ctrl_dt_s": run.ctrl_dt,
        "gains": {k: list(v) if isinstance(v, tuple) else v for k, v in g.items()},
        "timestep_s": run.timestep_s,
        **stated,
        "nominal": m.nominal(),
        "effects": [e.as_dict() for e in m.effects()],
        "plant": {
            "k_pos": cfg.shaft.k_pos,
            "s_pos": cfg.shaft.s_pos,
            "k_neg": cfg.shaft.k_neg,
            "s_neg": cfg.shaft.s_neg,
            "kb": cfg.shaft.kb,
            "slip_k": list(cfg.shaft.slip_k),
            "slip_f": list(cfg.shaft.slip_f),
            **dataclasses.asdict(cfg.effects),
        },
    }


class ArmModelFileError(FsarmError, ValueError):
    """An arm model file is malformed."""


def model_from_dict(
    d: Mapping[str, Any], where: str = "arm model"
) -> tuple[arm_model.ArmModel, arm_run.ArmRun]:
    """(model, stated run without references) from a model-file dict."""
    if d.get("format") != arm_fit.MODEL_FORMAT or d.get("setup") != "arm":
        raise ArmModelFileError(
            f"{where}: not an arm model file (format {arm_fit.MODEL_FORMAT!r}, setup 'arm')"
        )
    try:
        stated = {"setup": "arm", "shaft": d["shaft"]}
        exact = d.get("shaft_params") is not None
        if exact:  # the run's exact shaft (the model of a record of fsarm run)
            stated["shaft_params"] = d["shaft_params"]
        shaft = resolve_shaft(as_record(stated, where), Path(where))
        side = {"gains": d.get("gains", {}), "ctrl_dt_s": d["ctrl_dt_s"]}
        gains = arm_run.parse_gains(side, Path(where))
        m = arm_model.ArmModel()
        for k, v in dict(d.get("nominal", {})).items():
            if k in ("k_scale_pos", "k_scale_neg"):
                if not float(v) > 0.0:
                    raise ArmModelFileError(f"{where}: {k} must be > 0, got {v!r}")
                m.values["c_scale_" + k[-3:]] = 1.0 / float(v)
            elif k in ("kb_scale", "payload_kg_refit"):
                m.values[k] = float(v)
            else:
                raise ArmModelFileError(f"{where}: unknown nominal parameter {k!r}")
        for e in d.get("effects", []):
            add_effect(m, str(e["name"]), str(e["variant"]), dict(e["params"]), where)
        tr = d.get("transmission")
        if tr is not None:
            rec = as_record({"setup": "arm", "transmission": tr}, where)
            tr_name, tr_params, tr_ctrl = arm_run.stated_transmission(rec, Path(where))
        else:
            tr_name, tr_params, tr_ctrl = transmissions.DEFAULT, (), None
        integrator = d.get("integrator")
        if integrator is not None and not isinstance(integrator, str):
            raise ArmModelFileError(f"{where}: 'integrator' must be a string, got {integrator!r}")
        run = arm_run.ArmRun(
            shaft=shaft,
            payload_kg=float(d.get("payload_kg", 0.0)),
            payload_tolerance_kg=0.0,
            gains=gains,
            timestep_s=d.get("timestep_s"),
            ref_table=np.zeros((1, 9)),
            t=np.zeros(1),
            h=float(d["ctrl_dt_s"]),
            ref_note="",
            transmission=tr_name,
            transmission_params=tr_params,
            controller_transmission_params=tr_ctrl,
            integrator=integrator,
            exact_shaft=exact,
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, ArmModelFileError):
            raise
        raise ArmModelFileError(f"{where}: malformed arm model ({exc})") from exc
    return m, run


def add_effect(
    m: arm_model.ArmModel, name: str, variant: str, p: Mapping[str, Any], where: str
) -> None:
    """Add a named effect with its parameters (the arm's variants: :data:`.variants.ARM`)."""
    label = f"{name}[{variant}]"
    if (name, variant) in arm_screen.MEASUREMENT_CANDIDATES:  # one parameter: the channel's
        m.values[f"{name}.{variant}"] = float(p[variants.ARM[name][0].params[0].name])
    elif (name, variant) in arm_screen.PLANT_CANDIDATES and name == variants.HYSTERESIS:
        ks, ds_ = list(p["k_nm_per_rad"]), list(p["delta_rad"])
        if len(ks) != len(ds_) or not 1 <= len(ks) <= variants.ARM_MAX_ELEMENTS:
            raise ArmModelFileError(
                f"{where}: hysteresis needs 1-{variants.ARM_MAX_ELEMENTS} (k, delta) elements"
            )
        m.set_slip([float(k) for k in ks], [float(x) for x in ds_])
    elif (name, variant) in arm_screen.PLANT_CANDIDATES:
        for k, v in p.items():
            if f"{name}.{k}" not in arm_model.BOUNDS:
                raise ArmModelFileError(f"{where}: unknown parameter {k!r} of {label}")
            m.values[f"{name}.{k}"] = float(v)
        for (
            e,
            q,
        ), default in variants.ARM_DEFAULTS.items():  # optional parameters (backlash centre)
            if e == name:
                m.values.setdefault(f"{name}.{q}", default)
    else:
        raise ArmModelFileError(
            f"{where}: unknown arm effect {label}; known: "
            + ", ".join(
                f"{a}[{b}]"
                for a, b in arm_screen.PLANT_CANDIDATES + arm_screen.MEASUREMENT_CANDIDATES
            )
        )
    for k, v in m.values.items():
        if k in arm_model.BOUNDS and not arm_model.BOUNDS[k][0] <= v <= arm_model.BOUNDS[k][1]:
            raise ArmModelFileError(
                f"{where}: {k} = {v:g} outside [{arm_model.BOUNDS[k][0]:g}, {arm_model.BOUNDS[k][1]:g}]"
            )
    m.labels.append(label)


def save_arm_model(run: arm_run.ArmRun, m: arm_model.ArmModel, path: str | Path) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(jsonable(model_dict(run, m)), indent=2) + "\n", "utf-8")
    return p


def jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [jsonable(v) for v in x]
    if isinstance(x, np.floating | np.integer):
        return x.item()
    return x


def load_arm_model(path: str | Path) -> tuple[arm_model.ArmModel, arm_run.ArmRun]:
    p = Path(path)
    d = read_json_file(p, "model file", ArmModelFileError, "{p}: not a readable JSON file ({exc})")
    return model_from_dict(d, str(p))


def load_arm_config(path: str | Path) -> SimConfig:
    """The simulator configuration of an arm model file (``fsarm diagnose`` writes it).

    Run it with ``run_scenario(name, cfg, payload_kg=cfg.payload_kg, backend="native")``. The
    measurement effects (sensor offsets, delays) are not part of the plant: apply them to a run's
    columns with :func:`apply_measurement` (``load_arm_model(path)[0]`` is the model).
    """
    m, run = load_arm_model(path)
    return arm_model.to_config(run, m)
