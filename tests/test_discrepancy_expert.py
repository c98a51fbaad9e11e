"""Issue 16: what remains unexplained is characterised (spectral line, drift, dependence on a
signal), every fitted parameter gets a confidence interval, a near-tie gets a designed input
(trajectory file) that synth plays."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from batteries import battery, battery_expert
from fsarm_sim.discrepancy import report, synth
from fsarm_sim.discrepancy.bench_setup import diagnose
from fsarm_sim.discrepancy.benchmodel import BenchModel
from fsarm_sim.discrepancy.unexplained import Signals, characterise
from fsarm_sim.errors import InvalidParameterError

from conftest import check_battery_printout


def _signals(extra: np.ndarray, t: np.ndarray, twist: np.ndarray, y: np.ndarray) -> Signals:
    rng = np.random.default_rng(0)
    r = extra + 0.01 * rng.standard_normal(t.size)
    return Signals(
        channel="tau_s",
        unit="N·m",
        t=t,
        residual=r,
        output=y,
        sigma=0.01,
        inputs=[twist],
        signals={"twist": twist, "twist rate": np.gradient(twist, t), "model output": y},
    )


@pytest.fixture(scope="module")
def record() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(20000) * 1e-3
    twist = 0.3 * np.sin(2 * np.pi * 0.4 * t) + 0.1 * np.sin(2 * np.pi * 1.3 * t + 1.0)
    return t, twist, 15.0 * twist


def test_a_mains_line_is_named_with_its_frequency_and_amplitude(record: tuple) -> None:
    t, twist, y = record
    sig = characterise(_signals(0.03 * np.sin(2 * np.pi * 50.0 * t + 0.3), t, twist, y))
    assert sig["kind"] == "spectral_line"
    line = sig["spectral_lines"][0]
    assert line["frequency_hz"] == pytest.approx(50.0, abs=0.05)
    assert line["amplitude"] == pytest.approx(0.03, rel=0.05) and not line["in_input"]
    assert "50 Hz line" in sig["summary"] and "tau_s" in sig["summary"]


def test_a_stiffness_drift_is_named_with_its_rate(record: tuple) -> None:
    t, twist, y = record
    tau = (t - t.mean()) / (t[-1] - t[0])
    sig = characterise(_signals(0.12 * tau * (y - y.mean()), t, twist, y))
    assert sig["kind"] == "drift"
    g = sig["trend"]["gain"]
    assert g["relative_change_over_record"] == pytest.approx(0.12, rel=0.05)
    assert "rises by ~12" in sig["summary"]


def test_an_offset_ramp_is_a_drift_with_its_change_not_a_localized_residual(record: tuple) -> None:
    """A ramp of 3x the noise's RMS: its t value uses what the regression leaves (the ramp is
    not correlated noise against itself), and its ends are not a burst."""
    t, twist, y = record
    tau = (t - t.mean()) / (t[-1] - t[0])
    sig = characterise(_signals(0.1 * tau, t, twist, y))
    assert sig["kind"] == "drift"
    o = sig["trend"]["offset"]
    assert o["change_over_record"] == pytest.approx(0.1, rel=0.05)
    # white noise 0.01 on 20 000 samples, var(tau) = 1/12: se = 0.01 / sqrt(20000 / 12)
    assert o["t_value"] == pytest.approx(0.1 / (0.01 / np.sqrt(20000 / 12)), rel=0.2)
    assert "drifts by +0.1" in sig["summary"]
    assert all(d["kind"] != "localized" for d in sig["descriptions"])


def test_a_dependence_on_the_twist_is_named_and_noise_is_not(record: tuple) -> None:
    t, twist, y = record
    sig = characterise(_signals(0.03 * np.sin(2 * np.pi * twist / 0.08), t, twist, y))
    assert sig["kind"] == "signal" and sig["dependence"][0]["signal"] == "twist"
    noise = characterise(_signals(np.zeros_like(t), t, twist, y))
    assert noise["kind"] == "none" and noise["spectral_lines"] == []
    assert max(d["share_of_residual"] for d in noise["dependence"]) < 0.05


def test_an_out_of_library_line_is_unexplained_and_intervals_cover_the_truth(
    tmp_path: Path,
) -> None:
    """A bench record with Coulomb friction and a 50 Hz line on the torque: the friction named
    with a 95 % interval holding its true value, the residual unexplained and named."""
    case = battery_expert._case(
        "line",
        "series_bench",
        [("coulomb_friction", "shaft")],
        0.03,
        seed=7,
        duration_s=10.0,
        extra=("line", 0.01),
    )
    case = battery.replace(case, rate_hz=500.0, trajectory="random")
    truth, _ = battery.build_truth(case)
    diag = diagnose(battery.dataset(truth, case, case.noise))
    res = report.result_dict(diag)
    assert res["named_effects"] == ["coulomb_friction"]
    assert res["unexplained"] is True and res["nothing_missing"] is False
    line = res["residual_signature"]["spectral_lines"][0]
    assert line["frequency_hz"] == pytest.approx(50.0, abs=0.1) and line["channel"] == "tau_s"
    assert "50 Hz line" in res["verdict"]
    ci = {p["name"]: p for p in res["confidence_intervals"]["parameters"]}
    f_c = truth.effects[0].params["f_c_nm"]
    p = ci["coulomb_friction[shaft].f_c_nm"]
    assert p["lower"] <= f_c <= p["upper"] and p["upper"] - p["lower"] < 0.2 * f_c
    assert "Fisher" in res["confidence_intervals"]["method"]
    files = report.write_report(diag, tmp_path / "rep")
    assert files["residual_signature"].is_file()


def test_an_input_file_drives_synth_and_bad_files_are_refused(tmp_path: Path) -> None:
    t = np.arange(0, 5.0, 1e-3)
    u = 0.2 * np.sin(2 * np.pi * 0.5 * t)
    f = synth.write_input_file(tmp_path / "u.csv", t, u, "series_bench")
    rec = synth.Recording(duration_s=4.0, noise=0.0, input_file=str(f), encoder_counts=0)
    cols, side = synth.synthesize(synth.truth_model("series_bench"), rec)
    assert np.allclose(cols["theta_m"], np.interp(cols["t"], t, u), atol=1e-9)
    assert "file u.csv" in side["notes"]
    with pytest.raises(InvalidParameterError, match="needs the columns t and phi_b"):
        synth.read_input_file(f, "parallel_bench")
    long = synth.Recording(duration_s=9.0, noise=0.0, input_file=str(f))
    with pytest.raises(InvalidParameterError, match="shorter than"):
        synth.synthesize(synth.truth_model("series_bench"), long)


def test_designed_inputs_rest_at_the_ends_and_keep_the_rate_limit() -> None:
    from fsarm_sim.discrepancy import design

    t = np.arange(0, 30.0, 1e-3)
    ds = design.designs(0.4)
    assert {d.bias for d in ds} >= {0.0} and min(d.bias for d in ds) < 0 < max(d.bias for d in ds)
    for k, d in enumerate(ds):
        u = design.input_of(d, t, "series_bench", seed=k)
        assert abs(u[0]) < 1e-9 and abs(u[-1]) < 1e-6
        assert np.max(np.abs(np.gradient(u, t))) <= synth.SERIES_RATE_LIMIT
        assert np.max(np.abs(u)) <= abs(d.bias) + d.amplitude + 1e-9
    # a wrong model leaving the noise variance on 10 000 held-out samples: 10 000 ln 2 - ln n
    assert design.expected_margin(1.0, 1.0, 1e4, 1) == pytest.approx(1e4 * np.log(2) - np.log(1e4))


# ---- the printout (format_results, shared with the arm battery: format_battery)

# signatures that make signature_right True, False and not apply, a long summary cut at 90
FAKE_SIGNATURES: list[dict[str, Any]] = [
    {},
    {
        "summary": "x" * 120,
        "kind": "spectral_line",
        "spectral_lines": [{"frequency_hz": battery.LINE_HZ, "in_input": False}],
    },
    {
        "summary": "drift of the gain",
        "kind": "drift",
        "trend": {"gain": {"relative_change_over_record": 0.1}},
    },
    {"summary": "signal", "kind": "signal", "dependence": [{"signal": "twist"}]},
    {"summary": "q3 dep", "kind": "signal", "dependence": [{"signal": "q3"}]},
]


def _fake_results() -> list[battery_expert.Result]:
    """A Result for every case of the battery, its fields varied case by case (no diagnosis)."""
    out = []
    for i, (group, case) in enumerate(battery_expert.cases()):
        truth = [e for e, _ in case.effects]
        named = truth if i % 3 else truth[:1] + (["viscous_damping"] if i % 2 else [])
        covered = [(n, (i + j) % 3 != 0) for j, n in enumerate(["k", "c", "tau_f"][: 1 + i % 3])]
        out.append(
            battery_expert.Result(
                case=case,
                group=group,
                truth=BenchModel(setup=case.setup, nominal={}),
                named=list(named),
                unexplained=[None, True, False][i % 3],
                signature=FAKE_SIGNATURES[i % len(FAKE_SIGNATURES)],
                covered=[] if i % 4 == 0 else covered,
                runtime_s=math.nan if i % 7 == 0 else 0.37 * i,
                cpu_s=math.nan if i % 5 == 0 else 0.21 * i,
                joint_steps=i % 4,
                error="" if i % 11 else f"failed {i}",
                extra_truth={"relative_change_over_record": [0.1, -0.1][i % 2]},
            )
        )
    return out


def test_the_printout_reports_every_case_mark_and_rate() -> None:
    results = _fake_results()
    marks = {battery_expert.signature_right(r) for r in results}
    assert marks == {None, True, False}  # every signature mark is printed
    for sel in (results, results[:3], results[-5:], []):
        text = battery_expert.format_results(sel)
        check_battery_printout(
            text, sel, battery_expert.signature_right, battery_expert.rates(sel), ci_misses=False
        )
        for r in sel:  # the rate of each case's record, after its name
            assert f"{r.case.rate_hz:5.0f}Hz " in text
        cpu = [r.cpu_s for r in sel if math.isfinite(r.cpu_s)]
        assert ("process time per record" in text) == bool(cpu)
