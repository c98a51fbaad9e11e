"""The expert battery on the arm (issue 16): co-occurring effects, residuals outside the
library, every transmission - and the issue's rates, measured as :mod:`.battery_expert` measures
them on the benches.

Cases (SYNTHETIC ``fig14-sine`` runs of :func:`.arm_synth.synthesize_arm`, 17-bit encoders,
angle noise :data:`NOISE_RAD`, 1 kHz; the true flexible shaft 5 % stiffer than the catalogue):

* ``pair``: every pair of the arm's effects (:data:`EFFECTS`, each at a magnitude the one-effect
  arm battery names reliably on its own), recorded in turn at 1 kHz, 500 Hz (every second
  control tick) and 2 kHz (a 2 kHz controller) (:data:`PAIR_RATES`);
* ``triple``: :data:`TRIPLES`;
* ``ool``: out-of-library disturbances of the recording (:func:`disturbance`): a 50 Hz pickup
  line on the motor encoder's channel, the motor encoder's offset drifting linearly over the
  record, and the joint-3 encoder's cyclic error (16 periods per revolution: a dependence on
  q3 that no effect models) - alone and next to Coulomb friction;
* ``transmission``: every transmission other than the flexible shaft (its default parameters,
  stated in the sidecar as ``fsarm run --transmission`` states it) with Coulomb friction, with a
  motor-encoder offset, and with nothing hidden;
* ``null``: nothing hidden.

Rates (:func:`rates`, as :func:`.battery_expert.rates`): every effect of a multi-effect record
named; no effect named that is not hidden; ``unexplained`` right (true exactly for the ``ool``
cases); the signature naming the right frequency (within 0.5 Hz) / drift (offset, right sign,
within a factor 1.5) / signal (q3); the 95 % intervals holding the true value (cases whose named
effects are exactly the hidden ones; not the hysteresis elements).
"""

from __future__ import annotations

import itertools
import math
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from batteries import battery_expert as BE
from fsarm_sim.discrepancy import arm, arm_synth, core
from fsarm_sim.discrepancy.arm_model import ArmModel
from fsarm_sim.plant import transmissions
from fsarm_sim.records.measured import load_dataset

FloatArray = arm_synth.FloatArray

NOISE_RAD = 1e-5
STIFFNESS_SCALE = 1.05
EFFECTS: dict[str, str] = {  # the one-effect arm battery's magnitudes, between small and large
    "payload_error": "payload_error=0.4",
    "coulomb_friction": "coulomb_friction=0.1",
    "viscous_damping": "viscous_damping=0.1",
    "backlash": "backlash=0.008",
    "hysteresis": "hysteresis=4,0.002,2,0.005",
    "sensor_offset": "sensor_offset:theta_m=0.002",
    "delay": "delay:q3=0.004",
}
TRIPLES = (
    ("coulomb_friction", "sensor_offset", "delay"),
    ("payload_error", "viscous_damping", "sensor_offset"),
    ("hysteresis", "coulomb_friction", "delay"),
)
LINE_HZ = 50.0
# sizes: ~2-3x the noise floor of the basis channel they reach (twist ~2e-4 rad: the joint-3
# encoder's noise x i_G2 = 10; q3 ~2.5e-5 rad)
LINE_AMPLITUDE_RAD = 6e-4  # on theta_m: RMS ~2x the twist's floor
DRIFT_RAD = 2e-3  # change of the motor encoder's offset over the record: RMS ~2.6x
CYCLIC_AMPLITUDE_RAD = 8e-5  # on q3: RMS ~2.2x q3's floor (and the twist's, x i_G2)
CYCLIC_PER_REV = 16.0
OOL_KINDS = ("line", "drift", "signal")


@dataclass(frozen=True)
class ArmCase:
    name: str
    group: str
    effects: tuple[str, ...]  # truth names (EFFECTS keys)
    extra: str | None = None  # OOL kind
    transmission: str = transmissions.DEFAULT
    seed: int = 0
    duration_s: float = 8.0
    rate_hz: float | None = None  # the record's rate (None: the 1 kHz control rate)


# record rates of the pair cases, in turn (issue 16: 500 Hz to 2 kHz): the control rate, every
# second tick, and a 2 kHz controller
PAIR_RATES: tuple[float | None, ...] = (None, 500.0, 2000.0)


@dataclass
class ArmResult:
    case: ArmCase
    named: list[str]
    unexplained: bool | None
    signature: dict[str, Any]
    covered: list[tuple[str, bool]] = field(default_factory=list)
    runtime_s: float = math.nan
    simulations: int = 0
    joint_steps: int = 0
    extra_truth: dict[str, float] = field(default_factory=dict)
    error: str = ""

    @property
    def group(self) -> str:
        return self.case.group

    @property
    def truth_names(self) -> list[str]:
        return list(self.case.effects)


def cases(duration_s: float = 8.0) -> list[ArmCase]:
    """The whole battery (module docstring)."""
    out: list[ArmCase] = []
    seed = 1700
    for i, (a, b) in enumerate(itertools.combinations(EFFECTS, 2)):
        seed += 1
        rate = PAIR_RATES[i % len(PAIR_RATES)]
        at = "" if rate is None else f"@{rate:g}Hz"
        out.append(
            ArmCase(
                f"pair:{a}+{b}{at}", "pair", (a, b), seed=seed, duration_s=duration_s, rate_hz=rate
            )
        )
    for tr3 in TRIPLES:
        seed += 1
        out.append(
            ArmCase(f"triple:{'+'.join(tr3)}", "triple", tr3, seed=seed, duration_s=duration_s)
        )
    for kind in OOL_KINDS:
        for with_eff in ((), ("coulomb_friction",)):
            seed += 1
            nm = f"ool:{kind}{'+' + with_eff[0] if with_eff else ''}"
            out.append(ArmCase(nm, "ool", with_eff, kind, seed=seed, duration_s=duration_s))
    for tr in transmissions.names():
        if tr == transmissions.DEFAULT:
            continue
        for effs in (("coulomb_friction",), ("sensor_offset",), ()):
            seed += 1
            nm = f"{tr}/{effs[0] if effs else 'null'}"
            out.append(
                ArmCase(nm, "transmission", effs, transmission=tr, seed=seed, duration_s=duration_s)
            )
    for _ in range(2):
        seed += 1
        out.append(ArmCase("null", "null", (), seed=seed, duration_s=duration_s))
    return out


def disturbance(kind: str) -> arm_synth.Disturbance:
    """What outside the library adds to the recording (module docstring)."""

    def add(t: FloatArray, ch: dict[str, FloatArray]) -> dict[str, FloatArray]:
        if kind == "line":
            return {"theta_m": LINE_AMPLITUDE_RAD * np.sin(2 * np.pi * LINE_HZ * t + 0.3)}
        if kind == "drift":
            tau = (t - 0.5 * (t[0] + t[-1])) / (float(t[-1] - t[0]) or 1.0)
            return {"theta_m": DRIFT_RAD * tau}
        if kind == "signal":
            return {"q3": CYCLIC_AMPLITUDE_RAD * np.sin(CYCLIC_PER_REV * ch["q3"])}
        raise ValueError(f"unknown out-of-library kind {kind!r}")

    return add


def truth_of(case: ArmCase) -> ArmModel:
    scale = STIFFNESS_SCALE if case.transmission == transmissions.DEFAULT else 1.0
    return arm_synth.truth_model([EFFECTS[e] for e in case.effects], stiffness_scale=scale)


def truth_values(truth: ArmModel) -> dict[str, float]:
    """Fitted key -> true value; the compliance scales as the product the plant sees."""
    c = truth.v("c_scale")
    out = {
        "c_scale": c * truth.v("c_scale_pos"),
        "c_scale_pos": c * truth.v("c_scale_pos"),
        "c_scale_neg": c * truth.v("c_scale_neg"),
        "kb_scale": truth.v("kb_scale"),
        "payload_kg_refit": 0.0,
    }
    out.update({k: float(v) for k, v in truth.values.items() if "." in k})
    return out


def run(case: ArmCase, joint: bool | None = None) -> ArmResult:
    """Synthesize, diagnose and score one case (``joint``: the core's joint search with its
    restart and pruning; None: :data:`.arm.JOINT_SEARCH`)."""
    truth = truth_of(case)
    rec = arm_synth.ArmRecording(
        duration_s=case.duration_s,
        noise_rad=NOISE_RAD,
        seed=case.seed,
        transmission=case.transmission,
        rate_hz=case.rate_hz,
    )
    dist = disturbance(case.extra) if case.extra else None
    try:
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "arm.csv"
            arm_synth.write_arm_synthetic(path, truth, rec, disturbance=dist)
            ds = load_dataset(path)
            t0 = time.perf_counter()
            setup = arm.ArmSetup(ds)
            j = arm.JOINT_SEARCH if joint is None else joint
            diag = core.diagnose(setup, arm.MAX_EFFECTS, started=t0, joint=j, restart=j)
            dt = time.perf_counter() - t0
    except Exception as exc:  # a battery reports failures, it does not stop at them
        return ArmResult(case, [], None, {}, error=f"{type(exc).__name__}: {exc}"[:160])
    ci = diag.extras.get("confidence_intervals") or {}
    covered: list[tuple[str, bool]] = []
    if sorted(diag.named) == sorted(case.effects) and not case.extra:
        tv = truth_values(truth)
        for p in ci.get("parameters", []):
            nm = p["name"]
            if nm.startswith("hysteresis.") or nm not in tv or not math.isfinite(p["sd"]):
                continue  # grid elements have no one-to-one true counterpart
            # the refit fits c_scale or the side scales (never both): each is the product
            covered.append((nm, bool(p["lower"] <= tv[nm] <= p["upper"])))
    return ArmResult(
        case=case,
        named=list(diag.named),
        unexplained=bool(diag.extras.get("unexplained")),
        signature=diag.extras.get("residual_signature") or {},
        covered=covered,
        runtime_s=dt,
        simulations=diag.ctx.n_sims,
        joint_steps=sum(1 for st in diag.steps if st.joint and st.added),
        extra_truth={"line_hz": LINE_HZ, "drift_rad": DRIFT_RAD} if case.extra else {},
    )


def signature_right(r: ArmResult) -> bool | None:
    """Does the signature name the hidden out-of-library disturbance? None: none hidden."""
    kind = r.case.extra
    sig = r.signature
    if not kind:
        return None
    if not sig:
        return False
    if kind == "line":
        lines = [ln for ln in sig.get("spectral_lines", []) if not ln["in_input"]]
        return (
            sig.get("kind") == "spectral_line"
            and bool(lines)
            and abs(lines[0]["frequency_hz"] - LINE_HZ) < 0.5
        )
    if kind == "drift":
        if sig.get("kind") != "drift":
            return False
        ch = sig["trend"]["offset"]["change_over_record"]
        return bool(ch * DRIFT_RAD > 0 and 1 / 1.5 <= abs(ch) / DRIFT_RAD <= 1.5)
    if kind == "signal":
        dep = sig.get("dependence") or []
        return sig.get("kind") == "signal" and bool(dep) and dep[0]["signal"] == "q3"
    return None


def rates(results: list[ArmResult]) -> dict[str, tuple[int, int]]:
    """The issue's rates as (hits, cases) (module docstring)."""
    ok = [r for r in results if not r.error]
    tr = [r for r in ok if r.group == "transmission"]
    return {
        **BE.common_rates(ok, signature_right),
        "transmissions_exact": BE.frac([sorted(r.named) == sorted(r.truth_names) for r in tr]),
        "errors": (len(results) - len(ok), len(results)),
    }


PRINTOUT = BE.Printout(
    header="per case: group | case | named | unexplained | joint | CI covered | s | signature",
    group_width=12,
    name_width=52,
    named_width=50,
    ci_width=5,
    after_name=lambda r: "",
    after_runtime=lambda r: f"({r.simulations} runs)",
    ci_misses=True,
)


def format_results(results: list[ArmResult]) -> str:
    """The battery's printout (:func:`battery_expert.format_battery`)."""
    return BE.format_battery(
        results,
        PRINTOUT,
        signature_right,
        rates(results),
        f" ({results[0].case.duration_s:g} s records)" if results else "",
    )
