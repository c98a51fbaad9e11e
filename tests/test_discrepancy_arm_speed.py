"""What makes the arm's diagnosis faster (issue 15) changes none of its results: the delay of a
recorded channel without the compiled function (the same bits), one run per simulator input
(models that differ only in parameters the simulator never sees), refinements in lockstep (the
runs of several side by side: the same fits and the same runs as one after the other), and a
whole diagnosis with its runs side by side or one after the other."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.discrepancy import arm, arm_fit, arm_model, arm_run, arm_synth, core, replay
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.records.measured import Dataset, load_dataset

DURATION_S = 2.0  # s of fig14-sine: short, the runs are what is compared


@pytest.fixture(scope="module")
def record(tmp_path_factory: pytest.TempPathFactory) -> Dataset:
    truth = arm_synth.truth_model(["payload_error=0.5", "coulomb_friction:q3=0.1"])
    rec = arm_synth.ArmRecording(duration_s=DURATION_S, noise_rad=2e-5, seed=4)
    path: Path = tmp_path_factory.mktemp("speed") / "arm.csv"
    arm_synth.write_arm_synthetic(path, truth, rec)
    return load_dataset(path)


def _context(ds: Dataset) -> arm_fit.ArmContext:
    return arm_fit.make_context(ds, arm_run.arm_run(ds))


def _bits(a: np.ndarray) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.int64)


def test_delayed_is_the_compiled_shift_bit_for_bit() -> None:
    rng = np.random.default_rng(15)
    for n in (1, 2, 5, 1001):
        y = np.cumsum(rng.normal(size=n)) * 1e-3
        for d in (0.0, 0.37, -0.37, 3.0, -2.5, 17.25, n + 1.5, -n - 1.0, 1e-13):
            np.testing.assert_array_equal(
                _bits(arm_model.delayed(y, d)), _bits(replay.shifted(y, d))
            )


def test_models_with_the_same_simulator_input_are_one_run(record: Dataset) -> None:
    ctx = _context(record)
    base = arm_model.ArmModel()
    same = [
        arm_fit.with_values(base, ["viscous_damping.b_nms"], np.array([0.0])),  # an effect at zero
        arm_fit.with_values(base, ["payload_kg_refit"], np.array([0.0])),
    ]
    other = arm_fit.with_values(base, ["viscous_damping.b_nms"], np.array([0.01]))
    assert len({m.physical_key() for m in [base, *same]}) == 3  # not one key by their values
    first = ctx.simulate(base)
    assert first is not None and ctx.n_sims == 1
    for m in same:
        assert ctx.simulate(m) is first
    ctx.prefetch([*same, other, other])
    ran = ctx.simulate(other)
    assert ctx.n_sims == 2  # only ``other`` was run (once)
    alone = ctx._run(other)
    assert ran is not None and alone is not None
    for ch in alone:
        np.testing.assert_array_equal(ran[ch], alone[ch])
    # an element with no stiffness slips at no torque: its slip deflection does not matter
    no_k = [base.copy(), base.copy()]
    no_k[0].set_slip([0.0], [1e-3])
    no_k[1].set_slip([0.0], [2e-3])
    assert not ctx.run.exact_shaft  # (a run's own slip elements would stand in for none)
    assert ctx.simulate(no_k[0]) is ctx.simulate(no_k[1])


def test_refinements_in_lockstep_are_the_refinements_one_after_the_other(
    record: Dataset, monkeypatch: pytest.MonkeyPatch
) -> None:
    def starts(ctx: arm_fit.ArmContext) -> list[arm_fit.ArmFit]:
        out = []
        for key, value in (("coulomb_friction.f_c_nm", 0.05), ("payload_error.dm_kg", 0.2)):
            m = arm_fit.with_values(arm_model.ArmModel(), [key], np.array([value]))
            m.labels.append(f"{key.split('.')[0]}[{'q3' if 'friction' in key else 'mass'}]")
            f = arm_fit.evaluate(ctx, m, ["c_scale", key], m.labels[0])
            assert f is not None
            out.append(f)
        return out

    monkeypatch.setattr(arm_fit, "SIM_THREADS", 1)
    one = _context(record)
    alone = [arm_fit.refine(one, f, 2) for f in starts(one)]
    monkeypatch.setattr(arm_fit, "SIM_THREADS", 2)
    two = _context(record)
    lockstep = arm_fit.refine_many(two, starts(two), 2)
    assert two.n_sims == one.n_sims  # the same runs, none on speculation
    for a, b in zip(alone, lockstep, strict=True):
        assert a.model.values == b.model.values and a.model.labels == b.model.labels
        assert a.cost == b.cost and a.label == b.label and a.free == b.free


def test_a_diagnosis_with_its_runs_side_by_side_is_the_same(
    record: Dataset, monkeypatch: pytest.MonkeyPatch
) -> None:
    diags = []
    for threads in (1, 2):
        monkeypatch.setattr(arm_fit, "SIM_THREADS", threads)
        diags.append(arm.diagnose_arm(record))
    seq, par = diags
    assert seq.named == par.named
    assert seq.ctx.n_sims == par.ctx.n_sims
    for a, b in ((seq.final, par.final), (seq.nominal, par.nominal)):
        assert a.model.values == b.model.values and a.cost == b.cost
    assert [s.reason for s in seq.steps] == [s.reason for s in par.steps]
    assert isinstance(seq, core.Diagnosis)


def test_simulation_threads_limits_prefetch_in_its_block_only(
    record: Dataset, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``simulation_threads(1)`` (the benchmark's 0.4.0 path) keeps prefetch from starting a
    pool, nests, and gives the module's limit back on exit, also after an error."""
    pools: list[int] = []

    class Spy(arm_fit.ThreadPoolExecutor):
        def __init__(self, n: int) -> None:
            pools.append(n)
            super().__init__(n)

    monkeypatch.setattr(arm_fit, "ThreadPoolExecutor", Spy)
    monkeypatch.setattr(arm_fit, "SIM_THREADS", 2)
    models = [
        arm_fit.with_values(arm_model.ArmModel(), ["coulomb_friction.f_c_nm"], np.array([v]))
        for v in (0.03, 0.07)
    ]
    with arm_fit.simulation_threads(1):
        assert arm_fit.threads_now() == 1
        with arm_fit.simulation_threads(3):
            assert arm_fit.threads_now() == 3
        assert arm_fit.threads_now() == 1
        _context(record).prefetch(models)
    assert pools == []
    assert arm_fit.threads_now() == 2
    with pytest.raises(RuntimeError), arm_fit.simulation_threads(1):
        raise RuntimeError
    assert arm_fit.threads_now() == 2
    _context(record).prefetch(models)
    assert pools == [2]
    for bad in (0, -1, 1.5, True):
        with (
            pytest.raises(InvalidParameterError, match="simulation threads"),
            arm_fit.simulation_threads(bad),
        ):
            pass
