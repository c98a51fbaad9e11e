"""The arm's pairs for the core's joint search, the restart and the pruning (issue 16):
:mod:`fsarm_sim.discrepancy.arm_joint` behind :class:`fsarm_sim.discrepancy.arm.ArmSetup`. One
short synthetic record (3 s of ``fig14-sine``) with a payload error and Coulomb friction at
joint 3 - two effects that hide each other: alone neither earns its place."""

from __future__ import annotations

from pathlib import Path

import pytest

from batteries import battery_arm_expert
from fsarm_sim.discrepancy import arm, arm_synth, core
from fsarm_sim.records.measured import Dataset, load_dataset

DURATION_S = 3.0
PAIR = ("payload_error", "coulomb_friction")


@pytest.fixture(scope="module")
def record(tmp_path_factory: pytest.TempPathFactory) -> Dataset:
    case = battery_arm_expert.ArmCase("pair", "pair", PAIR, seed=1701, duration_s=DURATION_S)
    rec = arm_synth.ArmRecording(
        duration_s=DURATION_S, noise_rad=battery_arm_expert.NOISE_RAD, seed=case.seed
    )
    path: Path = tmp_path_factory.mktemp("joint") / "arm.csv"
    arm_synth.write_arm_synthetic(path, battery_arm_expert.truth_of(case), rec)
    return load_dataset(path)


@pytest.fixture(scope="module")
def diag(record: Dataset) -> core.Diagnosis[arm.ArmFit]:
    return arm.diagnose_arm(record)


def test_two_effects_that_hide_each_other_are_named_together(
    record: Dataset, diag: core.Diagnosis[arm.ArmFit]
) -> None:
    greedy = core.diagnose(arm.ArmSetup(record), arm.MAX_EFFECTS, joint=False)
    assert set(PAIR) - set(greedy.named), "the greedy selection names both: no test of the pair"
    assert sorted(diag.named) == sorted(PAIR)
    assert any(st.joint and st.added for st in diag.steps)
    assert diag.extras["unexplained"] is False
    truth = battery_arm_expert.truth_values(
        battery_arm_expert.truth_of(
            battery_arm_expert.ArmCase("p", "pair", PAIR, duration_s=DURATION_S)
        )
    )
    ci = {p["name"]: p for p in diag.extras["confidence_intervals"]["parameters"]}
    for name in ("payload_error.dm_kg", "coulomb_friction.f_c_nm"):
        assert ci[name]["lower"] <= truth[name] <= ci[name]["upper"], (name, ci[name])


def test_without_drops_one_effect_and_refits_the_rest(diag: core.Diagnosis[arm.ArmFit]) -> None:
    setup = diag.setup
    assert isinstance(setup, arm.ArmSetup)
    assert setup.holds(diag.final, "coulomb_friction") and not setup.holds(diag.final, "backlash")
    assert setup.without(diag.final, "backlash") is None
    sub = setup.without(diag.final, "coulomb_friction")
    assert sub is not None
    assert [e.name for e in sub.model.effects()] == ["payload_error"]
    assert not any(k.startswith("coulomb_friction.") for k in [*sub.model.values, *sub.free])
    assert setup.cost(sub)[1] > 2.0 * setup.cost(diag.final)[1]  # the friction was needed


def test_an_encoder_offset_moves_to_the_other_encoder_with_the_same_twist(
    record: Dataset,
) -> None:
    """twist = theta_m - i_G2 q3: a q3 offset o starts the swap as a theta_m offset -i_G2 o
    (and back), everything else as it was; other effects give no start."""
    import numpy as np

    from fsarm_sim.discrepancy import arm_fit, arm_joint, arm_model, arm_screen

    setup = arm.ArmSetup(record)
    ctx = setup.ctx
    m = arm_screen.add_candidate(ctx, arm_model.ArmModel(), "sensor_offset", "q3")
    m = arm_fit.with_values(m, ["sensor_offset.q3", "c_scale"], np.array([-2e-4, 0.97]))
    fit = arm_fit.evaluate(ctx, m, ["c_scale", "sensor_offset.q3"], "sensor_offset[q3]")
    assert fit is not None
    (alt,) = arm_joint.twist_equivalent(ctx, fit)
    assert alt.model.labels == ["sensor_offset[theta_m]"] and alt.variant == "theta_m"
    assert alt.model.v("sensor_offset.theta_m") == pytest.approx(2e-4 * ctx.coef_s)
    assert "sensor_offset.q3" not in alt.model.values and alt.model.v("c_scale") == 0.97
    assert alt.free == ["c_scale", "sensor_offset.theta_m"]
    (back,) = arm_joint.twist_equivalent(ctx, alt)
    assert back.model.v("sensor_offset.q3") == pytest.approx(-2e-4)
    # the two runs see the same twist: the twist channel's prediction is the same
    np.testing.assert_allclose(alt.pred["twist"], fit.pred["twist"], atol=1e-9)
    f2 = arm_fit.evaluate(
        ctx, arm_screen.add_candidate(ctx, arm_model.ArmModel(), "sensor_offset", "q2"), [], "q2"
    )
    assert f2 is not None and arm_joint.twist_equivalent(ctx, f2) == []
