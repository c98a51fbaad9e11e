"""The arm's model in the replay: nominal parameters and named effects (:class:`ArmModel`), the
simulator configuration they build (:func:`to_config`: refits and effects act on the plant only,
the controller keeps the stated shaft and payload), the closed-loop run of it
(:func:`simulate_config`) and the measurement effects applied to the simulated channels
(:func:`apply_measurement`). The fits are :mod:`.arm_fit`'s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import variants
from fsarm_sim.discrepancy.arm_run import ArmRun
from fsarm_sim.discrepancy.benchmodel import EffectInstance
from fsarm_sim.engine.model import PAYLOAD_MAX_KG, Effects, SimConfig
from fsarm_sim.plant.effects import registry, sensor_offset
from fsarm_sim.plant.effects.base import is_off
from fsarm_sim.sim.simulation import Simulation

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


RAW = variants.ARM_CHANNELS  # recorded channels the replay compares
SCALE_BOUNDS = (0.25, 4.0)  # stiffness scales: within 4x of the catalogue (as candidates.py)


# ----------------------------------------------------------------------------- the model

# parameter -> (lower, upper, typical magnitude: the unit of the normalised fit variable)
# effect parameters: "<effect>.<parameter>" (plant), "<effect>.<channel>" (recording),
# "hysteresis.k<i>" / "hysteresis.d<i>" (element i); bounds from the registry (.variants.ARM)
UNITS = {  # typical magnitude per registry parameter
    "dm_kg": 0.5,
    "f_c_nm": 0.1,
    "b_nms": 0.1,
    "width_rad": 0.005,
    "center_rad": 0.005,
    "k_nm_per_rad": 2.0,
    "delta_rad": 1e-3,
    "offset_rad": 1e-3,
    "delay_s": 2e-3,
}
_HK, _HD = variants.ARM[variants.HYSTERESIS][0].params
BOUNDS: dict[str, tuple[float, float, float]] = {
    "c_scale": (*SCALE_BOUNDS, 0.1),
    "c_scale_pos": (*SCALE_BOUNDS, 0.1),
    "c_scale_neg": (*SCALE_BOUNDS, 0.1),
    "kb_scale": (*SCALE_BOUNDS, 0.1),
    "payload_kg_refit": (-PAYLOAD_MAX_KG, PAYLOAD_MAX_KG, 0.5),
    **{
        f"{name}.{v.key if name in variants.ARM_RECORDING else p.name}": (
            p.lower,
            p.upper,
            UNITS.get(p.name, p.scale()),
        )
        for name, vs in variants.ARM.items()
        if name != variants.HYSTERESIS
        for v in vs
        for p in v.params
    },
    **{f"{variants.HYSTERESIS}.k{i}": (_HK.lower, _HK.upper, UNITS[_HK.name]) for i in range(3)},
    **{f"{variants.HYSTERESIS}.d{i}": (_HD.lower, _HD.upper, UNITS[_HD.name]) for i in range(3)},
}
# The series stiffness is fitted as a compliance scale c = 1 / (stiffness scale): the twist that
# carries a torque is linear in c, so the linearised steps below are nearly exact.
# ``c_scale`` scales both twist sides alike (a record that twists the shaft mostly one way);
# ``c_scale_pos``/``c_scale_neg`` multiply it per side (a record that visits both).
NOMINAL_KEYS = ("c_scale", "c_scale_pos", "c_scale_neg", "kb_scale", "payload_kg_refit")
NOMINAL_DEFAULTS = {"c_scale": 1.0, "c_scale_pos": 1.0, "c_scale_neg": 1.0, "kb_scale": 1.0}
MEASUREMENT_PREFIXES = tuple(f"{name}." for name in variants.ARM if name in variants.ARM_RECORDING)


@dataclass
class ArmModel:
    """Nominal parameters and named effects of the arm (plant) and of its recording.

    ``values`` holds every parameter present (nominal keys always, effect keys when the effect
    is); ``labels`` the effects in the order added. Hysteresis element ``i`` has the stiffness
    ``hysteresis.k{i}`` and the slip deflection ``hysteresis.d{i}`` (slip torque k d).
    """

    values: dict[str, float] = field(default_factory=lambda: dict(NOMINAL_DEFAULTS))
    labels: list[str] = field(default_factory=list)

    @property
    def slip_delta(self) -> tuple[float, ...]:
        out: list[float] = []
        while f"hysteresis.d{len(out)}" in self.values:
            out.append(self.values[f"hysteresis.d{len(out)}"])
        return tuple(out)

    def set_slip(self, ks: list[float], deltas: list[float]) -> None:
        """Replace the hysteresis elements."""
        for key in [k for k in self.values if k.startswith("hysteresis.")]:
            del self.values[key]
        for i, (k, d) in enumerate(zip(ks, deltas, strict=True)):
            self.values[f"hysteresis.k{i}"] = float(k)
            self.values[f"hysteresis.d{i}"] = float(d)

    def copy(self) -> ArmModel:
        return ArmModel(dict(self.values), list(self.labels))

    def v(self, key: str) -> float:
        return float(self.values.get(key, NOMINAL_DEFAULTS.get(key, 0.0)))

    def physical_key(self) -> tuple[Any, ...]:
        items = sorted(
            (k, round(v, 15))
            for k, v in self.values.items()
            if not k.startswith(MEASUREMENT_PREFIXES)
        )
        return tuple(items)

    def effects(self) -> list[EffectInstance]:
        """The named effects with their parameters (registry vocabulary)."""
        out = []
        for lab in self.labels:
            name, variant = lab[:-1].split("[")
            if name == variants.HYSTERESIS:
                ks = [self.v(f"hysteresis.k{i}") for i in range(len(self.slip_delta))]
                p: dict[str, Any] = {"k_nm_per_rad": ks, "delta_rad": list(self.slip_delta)}
                p["slip_torque_nm"] = [k * d for k, d in zip(ks, self.slip_delta, strict=True)]
            elif name in variants.ARM_RECORDING:  # one parameter, the channel's
                p = {variants.ARM[name][0].params[0].name: self.v(f"{name}.{variant}")}
            else:
                p = {
                    k.split(".", 1)[1]: val
                    for k, val in self.values.items()
                    if k.startswith(name + ".")
                }
            out.append(EffectInstance(name, variant, p))
        return out

    def nominal(self) -> dict[str, float]:
        """Nominal parameters as the model file states them (stiffness scales, K_b scale,
        payload refit)."""
        return {
            "k_scale_pos": 1.0 / (self.v("c_scale") * self.v("c_scale_pos")),
            "k_scale_neg": 1.0 / (self.v("c_scale") * self.v("c_scale_neg")),
            "kb_scale": self.v("kb_scale"),
            "payload_kg_refit": self.v("payload_kg_refit"),
        }


def to_config(run: ArmRun, m: ArmModel) -> SimConfig:
    """The simulator configuration of a model: the plant refit and with its effects, the
    controller with the stated shaft and payload."""
    sh = run.shaft
    c = m.v("c_scale")
    sp, sn, kb = 1.0 / (c * m.v("c_scale_pos")), 1.0 / (c * m.v("c_scale_neg")), m.v("kb_scale")
    slip_k = [0.0, 0.0, 0.0]
    slip_f = [0.0, 0.0, 0.0]
    if run.exact_shaft and not m.slip_delta:  # the run's own slip elements
        slip_k, slip_f = list(sh.slip_k), list(sh.slip_f)
    for i, d in enumerate(m.slip_delta[:3]):
        k = m.v(f"hysteresis.k{i}")
        slip_k[i], slip_f[i] = k, k * d
    plant = replace(
        sh,
        k_pos=sh.k_pos * sp,
        s_pos=sh.s_pos * sp,
        k_neg=sh.k_neg * sn,
        s_neg=sh.s_neg * sn,
        kb=sh.kb * kb,
        slip_k=(slip_k[0], slip_k[1], slip_k[2]),
        slip_f=(slip_f[0], slip_f[1], slip_f[2]),
    )
    # the plant effects that are registry laws, with their fitted values; the payload refit
    # acts through the payload error's law too (the controller keeps the stated payload)
    laws = []
    for name in variants.ARM_PLANT_LAWS:
        values = {p.name: m.v(f"{name}.{p.name}") for v in variants.ARM[name] for p in v.params}
        present = any(k.startswith(name + ".") for k in m.values)
        if name == variants.PAYLOAD:
            values["dm_kg"] = m.v("payload_kg_refit") + values["dm_kg"]
            present = True
        if present and not is_off(registry.get(name).law, values):  # (at 0: the same run)
            laws.append((name, tuple(values.items())))
    fx = Effects(laws=tuple(laws))
    return SimConfig(
        shaft=plant,
        payload_kg=run.payload_kg,
        gains=run.gains,
        effects=fx,
        controller_shaft=sh,
        timestep_s=run.timestep_s,
        integrator=run.integrator,
        transmission=run.transmission,
        transmission_params=run.transmission_params,
        controller_transmission_params=run.controller_transmission_params,
    )


# ----------------------------------------------------------------------------- simulation


class _ArmSim(Simulation):
    """A Simulation that records only the channels the replay compares (fast)."""

    def _columns(
        self, t: FloatArray, qpos: FloatArray, qvel: FloatArray, act: FloatArray, ud: FloatArray
    ) -> dict[str, FloatArray]:
        st = self.structure
        return {
            "t": t,
            "q1": qpos[:, st.qadr[0]].copy(),
            "q2": qpos[:, st.qadr[1]].copy(),
            "q3": qpos[:, st.qadr[2]].copy(),
            "theta_m": st.coef_m * qpos[:, st.qadr[3]],
        }


def simulate_config(run: ArmRun, cfg: SimConfig) -> tuple[dict[str, FloatArray], float]:
    """Closed-loop run of ``cfg`` on the run's references; channels on the record's time grid,
    and the gear ratio i_G2. Raises InvalidParameterError / SimulationWarningError."""
    sim = _ArmSim(cfg, run.ref_table, "native")
    dt = run.ctrl_dt
    n_rows = math.floor(run.t[-1] / dt + 1e-6) + 2
    cols, _ = sim.run(n_rows * dt, log_every_ticks=1)
    tick_t = cols["t"]
    idx = np.rint(run.t / dt).astype(np.int64)
    on_grid = bool(np.all(np.abs(run.t - idx * dt) <= 1e-6 * dt)) and idx[-1] < tick_t.size
    out = {}
    for ch in ("q1", *RAW):
        y = cols[ch]
        out[ch] = y[idx] if on_grid else np.interp(run.t, tick_t, y)
    return out, float(sim.structure.coef_s)


def delayed(y: FloatArray, delay_samples: float) -> FloatArray:
    """``y`` delayed by a (fractional, signed) number of samples: :func:`.replay.shifted`
    (effects.delay's ``delayed_signal``: linear interpolation, ends held) with numpy's
    element-wise arithmetic - the same operations in the same order, so the same bits
    (tests/test_discrepancy_arm_speed.py) - without loading the compiled function, which took
    0.24 s of every diagnosis in a fresh process (issue 15)."""
    n = y.shape[0]
    x = np.arange(n, dtype=np.float64) - delay_samples
    out = np.empty(n)
    low = x <= 0.0
    high = ~low & (x >= n - 1)
    mid = ~(low | high)
    xm = x[mid]
    i = xm.astype(np.int64)  # int(x) of x > 0: truncation
    f = xm - i
    out[mid] = y[i] + f * (y[i + 1] - y[i])
    out[low] = y[0] if n else 0.0
    out[high] = y[n - 1] if n else 0.0
    return out


def apply_measurement(
    raw: Mapping[str, FloatArray], m: ArmModel, h: float
) -> dict[str, FloatArray]:
    """The recorded channels of a simulated run: each delayed (effects.delay: linear
    interpolation, ends held; :func:`delayed`) and biased (effects.sensor_offset) as the
    model's measurement effects say."""
    out: dict[str, FloatArray] = {}
    for ch in RAW:
        y = raw[ch]
        d = m.v(f"delay.{ch}")
        if d != 0.0:
            y = delayed(np.ascontiguousarray(y, dtype=np.float64), d / h)
        out[ch] = np.asarray(sensor_offset.reading(y, m.v(f"sensor_offset.{ch}")))  # type: ignore[arg-type]
    return out


def to_basis(raw: Mapping[str, FloatArray], coef_s: float) -> dict[str, FloatArray]:
    return {"q3": raw["q3"], "twist": raw["theta_m"] - coef_s * raw["q3"], "q2": raw["q2"]}
