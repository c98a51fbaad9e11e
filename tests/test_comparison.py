"""Side-by-side comparison of transmissions (fsarm compare-transmissions)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from fsarm_sim.engine.model import SimConfig, reference_stiffness
from fsarm_sim.plant.transmissions import TransmissionError
from fsarm_sim.sim.simulation import run_scenario
from fsarm_sim.studies.comparison import compare

from conftest import run_fsarm


def test_rows_match_the_runs_they_summarise() -> None:
    rows = compare(["flexible-shaft", "rtca"], duration_s=2.0, analyses=False)
    assert [r.transmission for r in rows] == ["flexible-shaft", "rtca"]
    for r in rows:
        assert r.error is None
        run = run_scenario(
            "fig14-sine", SimConfig(transmission=r.transmission), duration_s=2.0, backend="native"
        )
        assert r.metrics["q3_rmse_deg"] == run.metrics["rmse_deg"]["q3"]  # type: ignore[index]
        assert r.metrics["motor_energy_j"] == run.metrics["motor_energy_j"]
        assert r.metrics["motor_energy_j"] >= 0.0  # regenerated work is not credited


def test_a_transmission_that_cannot_hold_the_load_is_a_row_not_a_crash() -> None:
    """15 kg needs ~7 N*m at the shaft side: beyond the published magnetic spring (1 N*m)."""
    rows = compare(["magnetic-spring"], payload_kg=15.0, duration_s=0.5, analyses=False)
    assert rows[0].error is not None and "cannot hold" in rows[0].error


def test_unknown_names_fail_before_any_work() -> None:
    with pytest.raises(TransmissionError):
        compare(["flexible-shaft", "nope"])


def test_fixed_gains_are_tuned_at_a_loaded_operating_point() -> None:
    """Stiffening laws have almost no stiffness at zero twist; the reference stiffness is taken
    where 30 % of the rating is held, straight (the shaft's is its linear K_sp(0))."""
    shaft = SimConfig()
    assert reference_stiffness(shaft) == pytest.approx(shaft.shaft.k_series(0.0, 1))
    rtca = SimConfig(transmission="rtca")
    tr = rtca.transmission_model()
    block = rtca.transmission_blocks()[1]
    k_ref = reference_stiffness(rtca)
    assert k_ref > 2.0 * tr.stiffness(block, 0.0, 0.0)
    x = tr.twist_for_torque(block, 0.3 * tr.rating_nm(block), 0.0)
    assert k_ref == pytest.approx(tr.stiffness(block, x, 0.0))


def test_cli_writes_the_table_as_json(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    out = tmp_path / "rows.json"
    code = run_fsarm(
        monkeypatch,
        "compare-transmissions",
        "--only",
        "qa-joint",
        "--duration",
        "1",
        "--quick",
        "--json",
        str(out),
    )
    assert code == 0
    rows = json.loads(out.read_text())
    assert rows[0]["transmission"] == "qa-joint" and math.isfinite(rows[0]["q3_rmse_deg"])
    assert run_fsarm(monkeypatch, "compare-transmissions", "--only", "nope") == 2


def test_gain_overrides_are_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    from fsarm_sim.cli.transmissions import parse_gains
    from fsarm_sim.errors import InvalidParameterError

    assert parse_gains(["torque_integral_rad_s=0"]) == {"torque_integral_rad_s": 0.0}
    with pytest.raises(InvalidParameterError, match="allowed"):
        parse_gains(["wn_rad_s=3"])
    code = run_fsarm(monkeypatch, "compare-transmissions", "--gain", "speed_kp=-1", "--quick")
    assert code == 2  # Gains.validate: a negative gain is a named error
