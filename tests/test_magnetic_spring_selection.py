"""Seed 003's model-selection study on the simulated ATTRACTOR bench."""

from __future__ import annotations

import pytest

from fsarm_sim.studies import magnetic_spring_selection as sel


@pytest.fixture(scope="module")
def study() -> sel.Study:
    return sel.run_study(
        sel.BenchConfig(trial_s=2.5), free_run=True, free_run_models=("A", "F", "FL")
    )


def test_experiments_a_and_b_identify_the_bench(study: sel.Study) -> None:
    assert study.inertia_kgm2 == pytest.approx(study.cfg.inertia_kgm2, rel=0.05)
    assert study.fitted_stiffness_nm_per_rad == pytest.approx(
        study.true_stiffness_nm_per_rad, rel=0.05
    )
    assert study.n_trials[0] == study.n_trials[1]  # two equinumerous sets (Sec. 6.1)


def test_model_ranking_on_the_verifying_half(study: sel.Study) -> None:
    v = {m: r.verifying.mse for m, r in study.rows.items()}
    assert v["F"] < v["D"] < v["C"] < v["B"] < v["A"]
    # the linearised models fail once trials exceed the critical angle (Table 4: A_L, F_L)
    assert study.n_beyond_critical > 0
    assert v["FL"] > 10 * v["F"]
    assert "Verifying set" in study.table()


def test_long_term_simulation_model_f_beats_a_within_the_stable_range(study: sel.Study) -> None:
    within = next(v for k, v in study.free_run_deg.items() if k.startswith("within"))
    assert within["F"] < 0.5 * within["A"]
    assert within["F"] < within["FL"]
    assert "long-term simulation" in study.table()


def test_unbalance_term_gain_grows_with_the_unbalance() -> None:
    def gain(w: float) -> float:
        st = sel.run_study(sel.BenchConfig(trial_s=2.0, unbalance_nm=w))
        return 1.0 - st.rows["D"].verifying.mse / st.rows["C"].verifying.mse

    assert gain(0.03) > gain(0.0) + 0.05


def test_split_halves_and_bad_config() -> None:
    trials = list(range(7))
    teach, verify = sel.split_halves(trials)  # type: ignore[arg-type]
    assert teach == [0, 2, 4] and verify == [1, 3, 5]
    with pytest.raises(sel.BenchError):
        sel.split_halves([1])  # type: ignore[list-item]
    for bad in (
        {"inertia_kgm2": 0.0},
        {"unbalance_nm": -1.0},
        {"period_s": 0.0007},
        {"encoder_bits": 4},
        {"a_distances_m": (0.0, 0.001)},
    ):
        with pytest.raises(sel.BenchError):
            sel.BenchConfig(**bad).check()


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"trial_s": 1e9}, "trial_s (--trial-s) must be at most 600 s"),  # was 14.6 TiB
        ({"trial_s": 60.0, "dt_sim_s": 1e-5, "period_s": 1e-5}, "samples per trial"),
        ({"trial_s": True}, "trial_s must be a number"),
    ],
)
def test_trial_sizes_are_capped_before_any_work(changes: dict[str, object], words: str) -> None:
    with pytest.raises(sel.BenchError, match=words.replace("(", r"\(").replace(")", r"\)")):
        sel.run_study(sel.BenchConfig(**changes))  # type: ignore[arg-type]
