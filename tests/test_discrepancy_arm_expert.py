"""Issue 16 on the arm: ``unexplained`` / ``residual_signature`` / confidence intervals of arm
records, synthetic arm records of every transmission."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from batteries import battery_arm_expert
from fsarm_sim.discrepancy import arm, arm_synth, report
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.records.measured import load_dataset

from conftest import check_battery_printout

DURATION_S = 3.0


def test_a_pickup_line_on_the_motor_encoder_is_unexplained_and_named(tmp_path: Path) -> None:
    case = battery_arm_expert.ArmCase("line", "ool", (), "line", seed=3, duration_s=DURATION_S)
    truth = battery_arm_expert.truth_of(case)
    rec = arm_synth.ArmRecording(
        duration_s=DURATION_S, noise_rad=battery_arm_expert.NOISE_RAD, seed=3
    )
    path = tmp_path / "arm.csv"
    arm_synth.write_arm_synthetic(
        path, truth, rec, disturbance=battery_arm_expert.disturbance("line")
    )
    diag = arm.diagnose_arm(load_dataset(path))
    res = report.json_clean(report.result_dict(diag))
    assert res["named_effects"] == []
    assert res["unexplained"] is True and res["nothing_missing"] is False
    sig = res["residual_signature"]
    assert sig["kind"] == "spectral_line" and sig["channel"] == "twist"
    line = sig["spectral_lines"][0]
    assert line["frequency_hz"] == pytest.approx(battery_arm_expert.LINE_HZ, abs=0.2)
    # the line's amplitude on theta_m is the twist's (twist = theta_m - i_G2 q3)
    assert line["amplitude"] == pytest.approx(battery_arm_expert.LINE_AMPLITUDE_RAD, rel=0.15)
    assert "outside the library" in res["verdict"] and "50 Hz line" in res["verdict"]
    json.dumps(res)  # the signature's arrays are JSON-safe
    files = arm.write_plots(diag, tmp_path / "plots")
    assert (tmp_path / "plots" / "residual_signature.png") in files


def test_intervals_of_an_arm_fit_cover_the_truth() -> None:
    r = battery_arm_expert.run(
        battery_arm_expert.ArmCase(
            "coulomb", "single", ("coulomb_friction",), seed=5, duration_s=DURATION_S
        )
    )
    assert r.error == "" and r.named == ["coulomb_friction"] and r.unexplained is False
    names = {n for n, _ in r.covered}
    assert "coulomb_friction.f_c_nm" in names and names & {"c_scale", "c_scale_pos"}
    assert all(ok for _, ok in r.covered), r.covered


def test_rounding_bias_of_a_quantiser_falls_with_the_noise_that_dithers_it() -> None:
    from fsarm_sim.discrepancy.arm_expert import rounding_bias_rms

    q = 1e-4
    assert rounding_bias_rms(q, 0.0) == pytest.approx(q / math.sqrt(12.0))
    # the series at sigma -> 0 is the sawtooth's own RMS (sum 1/k^2 = pi^2/6, to its 8 terms)
    assert rounding_bias_rms(q, 1e-12 * q) == pytest.approx(q / math.sqrt(12.0), rel=0.05)
    values = [rounding_bias_rms(q, f * q) for f in (0.0, 0.1, 0.2, 0.3, 0.5)]
    assert all(a > b for a, b in itertools.pairwise(values))
    assert values[-1] < 2e-3 * q  # noise of half a count dithers the rounding away
    # Monte Carlo: mean rounding error at a random cell position, RMS over positions
    rng = np.random.default_rng(0)
    u = rng.uniform(0.0, q, 400)
    noise = 0.2 * q * rng.standard_normal((400, 4000))
    x = u[:, None] + noise
    bias = np.mean(np.round(x / q) * q - x, axis=1)
    assert float(np.sqrt(np.mean(bias**2))) == pytest.approx(rounding_bias_rms(q, 0.2 * q), rel=0.1)


def test_a_quantised_joint_held_at_a_pose_does_not_make_the_interval_overconfident() -> None:
    """tendon-sheath record with nothing hidden: joint 2 dwells on a few encoder counts, whose
    rounding biased kb_scale by 5 of its SDs (0.5.2); the interval now carries that offset."""
    case = next(c for c in battery_arm_expert.cases() if c.name == "tendon-sheath/null")
    r = battery_arm_expert.run(case)
    assert r.error == "" and r.named == []
    assert dict(r.covered).get("kb_scale") is True, r.covered


@pytest.mark.parametrize("rate", [500.0, 2000.0])
def test_arm_records_at_500_hz_and_2_khz_are_diagnosed(rate: float) -> None:
    r = battery_arm_expert.run(
        battery_arm_expert.ArmCase(
            "r", "single", ("coulomb_friction",), seed=6, duration_s=DURATION_S, rate_hz=rate
        )
    )
    assert r.error == "" and r.named == ["coulomb_friction"] and r.unexplained is False
    assert {c.rate_hz for c in battery_arm_expert.cases() if c.group == "pair"} == {
        None,
        500.0,
        2000.0,
    }


@pytest.mark.parametrize("transmission", ["qa-joint", "tendon-sheath"])
def test_synthetic_arm_record_of_another_transmission_is_diagnosed(transmission: str) -> None:
    case = battery_arm_expert.ArmCase(
        "t", "transmission", ("sensor_offset",), transmission=transmission, seed=9, duration_s=3.0
    )
    r = battery_arm_expert.run(case)
    assert r.error == "" and r.named == ["sensor_offset"] and r.unexplained is False


def test_synthetic_arm_record_states_its_transmission(tmp_path: Path) -> None:
    rec = arm_synth.ArmRecording(duration_s=1.0, transmission="rtca")
    arm_synth.write_arm_synthetic(tmp_path / "a.csv", arm_synth.truth_model([]), rec)
    assert arm.arm_run(load_dataset(tmp_path / "a.csv")).transmission == "rtca"
    with pytest.raises(InvalidParameterError, match="unknown transmission"):
        arm_synth.ArmRecording(transmission="harmonic-drive").validate()


# ---- the printout (format_results, shared with the bench battery: battery_expert.format_battery)

# signatures that make signature_right True, False and not apply, a long summary cut at 90
FAKE_SIGNATURES: list[dict[str, Any]] = [
    {},
    {
        "summary": "x" * 120,
        "kind": "spectral_line",
        "spectral_lines": [{"frequency_hz": battery_arm_expert.LINE_HZ, "in_input": False}],
    },
    {
        "summary": "drift of the offset",
        "kind": "drift",
        "trend": {"offset": {"change_over_record": battery_arm_expert.DRIFT_RAD}},
    },
    {"summary": "signal", "kind": "signal", "dependence": [{"signal": "q3"}]},
    {"summary": "twist dep", "kind": "signal", "dependence": [{"signal": "twist"}]},
]


def _fake_results() -> list[battery_arm_expert.ArmResult]:
    """An ArmResult for every case of the battery, its fields varied case by case (no run)."""
    out = []
    for i, case in enumerate(battery_arm_expert.cases()):
        truth = list(case.effects)
        named = truth if i % 3 else truth[:1] + (["payload_error"] if i % 2 else [])
        covered = [(n, (i + j) % 3 != 0) for j, n in enumerate(["k", "c", "tau_f"][: 1 + i % 3])]
        out.append(
            battery_arm_expert.ArmResult(
                case=case,
                named=named,
                unexplained=[None, True, False][i % 3],
                signature=FAKE_SIGNATURES[i % len(FAKE_SIGNATURES)],
                covered=[] if i % 4 == 0 else covered,
                runtime_s=math.nan if i % 7 == 0 else 1.3 * i,
                simulations=3 * i,
                joint_steps=i % 4,
                error="" if i % 11 else f"failed {i}",
            )
        )
    return out


def test_the_printout_reports_every_case_mark_and_rate() -> None:
    results = _fake_results()
    marks = {battery_arm_expert.signature_right(r) for r in results}
    assert marks == {None, True, False}  # every signature mark is printed
    assert any(not c for r in results for _, c in r.covered)  # and CI-miss lines
    for sel in (results, results[:3], results[-5:], []):
        text = battery_arm_expert.format_results(sel)
        check_battery_printout(
            text,
            sel,
            battery_arm_expert.signature_right,
            battery_arm_expert.rates(sel),
            ci_misses=True,
        )
        if sel:
            assert f"({sel[0].case.duration_s:g} s records)" in text
