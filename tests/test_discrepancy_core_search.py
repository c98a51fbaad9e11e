"""The search beyond one effect at a time (issue 16): backfitting of nonlinear settings, the
restart from the nominal model, variant / look-alike swaps and backward elimination
(:mod:`fsarm_sim.discrepancy.core`, :mod:`fsarm_sim.discrepancy.candidates`), and the replay-error
term of the confidence intervals (:mod:`fsarm_sim.discrepancy.uncertainty`). Short synthetic
bench records (10 s) whose true parameters are those the expert battery calibrated."""

from __future__ import annotations

import math

import pytest

from batteries import battery
from batteries.battery_expert import truth_values
from fsarm_sim.discrepancy import (
    candidate_structure,
    candidates,
    replay_inputs,
    selection,
    synth,
    variants,
)
from fsarm_sim.discrepancy.bench_setup import BenchDiagnosis, diagnose
from fsarm_sim.discrepancy.benchmodel import BenchModel, EffectInstance, stated_model
from fsarm_sim.plant.effects import registry


def _record(
    setup: str, effects: list[EffectInstance], trajectory: str, seed: int, rate_hz: float
) -> tuple[BenchModel, BenchDiagnosis]:
    truth = synth.truth_model(setup, stiffness_scale=1.1)
    for e in effects:
        truth = truth.with_effect(e)
    case = battery.Case(
        name=f"{setup}-{seed}",
        setup=setup,
        inertia=False,
        effects=[(e.name, e.variant) for e in effects],
        size=None,
        noise=0.003,
        trajectory=trajectory,
        seed=seed,
        duration_s=10.0,
        rate_hz=rate_hz,
    )
    return truth, diagnose(battery.dataset(truth, case, case.noise))


def _covered(truth: BenchModel, diag: BenchDiagnosis) -> dict[str, bool]:
    tv = truth_values(truth)
    ci = diag.extras["confidence_intervals"]["parameters"]
    return {p["name"]: p["lower"] <= tv[p["name"]] <= p["upper"] for p in ci if p["name"] in tv}


def test_backfit_moves_a_delay_found_before_a_coulomb_element() -> None:
    """A delay named first absorbs part of the friction's lag; once the Coulomb element is in,
    the delay is searched again (with the presliding deflection refined with it): the final
    model reaches the noise floor and its intervals hold the true delay and friction."""
    truth, diag = _record(
        "series_bench",
        [
            EffectInstance(variants.COULOMB, "shaft", {"f_c_nm": 0.377}),
            EffectInstance(variants.DELAY, "input", {"delay_s": 0.0288}),
        ],
        "random",
        1605,
        500.0,
    )
    assert sorted(diag.named) == sorted([variants.COULOMB, variants.DELAY])
    assert not diag.extras["unexplained"]
    cov = _covered(truth, diag)
    assert cov["delay[input].delay_s"] and cov["coulomb_friction[shaft].f_c_nm"]


def test_restart_names_a_backlash_and_the_offset_it_stood_in_for() -> None:
    """One-at-a-time, a backlash off its centre explains most of a backlash *and* an output
    offset, and no offset earns its place on top of it (the residual stays ~7x the noise):
    the restart from the nominal model names both."""
    _, diag = _record(
        "series_bench",
        [
            EffectInstance(
                variants.BACKLASH, "coupling", {"width_rad": 0.1106, "center_rad": 0.01106}
            ),
            EffectInstance(variants.OFFSET, "output", {"offset_nm": 0.638}),
        ],
        "steps",
        1615,
        1000.0,
    )
    assert sorted(diag.named) == sorted([variants.BACKLASH, variants.OFFSET])
    assert any(st.added and "restart" in st.reason for st in diag.steps)
    assert not diag.extras["unexplained"]


def test_a_look_alike_stand_in_is_swapped_for_the_true_effect() -> None:
    """A visco-elastic branch at its shortest time constant stands in for a damper (it won the
    first step of the expert battery's 30 s record of this pair); with the Coulomb element
    beside it, the damper replaces it (:func:`.candidates.swap_variants`)."""
    truth = (
        synth.truth_model("series_bench", stiffness_scale=1.1)
        .with_effect(EffectInstance(variants.COULOMB, "shaft", {"f_c_nm": 0.363}))
        .with_effect(EffectInstance(variants.VISCOUS, "shaft", {"b_nms": 0.477}))
    )
    case = battery.Case(
        "swap", "series_bench", False, [], None, 0.003, "random", 1601, duration_s=10.0
    )
    ds = battery.dataset(truth, case, case.noise)
    ctx = candidate_structure.make_context(replay_inputs.prepare_inputs(ds), stated_model(ds))
    ve = candidates.candidate(ctx, candidates.nominal(ctx), variants.HYSTERESIS, "viscoelastic")
    assert ve is not None
    both = candidates.candidate(ctx, ve, variants.COULOMB, "shaft")
    assert both is not None
    pairs = registry.applicable("series_bench", False)
    swapped, replaced = candidates.swap_variants(ctx, both, pairs, selection.LOOK_ALIKES)
    assert replaced == {variants.HYSTERESIS: variants.VISCOUS}
    assert swapped.mse_held < both.mse_held
    assert {e for e, _ in candidates.present(swapped.structure)} == {
        variants.COULOMB,
        variants.VISCOUS,
    }
    # without the look-alikes nothing but a variant may change
    _, none = candidates.swap_variants(ctx, both, pairs, ())
    assert none == {}


def test_intervals_count_the_replays_own_error() -> None:
    """The parallel bench's link inertia, fitted through the replay's smoothed acceleration, is
    off its true value by several Fisher sd on a plain record; the replay-error term (the
    shift with every filter window halved) widens the interval to hold it, and is reported."""
    truth, diag = _record("parallel_bench", [], "multisine", 1672, 1000.0)
    assert diag.named == []
    ci = {p["name"]: p for p in diag.extras["confidence_intervals"]["parameters"]}
    j = ci["nominal.j_link"]
    assert j["sd_method"] > 0.0 and j["sd"] == math.hypot(j["sd_fisher"], j["sd_method"])
    off = abs(j["value"] - truth_values(truth)["nominal.j_link"])
    assert off > 1.96 * j["sd_fisher"]  # the Fisher interval alone would miss it
    assert _covered(truth, diag)["nominal.j_link"]
    assert "halved" in diag.extras["confidence_intervals"]["method"]


def test_a_candidate_is_fitted_once_per_structure(monkeypatch: pytest.MonkeyPatch) -> None:
    """The bench setup fits a candidate on top of a structure once (the joint search and the
    restart extend the same structures again) and hands out copies whose labels callers set;
    another structure or an inertia load's options fit anew."""
    from types import SimpleNamespace as NS

    import numpy as np

    from fsarm_sim.discrepancy import bench_setup, candidates
    from fsarm_sim.discrepancy.candidate_structure import Fit, Structure

    calls: list[tuple[str, str]] = []

    def fake(ctx: object, cur: Fit, effect: str, variant: str) -> Fit:
        calls.append((effect, variant))
        return Fit(cur.structure, cur.model, cur.yhat, None, 3, 1.0, 2.0, f"{effect}[{variant}]")

    monkeypatch.setattr(candidates, "candidate", fake)
    setup = NS(ctx=NS(inp=NS(inertia_load=False)), _fits={})
    cur = Fit(Structure(slip=np.array([1e-3, 2e-3])), None, np.zeros(3), None, 2, 1.0, 2.0)  # type: ignore[arg-type]
    a = bench_setup.BenchSetup._candidate(setup, cur, "delay", "input")  # type: ignore[arg-type]
    assert a is not None
    a.label, a.effect = "changed", "delay"
    same = Fit(cur.structure.copy(), None, np.zeros(3), None, 2, 1.0, 2.0)  # type: ignore[arg-type]
    b = bench_setup.BenchSetup._candidate(setup, same, "delay", "input")  # type: ignore[arg-type]
    assert b is not None and b is not a and b.label == "delay[input]" and len(calls) == 1
    other = Fit(Structure(slip=np.array([1e-3, 3e-3])), None, np.zeros(3), None, 2, 1.0, 2.0)  # type: ignore[arg-type]
    bench_setup.BenchSetup._candidate(setup, other, "delay", "input")  # type: ignore[arg-type]
    bench_setup.BenchSetup._candidate(setup, cur, "backlash", "coupling")  # type: ignore[arg-type]
    assert len(calls) == 3
    setup.ctx.inp.inertia_load = True
    bench_setup.BenchSetup._candidate(setup, cur, "delay", "input")  # type: ignore[arg-type]
    assert len(calls) == 4
