"""SYNTHETIC arm records for tests and demos: ``fsarm synth --setup arm``.

The scenario is run by the simulator with a hidden truth (:class:`~fsarm_sim.discrepancy.arm.
ArmModel`: stiffness scales and effects) acting on the plant only - the controller keeps the
stated model - and recorded the way :mod:`fsarm_sim.discrepancy.arm` reads arm records: the
truth's channel delays and offsets, Gaussian angle noise, encoder quantisation. The hidden truth
goes into the sidecar under ``"synthetic"`` (never read by ``fsarm diagnose``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import arm_model, arm_modelfile, arm_run
from fsarm_sim.discrepancy.effect_text import parse_effect
from fsarm_sim.engine.model import Gains
from fsarm_sim.errors import InvalidParameterError, real_number
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects.registry import ARM
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.records import sidecar as records
from fsarm_sim.records.measured import stated_shaft, write_dataset
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import DEFAULT_TIMESTEP_S

FloatArray = npt.NDArray[np.float64]

ARM_ENCODER_COUNTS = 131072  # 17-bit absolute encoders on every angle (estimate, as synth.py)
ARM_NOISE_RAD = 2e-5  # angle noise std: a few counts of a 17-bit encoder (estimate)


@dataclass(frozen=True)
class ArmRecording:
    """How the synthetic arm run is recorded."""

    scenario: str = "fig14-sine"
    duration_s: float | None = None  # None: the scenario's
    payload_kg: float | None = None  # stated payload; None: the scenario's
    noise_rad: float = ARM_NOISE_RAD
    encoder_counts: int = ARM_ENCODER_COUNTS
    seed: int = 0
    derivatives: bool = True  # write qd*_ref / qdd*_ref
    transmission: str = transmissions.DEFAULT  # joint 3's (its default parameters)
    # samples per second of the record; None: the control rate (1 kHz). Slower: every k-th
    # control tick (the control rate / k, k whole); faster: the controller runs at this rate
    # (its period is the sample period, as a record's ctrl_dt_s states it)
    rate_hz: float | None = None

    def validate(self) -> None:
        for name in ("duration_s", "payload_kg", "rate_hz"):
            if getattr(self, name) is not None:
                real_number(getattr(self, name), name)  # True is not 1 s
        if not math.isfinite(real_number(self.noise_rad, "noise_rad")) or self.noise_rad < 0.0:
            raise InvalidParameterError(f"noise_rad must be >= 0, got {self.noise_rad!r}")
        if self.rate_hz is not None:
            self.sampling(Gains().ctrl_dt_s)
        if self.encoder_counts < 0:
            raise InvalidParameterError("encoder_counts must be >= 0")
        if self.transmission not in transmissions.names():
            raise InvalidParameterError(
                f"unknown transmission {self.transmission!r} "
                f"(known: {', '.join(transmissions.names())})"
            )

    def sampling(self, ctrl_dt_s: float) -> tuple[float, int]:
        """(the controller's period, control ticks per sample) of this record's rate."""
        if self.rate_hz is None:
            return ctrl_dt_s, 1
        rate = self.rate_hz
        if not (math.isfinite(rate) and MIN_RATE_HZ <= rate <= MAX_RATE_HZ):
            raise InvalidParameterError(
                f"arm record rate must be {MIN_RATE_HZ:g}-{MAX_RATE_HZ:g} Hz, got {rate!r}"
            )
        if rate >= 1.0 / ctrl_dt_s:
            return 1.0 / rate, 1  # the controller at the record's rate
        k = round(1.0 / (rate * ctrl_dt_s))
        if abs(k * ctrl_dt_s * rate - 1.0) > 1e-9:
            raise InvalidParameterError(
                f"an arm record slower than the {1 / ctrl_dt_s:g} Hz controller samples every "
                f"k-th tick: its rate must be {1 / ctrl_dt_s:g} Hz / k (k whole), got {rate:g} Hz"
            )
        return ctrl_dt_s, k


MIN_RATE_HZ = 100.0  # an arm record slower than this cannot follow the 0.1-1 Hz scenarios' loops
MAX_RATE_HZ = 5000.0  # estimate: the scenarios' loops gain nothing from a faster controller


def parse_arm_effect(text: str) -> tuple[str, str, dict[str, Any]]:
    """``NAME[:VARIANT]=v1[,v2...]`` -> (name, variant, params) of an arm effect: the effect
    text of every setup (:mod:`.effect_text`) with the arm's variants (:data:`.variants.ARM`).

    payload_error=DM_KG; coulomb_friction=F_NM; viscous_damping=B_NMS; backlash=W[,C];
    hysteresis=K1,D1[,K2,D2[,K3,D3]]; sensor_offset:CH=RAD; delay:CH=S (CH: q3, theta_m, q2).
    """
    e = parse_effect(text, ARM)
    m = arm_model.ArmModel()
    try:
        arm_modelfile.add_effect(m, e.name, e.variant, e.params, f"effect {text!r}")
    except arm_modelfile.ArmModelFileError as exc:
        raise InvalidParameterError(str(exc)) from None
    return e.name, e.variant, e.params


def truth_model(
    effects: list[str] | None = None, *, stiffness_scale: float = 1.0, kb_scale: float = 1.0
) -> arm_model.ArmModel:
    """A synthetic truth: stiffness scales (true / catalogue) plus the parsed effects."""
    m = arm_model.ArmModel()
    if not stiffness_scale > 0.0 or not kb_scale > 0.0:
        raise InvalidParameterError("stiffness and K_b scales must be > 0")
    m.values.update(c_scale=1.0 / stiffness_scale, kb_scale=kb_scale)
    for text in effects or []:
        name, variant, p = parse_arm_effect(text)
        arm_modelfile.add_effect(m, name, variant, p, f"effect {text!r}")
    return m


def _quantise(x: FloatArray, counts: int) -> FloatArray:
    if counts <= 0:
        return x
    q = 2.0 * math.pi / counts
    return np.asarray(np.round(x / q) * q + 0.0, dtype=np.float64)  # + 0.0: no "-0" cells


Disturbance = Callable[[FloatArray, dict[str, FloatArray]], dict[str, FloatArray]]


@dataclass(frozen=True)
class _ArmTicks:
    """The synthetic run's timing and reference: the control ticks, their reference table and
    the record's sampling."""

    run: arm_run.ArmRun
    gains: Gains
    timestep: float | None
    duration: float
    payload: float
    every: int  # control ticks per sample


def _arm_ticks(rec: ArmRecording, sh: ShaftParams) -> _ArmTicks:
    """The run of ``rec``'s scenario at its rate (the truth not yet applied)."""
    sc = scenarios.get(rec.scenario)
    ctrl_dt, every = rec.sampling(Gains().ctrl_dt_s)
    gains = Gains(ctrl_dt_s=ctrl_dt)
    # a controller faster than the model's physics step steps the physics at its own period
    timestep = ctrl_dt if ctrl_dt < DEFAULT_TIMESTEP_S * (1.0 - 1e-9) else None
    duration = float(sc.duration_s if rec.duration_s is None else rec.duration_s)
    payload = float(sc.payload_kg if rec.payload_kg is None else rec.payload_kg)
    n_ticks = round(duration / ctrl_dt) + 1
    t_ticks: FloatArray = np.arange(n_ticks, dtype=np.float64) * ctrl_dt
    table = sc.reference(np.arange(n_ticks + 1, dtype=np.float64) * ctrl_dt)
    run = arm_run.ArmRun(
        sh,
        payload,
        0.0,
        gains,
        timestep,
        table,
        t_ticks,
        ctrl_dt,
        "",
        transmission=rec.transmission,
    )
    return _ArmTicks(run, gains, timestep, duration, payload, every)


def _arm_columns(
    ticks: _ArmTicks,
    truth: arm_model.ArmModel,
    rec: ArmRecording,
    disturbance: Disturbance | None,
) -> dict[str, FloatArray]:
    """The recorded columns: the truth's run, measured, sampled, disturbed, noisy, quantised."""
    run = ticks.run
    ctrl_dt = run.ctrl_dt
    raw, _ = arm_model.simulate_config(run, arm_model.to_config(run, truth))
    meas = arm_model.apply_measurement(raw, truth, ctrl_dt)
    # the record: every ``every``-th control tick (the truth's delays act at the control rate)
    pick = np.arange(0, run.t.size, ticks.every)
    n = pick.size
    t: FloatArray = run.t[pick]
    raw = {ch: v[pick] for ch, v in raw.items()}
    meas = {ch: v[pick] for ch, v in meas.items()}
    table = run.ref_table[pick]
    rng = np.random.default_rng(rec.seed + 104729)
    cols: dict[str, FloatArray] = {"t": t}
    clean = {ch: meas[ch] if ch in meas else raw[ch] for ch in ("q1", "q2", "q3", "theta_m")}
    extra = disturbance(t, clean) if disturbance is not None else {}
    for ch in ("q1", "q2", "q3", "theta_m"):
        y = clean[ch] + extra[ch] if ch in extra else clean[ch]
        cols[ch] = _quantise(y + rec.noise_rad * rng.standard_normal(n), rec.encoder_counts)
    for j in range(3):
        cols[f"q{j + 1}_ref"] = table[:n, j]
    if rec.derivatives:
        for j in range(3):
            cols[f"qd{j + 1}_ref"] = table[:n, 3 + j]
        for j in range(3):
            cols[f"qdd{j + 1}_ref"] = table[:n, 6 + j]
    return cols


def _arm_sidecar(
    ticks: _ArmTicks,
    truth: arm_model.ArmModel,
    rec: ArmRecording,
    cols: dict[str, FloatArray],
) -> dict[str, Any]:
    """The synthetic record's sidecar, the hidden truth under ``"synthetic"``."""
    run, gains = ticks.run, ticks.gains
    sh, ctrl_dt = run.shaft, run.ctrl_dt
    hidden = truth.labels
    side = records.Sidecar(
        schema=records.SCHEMA,
        writer=records.WRITER_SYNTH,
        setup="arm",
        shaft=records.ShaftRef(diameter_mm=sh.diameter_mm, length_mm=sh.length_mm),
        payload_kg=ticks.payload,
        ctrl_dt_s=gains.ctrl_dt_s,
        timestep_s=ticks.timestep,
        scenario=rec.scenario,
        gains=records.gains_entry(gains),
        transmission=(
            None
            if rec.transmission == transmissions.DEFAULT
            else records.TransmissionRef(rec.transmission)
        ),
        notes=(
            f"SYNTHETIC data from fsarm synth --setup arm (not a measurement): scenario "
            f"{rec.scenario}, joint 3 by {rec.transmission}, {ticks.duration:g} s at "
            f"{1 / (ticks.every * ctrl_dt):g} Hz (control at {1 / ctrl_dt:g} Hz), angle noise "
            f"{rec.noise_rad:g} rad, {rec.encoder_counts} counts/rev, hidden effects: "
            f"{', '.join(hidden) if hidden else 'none'}"
        ),
        columns={c: records.UNITS[c] for c in cols},
        synthetic=records.jsonable(
            {
                "truth": arm_modelfile.model_dict(run, truth),
                "noise_rad": rec.noise_rad,
                "encoder_counts": rec.encoder_counts,
                "seed": rec.seed,
            }
        ),
    )
    return side.to_json()


def synthesize_arm(
    truth: arm_model.ArmModel,
    rec: ArmRecording,
    shaft: ShaftParams | None = None,
    disturbance: Disturbance | None = None,
) -> tuple[dict[str, FloatArray], dict[str, Any]]:
    """(columns, sidecar) of a SYNTHETIC arm record: the scenario run by the simulator with
    ``truth`` acting on the plant (the controller keeps the stated model), recorded with the
    truth's delays and offsets, Gaussian angle noise and encoder quantisation.

    ``disturbance(t, channels)``: what outside the library adds to recorded channels (e.g. a
    pickup line, a drifting offset, an encoder's cyclic error), given the time and the channels
    as measured before noise; added before the noise and the quantisation. Not recorded in the
    sidecar's truth (the caller knows it)."""
    rec.validate()
    ticks = _arm_ticks(rec, shaft or stated_shaft())
    cols = _arm_columns(ticks, truth, rec, disturbance)
    return cols, _arm_sidecar(ticks, truth, rec, cols)


def write_arm_synthetic(
    path: str | Path,
    truth: arm_model.ArmModel,
    rec: ArmRecording,
    shaft: ShaftParams | None = None,
    disturbance: Disturbance | None = None,
) -> tuple[Path, Path]:
    cols, side = synthesize_arm(truth, rec, shaft, disturbance)
    return write_dataset(path, cols, side)
