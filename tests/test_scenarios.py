"""Scenario tracking warnings: the built-in scenarios run clean with the default configuration,
and a configuration that cannot do what the scenario is for gets a named warning."""

from __future__ import annotations

import pytest

from fsarm_sim.engine.model import SimConfig
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.simulation import run_scenario


@pytest.mark.parametrize("name", sorted(scenarios.REGISTRY))
def test_default_configuration_raises_no_tracking_warning(name: str) -> None:
    result = run_scenario(name, SimConfig())
    assert result.warnings == ()
    limits = scenarios.get(name).rmse_warn_deg
    assert limits is not None  # every built-in scenario states what it is built for


def test_a_limp_qa_joint_is_warned_about() -> None:
    """The README's QA-Joint example at sigma_cmd = 0.1 tracks fig14-sine with ~8° RMSE."""
    cfg = SimConfig(transmission="qa-joint", transmission_params=(("sigma_cmd", 0.1),))
    result = run_scenario("fig14-sine", cfg)
    assert any(w.startswith("TrackingWarning: joint 3") for w in result.warnings)


def test_warning_text_names_joint_value_and_limit() -> None:
    sc = scenarios.get("fig14-sine")
    (w,) = sc.tracking_warnings({"q1": 0.0, "q2": 0.0, "q3": 8.0})
    assert "joint 3" in w and "8°" in w and "2°" in w
    assert sc.tracking_warnings({"q1": float("nan"), "q2": 0.1, "q3": 0.4}) == ()
