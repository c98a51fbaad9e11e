"""The discrepancy workflow on the arm: closed-loop replay of a recorded run, nominal refit,
effects hidden in SYNTHETIC runs (fsarm_sim.discrepancy.arm_synth.synthesize_arm) named and their
parameters recovered, named errors for bad arm data, model file and CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.discrepancy import arm, arm_synth, replay
from fsarm_sim.discrepancy import arm_modelfile as MF
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.effects import delay
from fsarm_sim.records.measured import (
    MissingColumnError,
    SidecarError,
    TimeAxisError,
    load_dataset,
    write_dataset,
)

from conftest import run_fsarm

DUR = 4.0  # s of fig14-sine: one full 0-90-0 deg sweep of joint 3


def _record(
    tmp: Path,
    name: str,
    effects: list[str],
    *,
    noise: float = 2e-5,
    counts: int = arm_synth.ARM_ENCODER_COUNTS,
    stiffness: float = 1.0,
    seed: int = 0,
    scenario: str = "fig14-sine",
    duration: float = DUR,
    derivatives: bool = True,
) -> Path:
    truth = arm_synth.truth_model(effects, stiffness_scale=stiffness)
    rec = arm_synth.ArmRecording(
        scenario=scenario,
        duration_s=duration,
        noise_rad=noise,
        encoder_counts=counts,
        seed=seed,
        derivatives=derivatives,
    )
    table, _ = arm_synth.write_arm_synthetic(tmp / f"{name}.csv", truth, rec)
    return table


def _effect(diag: arm.ArmDiagnosis, name: str) -> dict[str, float]:
    for e in diag.final.model.effects():
        if e.name == name:
            return e.params
    raise AssertionError(f"{name} not in the final model")


# ------------------------------------------------------------------ replay


def test_replay_reproduces_a_clean_record_exactly(tmp_path: Path) -> None:
    """Nothing hidden, no noise, no quantisation: the replay from the CSV (10 digits) and the
    sidecar is the recorded run to the CSV's precision - controller, references and all."""
    ds = load_dataset(_record(tmp_path, "clean", [], noise=0.0, counts=0))
    run = arm.arm_run(ds)
    sim, coef_s = arm.simulate_config(run, arm.to_config(run, arm.ArmModel()))
    assert coef_s == pytest.approx(10.0)  # i_G2 of the MJCF
    for ch in ("q1", "q2", "q3", "theta_m"):
        assert np.max(np.abs(sim[ch] - ds.columns[ch])) < 1e-8, ch
    assert np.ptp(ds.columns["q3"]) > 1.5  # the run does move (0-90 deg)


def test_reference_table_differentiates_missing_rates(tmp_path: Path) -> None:
    """Without qd/qdd columns the rates are central differences of the recorded references
    (second-order accurate on the smooth sweep) and zero across a step."""
    ds = load_dataset(_record(tmp_path, "sweep", [], derivatives=False, duration=2.0))
    table, note = arm.reference_table(ds, 1e-3)
    t = np.arange(table.shape[0]) * 1e-3
    w = 2 * np.pi / 4.0
    a = 0.25 * np.pi  # fig14-sine: q3 = a (1 - cos w t)
    inner = slice(2, ds.n - 2)
    assert np.allclose(table[inner, 5], a * w * np.sin(w * t[inner]), atol=1e-5)
    # accelerations: differences of differences of 10-digit CSV values (~1e-4 rad/s^2 noise)
    assert np.allclose(table[inner, 8], a * w * w * np.cos(w * t[inner]), atol=2e-3)
    assert "central differences" in note
    ds = load_dataset(_record(tmp_path, "step", [], derivatives=False, scenario="step-q3"))
    table, _ = arm.reference_table(ds, 1e-3)
    assert np.all(table[:, 5] == 0.0) and np.all(table[:, 8] == 0.0)  # the step has no rate


def test_measurement_model_uses_the_effect_kernels() -> None:
    h = 1e-3
    y = np.sin(np.arange(500) * h * 7.0)
    m = arm.ArmModel()
    m.values.update({"delay.q3": 0.0037, "sensor_offset.theta_m": 0.01})
    out = arm.apply_measurement({"q3": y, "theta_m": y, "q2": y}, m, h)
    assert np.allclose(out["q3"], delay.delayed_signal(y, 3.7))
    assert np.allclose(out["theta_m"], y + 0.01) and np.array_equal(out["q2"], y)
    assert np.allclose(replay.shifted(y, 3.7), delay.delayed_signal(y, 3.7))


# ------------------------------------------------------------------ diagnosis


def test_null_record_names_nothing_and_refits_the_stiffness(tmp_path: Path) -> None:
    """True shaft 10 % stiffer than the catalogue, nothing else: the nominal refit finds the
    stiffness of the twist side the run visits and nothing is named; the gap is at the noise
    floor."""
    diag = arm.diagnose_arm(load_dataset(_record(tmp_path, "null", [], stiffness=1.1, seed=3)))
    assert diag.named == []
    assert diag.final.model.nominal()["k_scale_neg"] == pytest.approx(1.1, rel=0.01)
    assert diag.gap_over_noise(diag.final) < 1.1
    assert diag.gap_over_noise(diag.catalogue) > 5.0  # the catalogue model alone is off
    assert "nothing is missing" in diag.verdict


def test_payload_error_is_named_and_its_mass_recovered(tmp_path: Path) -> None:
    diag = arm.diagnose_arm(load_dataset(_record(tmp_path, "pay", ["payload_error=0.4"], seed=1)))
    assert diag.named == ["payload_error"]
    assert _effect(diag, "payload_error")["dm_kg"] == pytest.approx(0.4, abs=0.01)
    assert diag.gap_after < 0.5 * diag.gap_before
    assert diag.gap_over_noise(diag.final) < 1.2
    assert diag.steps[0].bic_margin is not None and diag.steps[0].bic_margin > 10.0


def test_coulomb_friction_at_joint_3_is_named(tmp_path: Path) -> None:
    ds = load_dataset(_record(tmp_path, "fric", ["coulomb_friction=0.15"], noise=5e-5, seed=2))
    diag = arm.diagnose_arm(ds)
    assert diag.named == ["coulomb_friction"]
    assert _effect(diag, "coulomb_friction")["f_c_nm"] == pytest.approx(0.15, rel=0.05)
    assert diag.gap_after < 0.5 * diag.gap_before


def test_delay_and_offset_of_recorded_channels_are_named(tmp_path: Path) -> None:
    """q3 recorded 4 ms late and theta_m with a 3 mrad bias: two measurement effects, one at a
    time; the delay is not taken for viscous damping (its look-alike)."""
    ds = load_dataset(
        _record(tmp_path, "meas", ["delay:q3=0.004", "sensor_offset:theta_m=0.003"], seed=4)
    )
    diag = arm.diagnose_arm(ds)
    assert sorted(diag.named) == ["delay", "sensor_offset"]
    assert _effect(diag, "delay")["delay_s"] == pytest.approx(0.004, abs=1e-4)
    assert _effect(diag, "sensor_offset")["offset_rad"] == pytest.approx(0.003, rel=0.02)
    assert {e.variant for e in diag.final.model.effects()} == {"q3", "theta_m"}
    assert diag.gap_over_noise(diag.final) < 1.2


# ------------------------------------------------------------------ bad data


def _minimal_arm(tmp: Path, **side_changes: object) -> Path:
    n = 300
    t = np.arange(n) * 1e-3
    cols = {c: np.zeros(n) for c in ("q1", "q2", "q3", "theta_m", "q1_ref", "q2_ref", "q3_ref")}
    cols["t"] = t
    side: dict[str, object] = {
        "setup": "arm",
        "shaft": {"diameter_mm": 9.0, "length_mm": 450.0},
        "payload_kg": 0.0,
        "ctrl_dt_s": 1e-3,
    }
    table, json_file = write_dataset(tmp / "arm.csv", cols, side)
    side.update(side_changes)
    side = {k: v for k, v in side.items() if v is not None}
    json_file.write_text(json.dumps(side))  # as written by hand: no writer's checks
    return table


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"payload_kg": None}, "needs 'payload_kg'"),
        ({"payload_kg": 20.0}, "payload_kg"),
        ({"ctrl_dt_s": None}, "needs 'ctrl_dt_s'"),
        ({"ctrl_dt_s": -1.0}, "ctrl_dt_s"),
        ({"gains": {"wn": 3}}, "unknown key 'gains.wn'"),
        ({"gains": {"zeta": [1.0, 1.0]}}, "list of 3 numbers"),
        ({"transmission": "harmonic-drive"}, "unknown transmission 'harmonic-drive'"),
        ({"transmission": {"name": "rtca", "params": {"scale": -1.0}}}, "transmission"),
        ({"payload_tolerance_kg": -1.0}, "payload_tolerance_kg"),
    ],
)
def test_bad_arm_sidecar_is_a_named_error(
    tmp_path: Path, change: dict[str, object], match: str
) -> None:
    """Reading (the schema: keys, types) or rebuilding the run (ranges, names) says which file
    and which key."""
    table = _minimal_arm(tmp_path, **change)
    with pytest.raises(SidecarError, match=match) as info:
        arm.arm_run(load_dataset(table))
    assert "arm.json" in str(info.value)


def test_bad_arm_table_is_a_named_error(tmp_path: Path) -> None:
    table = _minimal_arm(tmp_path)
    text = table.read_text().splitlines()
    head = text[0].split(",")
    i = head.index("q3_ref")
    table.write_text(
        "\n".join(",".join(c for j, c in enumerate(r.split(",")) if j != i) for r in text) + "\n"
    )
    with pytest.raises(MissingColumnError, match="q3_ref"):
        load_dataset(table)
    table = _minimal_arm(tmp_path)
    rows = table.read_text().splitlines()
    rows[10], rows[11] = rows[11], rows[10]
    table.write_text("\n".join(rows) + "\n")
    with pytest.raises(TimeAxisError, match="row"):
        load_dataset(table)


def test_ctrl_period_not_a_multiple_of_the_timestep_is_a_named_error(tmp_path: Path) -> None:
    ds = load_dataset(_minimal_arm(tmp_path, ctrl_dt_s=1.5e-3))
    with pytest.raises(arm.ArmReplayError, match="whole multiple"):
        arm.make_context(ds, arm.arm_run(ds))


# ------------------------------------------------------------------ model file, CLI


def test_model_file_loads_as_a_sim_config(tmp_path: Path, prototype) -> None:  # type: ignore[no-untyped-def]
    m = arm_synth.truth_model(
        ["payload_error=0.3", "coulomb_friction=0.1", "hysteresis=4,0.003", "delay:q3=0.002"],
        stiffness_scale=1.2,
    )
    run = arm.ArmRun(
        prototype, 2.0, 0.0, SimConfig().gains, None, np.zeros((1, 9)), np.zeros(1), 1e-3, ""
    )
    path = MF.save_arm_model(run, m, tmp_path / "model.json")
    cfg = MF.load_arm_config(path)
    laws = dict(cfg.effects.laws)
    assert cfg.payload_kg == 2.0 and dict(laws["payload_error"])["dm_kg"] == pytest.approx(0.3)
    assert dict(laws["coulomb_friction"]) == pytest.approx({"f_c_nm": 0.1})
    assert cfg.shaft.k_neg == pytest.approx(1.2 * prototype.k_neg)
    assert cfg.shaft.slip_k[0] == 4.0 and cfg.shaft.slip_f[0] == pytest.approx(0.012)
    assert cfg.controller_shaft == prototype  # the controller keeps the stated shaft
    back, _ = MF.load_arm_model(path)
    assert back.v("delay.q3") == 0.002 and back.labels == m.labels
    d = json.loads(path.read_text())
    d["effects"].append({"name": "warp_drive", "variant": "q3", "params": {}})
    path.write_text(json.dumps(d))
    with pytest.raises(MF.ArmModelFileError, match="unknown arm effect"):
        MF.load_arm_model(path)
    with pytest.raises(ValueError, match="not understood"):
        arm_synth.parse_arm_effect("payload_error=1,2")


def test_cli_synth_and_diagnose_arm(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    data = tmp_path / "cli_arm"
    code = run_fsarm(
        monkeypatch,
        "synth",
        str(data),
        "--setup",
        "arm",
        "--duration",
        "3",
        "--effect",
        "viscous_damping=0.2",
        "--seed",
        "5",
    )
    assert code == 0
    side = json.loads(data.with_suffix(".json").read_text())
    assert side["notes"].startswith("SYNTHETIC") and side["setup"] == "arm"
    out = tmp_path / "res.json"
    code = run_fsarm(
        monkeypatch,
        "diagnose",
        str(data) + ".csv",
        "--json",
        str(out),
        "--model",
        str(tmp_path / "m.json"),
    )
    assert code == 0
    res = json.loads(out.read_text())
    assert res["named_effects"] == ["viscous_damping"]
    assert res["gap_after"] < 0.5 * res["gap_before"]
    assert set(res["nrmse"]) == {"q3", "theta_m", "q2", "twist"}
    assert res["confidence"][0]["runner_up"] and res["bic"]["final"] < res["bic"]["nominal"]
    cfg = MF.load_arm_config(tmp_path / "m.json")
    assert dict(dict(cfg.effects.laws)["viscous_damping"])["b_nms"] == pytest.approx(0.2, rel=0.05)


@pytest.mark.parametrize(
    "bench_option", [["--noise", "0.01"], ["--trajectory", "triangle"], ["--load", "inertia"]]
)
def test_cli_synth_arm_refuses_what_only_benches_read(
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    bench_option: list[str],
) -> None:
    # 0.4.0 ignored them silently (and --rate): an arm record that is not what was asked for
    code = run_fsarm(monkeypatch, "synth", str(tmp_path / "a"), "--setup", "arm", *bench_option)
    assert code != 0
    assert bench_option[0] in capsys.readouterr().err
    assert not (tmp_path / "a.csv").exists()


def test_runs_side_by_side_give_the_runs_one_after_the_other(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # ArmContext.prefetch steps a step's simulations in threads: the same runs, bit for bit
    from fsarm_sim.discrepancy import arm_fit, arm_model, arm_run

    monkeypatch.setattr(arm_fit, "SIM_THREADS", 2)
    ds = load_dataset(_record(tmp_path, "par", ["coulomb_friction:q3=0.1"], duration=2.0))
    ctx = arm_fit.make_context(ds, arm_run.arm_run(ds))
    base = arm_model.ArmModel()
    models = [
        arm_fit.with_values(base, ["payload_kg_refit"], np.array([v])) for v in (0.0, 0.5, 1.0)
    ]
    sequential = [ctx._run(m) for m in models]
    ctx.prefetch(models)
    assert ctx.n_sims == 3
    for m, seq in zip(models, sequential, strict=True):
        par = ctx.simulate(m)
        assert par is not None and seq is not None
        for ch in seq:
            np.testing.assert_array_equal(par[ch], seq[ch])
    assert ctx.n_sims == 3  # found in the cache


@pytest.mark.parametrize(
    ("rate", "ctrl_dt", "timestep"), [(500.0, 1e-3, None), (2000.0, 5e-4, 5e-4)]
)
def test_arm_records_at_other_rates_replay(
    tmp_path: Path, rate: float, ctrl_dt: float, timestep: float | None
) -> None:
    # slower than the 1 kHz controller: every k-th tick, references interpolated back onto the
    # ticks by the replay; faster: the controller (and the physics) at the record's rate
    truth = arm_synth.truth_model([])
    rec = arm_synth.ArmRecording(duration_s=2.0, noise_rad=0.0, encoder_counts=0, rate_hz=rate)
    table, side = arm_synth.write_arm_synthetic(tmp_path / "r.csv", truth, rec)
    ds = load_dataset(table)
    assert ds.dt == pytest.approx(1.0 / rate)
    meta = json.loads(side.read_text())
    assert meta["ctrl_dt_s"] == pytest.approx(ctrl_dt)
    assert meta.get("timestep_s") == timestep
    run = arm.arm_run(ds)
    sim, _ = arm.simulate_config(run, arm.to_config(run, arm.ArmModel()))
    # exact at the control rate; at 500 Hz the references between samples are interpolated
    tol = 1e-8 if rate >= 1000.0 else 1e-5
    for ch in ("q2", "q3", "theta_m"):
        assert np.max(np.abs(sim[ch] - ds.columns[ch])) < tol, ch


def test_arm_record_rates_that_cannot_be_made_are_named_errors() -> None:
    for rate in (300.0, 1e6, float("nan"), 50.0):
        with pytest.raises(InvalidParameterError, match="rate"):
            arm_synth.ArmRecording(rate_hz=rate).validate()


def test_model_timestep_constant_is_the_models() -> None:
    import mujoco

    from fsarm_sim.engine.model import model_path
    from fsarm_sim.sim.simulation import DEFAULT_TIMESTEP_S

    assert mujoco.MjModel.from_xml_path(str(model_path())).opt.timestep == DEFAULT_TIMESTEP_S


def test_a_linear_step_to_a_bound_lands_on_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """A bounded step that goes to a lower bound ends exactly on it: ``v + ((a - v)/u) u`` can
    round past it (f_c = 0.9391... N*m with a 0.1 unit gave -1.1e-16), and a slip stiffness of
    -1e-16 made the transmission refuse the model, ending the whole diagnosis."""
    from fsarm_sim.discrepancy import arm_fit, arm_model, lsq

    key = "coulomb_friction.f_c_nm"
    # (the context is read only for payload bounds)
    lo, _, unit = arm_fit.bounds_of(None, key)
    v = 0.9391491627785106
    assert v + ((lo - v) / unit) * unit < lo  # the rounding this guards against
    m = arm_fit.with_values(arm_model.ArmModel(), [key], np.array([v]))
    monkeypatch.setattr(lsq, "bounded", lambda a, b, lo_, hi_: np.asarray(lo_, dtype=float))
    out = arm_fit.linear_solve(None, m, [key], np.ones((3, 1)), np.zeros(3))
    assert out.v(key) == lo
