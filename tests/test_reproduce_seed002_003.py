"""``fsarm reproduce`` for seeds 002 (QA-Joint experiments) and 003 (model selection), quick."""

from __future__ import annotations

import pytest

from fsarm_sim.studies.reproduce import measure002, measure003, runner
from fsarm_sim.studies.reproduce.claims import Context
from fsarm_sim.studies.reproduce.claims_file import paper_claims

# Table 4's linearised models on the teaching half: ours x51 / x238 worse, the paper's x1.23 /
# x1.55 (our trials' share beyond the critical angle; added by issue 27, a real disagreement)
# The C -> D gain of the wheel-unbalance term: ours ~6 % on the bench's estimated flywheel
# (1 kg at 1 mm), the paper's 31 % on its own unprinted one (a real disagreement, cause named).
KNOWN_CONTRADICTED = {"003-linearised-worse-teaching", "003-unbalance-term-significant"}


@pytest.mark.parametrize("paper", ["002", "003"])
def test_quick_claims_run_and_only_known_predictions_are_contradicted(paper: str) -> None:
    claims = runner.select([paper], quick=True)
    report = runner.Report(papers=[paper], quick=True, backend="python")
    runner.run(claims, Context(quick=True, backend="python"), report, lambda rep, _: None)
    assert not report.failed
    verdicts = {r.claim.id: r.verdict for r in report.results}
    # contradicted: only the known predictions, each naming its cause in the note (issue 27)
    contradicted = {r.claim.id: r for r in report.results if r.verdict == "contradicted"}
    assert set(contradicted) <= KNOWN_CONTRADICTED, verdicts
    for r in contradicted.values():
        assert r.claim.role == "prediction" and r.note, r.claim.id
    # the experiments of issue 14 are measured now, not declared missing
    measured = {
        "002": ("002-efficiency-2.7", "002-efficiency-trend", "002-stiffness-adjustment-266"),
        "003": ("003-model-ranking", "003-bic-ranking", "003-fms-broadens-safe-range"),
    }[paper]
    for cid in measured:
        assert verdicts[cid] in ("reproduced", "partly"), (cid, verdicts[cid])


def test_not_implemented_claims_say_what_the_paper_lacks() -> None:
    for claims in (paper_claims("002"), paper_claims("003")):
        for c in claims:
            if c.not_implemented:
                assert "not give" in c.not_implemented or "neither" in c.not_implemented, c.id
    assert set(measure002.MEASURES) >= {c.measure for c in paper_claims("002") if c.measure}
    assert set(measure003.MEASURES) >= {c.measure for c in paper_claims("003") if c.measure}


class _Throw:
    def __init__(self, feasible: bool) -> None:
        self.feasible = feasible


def _memo_throws(lowest: dict[float, float]) -> Context:
    """A context whose throws are feasible from ``lowest[sigma]`` deg/s on (no simulation)."""
    ctx = Context()
    for s, lo in lowest.items():
        speeds = list(measure002.WINDOW_SPEEDS_DEG_S)
        for v in speeds:
            ctx.memo[f"002/throw/{s}/{v}/none"] = _Throw(v >= lo)
        first = next((v for v in speeds if v >= lo), None)
        if first is not None and first != speeds[0]:
            lo_v, hi = speeds[speeds.index(first) - 1], first
            for _ in range(measure002.LOWEST_SPEED_STEPS):
                mid = 0.5 * (lo_v + hi)
                ctx.memo[f"002/throw/{s}/{mid}/none"] = _Throw(mid >= lo)
                if mid >= lo:
                    hi = mid
                else:
                    lo_v = mid
    return ctx


def test_lowest_feasible_speed_is_found_between_the_grid_speeds() -> None:
    rising = _memo_throws({3.0: 35.0, 7.0: 40.0, 11.0: 50.0, 15.0: 55.0})
    m = measure002.low_stiffness_needs_faster(rising)
    assert m.ours == [True, True]
    assert m.details is not None and 34.0 < m.details["3"] <= 36.0 and m.details["15"] > 54.0
    # a dip at one preset is not "never falls"; an infeasible preset shows nothing
    assert measure002.low_stiffness_needs_faster(
        _memo_throws({3.0: 35.0, 7.0: 50.0, 11.0: 40.0, 15.0: 55.0})
    ).ours == [True, False]
    assert measure002.low_stiffness_needs_faster(
        _memo_throws({3.0: 35.0, 7.0: 40.0, 11.0: 50.0, 15.0: 1e9})
    ).ours == [False, False]


class _Study:
    def __init__(self, fr: dict[str, dict[str, float]]) -> None:
        self.free_run_deg = fr


def test_free_run_claims_read_both_classes() -> None:
    ctx = Context()
    ctx.memo["003/study"] = _Study(
        {
            "within ±31.5° (2 trials)": {"A": 10.0, "F": 0.5, "AL": 9.0, "FL": 0.8},
            "beyond 31.5° (7 trials)": {"A": 300.0, "F": 1.3, "AL": 480.0, "FL": 97.0},
        }
    )
    assert measure003.free_run_beyond(ctx).ours == [True, True, True]
    assert measure003.free_run_within_fl(ctx).ours == pytest.approx(1.6)
    assert measure003.free_run_critical(ctx).ours == [True]
    ctx.memo["003/study"] = _Study({"beyond 31.5° (9 trials)": {"A": 1.0, "F": 1.0}})
    with pytest.raises(ValueError, match="lacks a class"):
        measure003.free_run_critical(ctx)


def test_no_model_beats_f_flags_each_model_and_class() -> None:
    ctx = Context()
    within = {"A": 10.0, "B": 0.8, "C": 0.8, "D": 0.6, "E": 0.49, "F": 0.5, "AL": 9.0, "FL": 3.0}
    beyond = {"A": 300.0, "B": 1.5, "C": 1.6, "D": 1.3, "E": 1.1, "F": 1.3, "AL": 480.0, "FL": 97.0}
    ctx.memo["003/study"] = _Study({"within ±31.5° (2 trials)": within, "beyond 31.5°": beyond})
    # E within 2 % of F is not better (5 % tie); E beyond, 15 % below F, is
    assert measure003.free_run_no_model_beats_f(ctx).ours == [True] * 7 + [False]
    # the beyond-class claim still compares F with A, F, A_L, F_L only
    assert measure003.free_run_beyond(ctx).ours == [True, True, True]


def _scored(mse_verify: dict[str, float]) -> Context:
    """A context whose study scored each Table 3 model with this verifying-half MSE."""
    from types import SimpleNamespace

    def half(mse: float) -> SimpleNamespace:
        return SimpleNamespace(mse=mse, one_minus_r2_adj=0.0, se=0.0, bic=0.0)

    rows = {
        m: SimpleNamespace(
            teaching=half(v), verifying=half(v), fit=SimpleNamespace(v=0.0, params=())
        )
        for m, v in mse_verify.items()
    }
    ctx = Context()
    ctx.memo["003/study"] = SimpleNamespace(rows=rows)
    return ctx


def test_unbalance_term_is_the_c_to_d_reduction_of_the_verifying_mse() -> None:
    mse = {"A": 4175.0, "B": 3051.0, "C": 2976.0, "D": 2050.0, "E": 2040.0, "F": 2000.0}
    m = measure003.unbalance_term(_scored(mse))
    assert m.ours == pytest.approx(1.0 - 2050.0 / 2976.0)  # Table 4: 31.1 %
    assert "-31.1 %" in m.text and "estimate" in m.note
    # a D no better than C is no gain at all
    flat = measure003.unbalance_term(_scored({**mse, "D": 2976.0}))
    assert flat.ours == pytest.approx(0.0)
