"""One more hysteresis slip element where the arm record asks for it (discrepancy.arm_slip)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.discrepancy import (
    arm,
    arm_expert,
    arm_fit,
    arm_model,
    arm_screen,
    arm_slip,
    arm_synth,
    selection,
)
from fsarm_sim.records.measured import load_dataset

# two elements slipping at quite different twists (the arm expert battery's hysteresis)
TRUTH = "hysteresis=4,0.002,2,0.005"


@pytest.fixture(scope="module")
def one_element(tmp_path_factory: pytest.TempPathFactory) -> tuple[arm.ArmSetup, arm_fit.ArmFit]:
    """A record of the two-element loop and the one-element fit the screen ends up with."""
    path: Path = tmp_path_factory.mktemp("slip") / "arm.csv"
    rec = arm_synth.ArmRecording(duration_s=4.0, noise_rad=2e-5, seed=11)
    arm_synth.write_arm_synthetic(path, arm_synth.truth_model([TRUTH]), rec)
    setup = arm.ArmSetup(load_dataset(path))
    setup.nominal()
    ctx = setup.ctx
    m = arm_screen.add_candidate(ctx, arm_model.ArmModel(), "hysteresis", "maxwell_slip")
    m.set_slip([5.5], [0.003])  # a compromise between the two elements
    free = ["c_scale", "hysteresis.k0", "hysteresis.d0"]
    fit = arm_fit.evaluate(ctx, m, free, "hysteresis[maxwell_slip]")
    assert fit is not None
    fit.effect, fit.variant = "hysteresis", "maxwell_slip"
    return setup, arm_fit.refine(ctx, fit)


def test_a_second_element_is_added_where_the_loop_needs_it(
    one_element: tuple[arm.ArmSetup, arm_fit.ArmFit],
) -> None:
    setup, fit = one_element
    before = arm_expert.over_noise(setup.ctx, fit)["q3"]
    assert before > 3.0  # one element leaves the loop's corners far above the noise
    grown = setup.finish(fit, ["hysteresis"])
    assert len(setup.slip_added) >= 1 and len(grown.model.slip_delta) >= 2
    assert arm_expert.over_noise(setup.ctx, grown)["q3"] < 0.3 * before
    deltas = sorted(grown.model.slip_delta)
    assert deltas[0] == pytest.approx(0.002, rel=0.3) and deltas[-1] == pytest.approx(
        0.005, rel=0.3
    )
    added = setup.slip_added[0]
    assert added.d_bic_teach < -selection.BIC_THRESHOLD
    assert added.d_bic_held < -selection.BIC_THRESHOLD
    assert {"hysteresis.k1", "hysteresis.d1"} <= set(grown.free)
    assert setup._nominal is not None
    verdict, extras = setup.conclude(setup._nominal, grown, ["hysteresis"])
    assert "slip element" in verdict
    assert extras["slip_elements_added"][0]["delta_rad"] == added.delta_rad


def test_an_element_that_does_not_earn_its_place_is_not_added(
    one_element: tuple[arm.ArmSetup, arm_fit.ArmFit],
) -> None:
    setup, fit = one_element

    def refuse(cur: arm_fit.ArmFit, cand: arm_fit.ArmFit) -> selection.Judgement:
        return selection.Judgement(0.0, 0.0, 0.0, 0.0, 0.0, True, False)

    out, added = arm_slip.grow(setup.ctx, fit, refuse)
    assert out is fit and added == []
    # and nothing is tried unless hysteresis was named
    assert setup.finish(fit, ["coulomb_friction"]) is fit and setup.slip_added == []


def test_new_elements_start_a_step_of_the_screens_own_grid_away(
    one_element: tuple[arm.ArmSetup, arm_fit.ArmFit],
) -> None:
    """GRID_RATIO is the ratio of the screen's slip-deflection grid (arm_fit.make_context)."""
    grid = one_element[0].ctx.slip_grid
    assert np.allclose(grid[1:] / grid[:-1], arm_slip.GRID_RATIO)


def test_the_result_json_lists_the_elements_added(tmp_path: Path) -> None:
    """``slip_elements_added`` in an arm result: what :func:`arm_slip.grow` added (here: a
    record without hysteresis, nothing)."""
    from fsarm_sim.discrepancy import report

    path = tmp_path / "arm.csv"
    arm_synth.write_arm_synthetic(
        path, arm_synth.truth_model([]), arm_synth.ArmRecording(duration_s=2.0, seed=3)
    )
    res = report.result_dict(arm.diagnose_arm(load_dataset(path)))
    assert res["slip_elements_added"] == []
