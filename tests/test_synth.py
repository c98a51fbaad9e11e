"""fsarm synth: synthetic measured-format datasets with hidden effects."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fsarm_sim.discrepancy import replay, replay_inputs, synth
from fsarm_sim.discrepancy.benchmodel import EffectInstance, load_model, model_from_dict
from fsarm_sim.discrepancy.residuals import lag_of_best_match, noise_floor
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.records.measured import load_dataset

REC = synth.Recording(duration_s=6.0, noise=0.01, trajectory="multisine", seed=1)


@pytest.mark.parametrize("kind", synth.TRAJECTORIES)
def test_trajectories_respect_amplitude_and_rate(kind: str) -> None:
    t = np.arange(0, 20.0, 1e-3)
    u = synth.trajectory(kind, t, 0.4, 5.0, seed=3)
    assert np.max(np.abs(u)) <= 0.4 + 1e-12
    assert np.max(np.abs(np.gradient(u, t))) <= 0.8 * 5.0 * 1.01
    assert abs(u[0]) < 1e-9 and abs(u[-1]) < 1e-9  # starts and ends at rest
    with pytest.raises(InvalidParameterError, match="unknown trajectory"):
        synth.trajectory("zigzag", t, 0.4, 5.0)


def test_synthetic_dataset_is_valid_labelled_and_noisy_as_asked(tmp_path: Path) -> None:
    truth = synth.truth_model("series_bench")
    table, side = synth.write_synthetic(tmp_path / "s", truth, REC)
    ds = load_dataset(table)
    assert ds.notes.startswith("SYNTHETIC")
    assert json.loads(side.read_text())["synthetic"]["truth"]["setup"] == "series_bench"
    sigma = ds.sidecar["synthetic"]["noise_std"]
    assert sigma == pytest.approx(0.01 * np.ptp(ds.columns["tau_s"]), rel=0.05)
    assert noise_floor(ds.columns["tau_s"]) == pytest.approx(sigma, rel=0.1)
    # the truth embedded in the sidecar replays the data down to the noise
    inp = replay_inputs.prepare_inputs(ds)
    y = replay.replay(model_from_dict(ds.sidecar["synthetic"]["truth"]), inp)["y"]
    assert np.std(inp.y - y) == pytest.approx(sigma, rel=0.1)


def test_parquet_and_parallel(tmp_path: Path) -> None:
    truth = synth.truth_model("parallel_bench")
    table, _ = synth.write_synthetic(tmp_path / "p.parquet", truth, REC)
    ds = load_dataset(table)
    assert ds.setup == "parallel_bench" and table.suffix == ".parquet"
    assert truth.nominal["j_link"] == pytest.approx(
        0.01
    )  # read from models/bench/parallel_bench.xml


def test_hidden_delay_and_offset_show_in_the_data() -> None:
    base = synth.truth_model("series_bench")
    rec = synth.Recording(duration_s=6.0, noise=0.0, trajectory="random", seed=2)
    cols0, _ = synth.synthesize(base, rec)
    d = base.with_effect(EffectInstance("delay", "input", {"delay_s": 0.02}))
    cols1, _ = synth.synthesize(d, rec)
    assert lag_of_best_match(cols1["tau_s"], cols0["tau_s"], 1e-3) == pytest.approx(0.02, abs=5e-4)
    o = base.with_effect(EffectInstance("sensor_offset", "output", {"offset_nm": 0.3}))
    cols2, _ = synth.synthesize(o, rec)
    assert np.allclose(cols2["tau_s"] - cols0["tau_s"], 0.3)


def test_inertia_load_moves_the_output() -> None:
    truth = synth.truth_model("series_bench", load_inertia_kgm2=0.01)
    cols, side = synth.synthesize(truth, REC)
    assert side["load"] == {"type": "inertia", "inertia_kgm2": 0.01}
    assert np.ptp(cols["theta_s"]) > 0.5 * np.ptp(cols["theta_m"])


def test_parse_effect() -> None:
    e = synth.parse_effect("hysteresis:maxwell_slip=12,0.01,6,0.03", "series_bench", 0.4)
    assert e.params == {"k_nm_per_rad": [12.0, 6.0], "delta_rad": [0.01, 0.03]}
    e = synth.parse_effect("nonlinear_stiffness=0.0,1.5", "series_bench", 0.4)
    assert e.variant == "poly" and e.params["x_ref_rad"] == 0.4
    for bad, words in (
        ("gremlins=1", "unknown effect"),
        ("delay=1.0", "outside"),
        ("backlash=0.1", "takes 2 value"),
        ("coulomb_friction:load=0.1", "does not act"),
        ("delay", "NAME"),
    ):
        with pytest.raises(InvalidParameterError, match=words):
            synth.parse_effect(bad, "parallel_bench" if "load" in bad else "series_bench", 0.4)


def test_cli_synth_then_diagnose(tmp_path: Path) -> None:
    from fsarm_sim.cli import app

    runner = CliRunner()
    out = tmp_path / "c"
    res = runner.invoke(
        app,
        [
            "synth",
            str(out),
            "--effect",
            "coulomb_friction:shaft=0.3",
            "--duration",
            "8",
            "--trajectory",
            "triangle",
            "--seed",
            "4",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "SYNTHETIC" in res.output
    res = runner.invoke(
        app,
        [
            "diagnose",
            str(out) + ".csv",
            "--json",
            str(tmp_path / "r.json"),
            "--model",
            str(tmp_path / "m.json"),
        ],
    )
    assert res.exit_code == 0, res.output
    r = json.loads((tmp_path / "r.json").read_text())
    assert r["named_effects"] == ["coulomb_friction"]
    assert r["gap_after"] < 0.5 * r["gap_before"]
    m = load_model(tmp_path / "m.json")
    assert m.effect("coulomb_friction", "shaft") is not None
    # the written model is a valid truth for synth (round trip through the model file)
    res = runner.invoke(
        app,
        ["synth", str(tmp_path / "again"), "--model", str(tmp_path / "m.json"), "--duration", "3"],
    )
    assert res.exit_code == 0, res.output


@pytest.mark.parametrize("names", [("--diameter-mm", "--length-mm"), ("--diameter", "--length")])
def test_cli_synth_shaft_options_take_the_run_commands_names(
    tmp_path: Path, names: tuple[str, str]
) -> None:
    """``--diameter-mm`` / ``--length-mm`` as in ``fsarm run``; the older names still work."""
    from fsarm_sim.cli import app

    out = tmp_path / "s"
    args = ["synth", str(out), names[0], "8", names[1], "500", "--duration", "2"]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    side = json.loads((tmp_path / "s.json").read_text())
    assert side["shaft"] == {"diameter_mm": 8.0, "length_mm": 500.0}


def test_synth_enforces_the_bend_validity_of_run(tmp_path: Path) -> None:
    """Issue 33: --bend-deg 500 wrote a record with a -9.8 N·m/rad slope; the one bend check
    (shaft.check_bend_rad, as run, sweep and the bench) now refuses it."""
    from fsarm_sim.errors import ShaftRangeError

    rec = synth.Recording(duration_s=1.0, bend_rad=math.radians(500.0))
    with pytest.raises(ShaftRangeError, match=r"outside the validity range \[-2.094, 2.094\]"):
        synth.synthesize_setup("series_bench", recording=rec)
    ok = synth.Recording(duration_s=1.0, bend_rad=math.radians(120.0))  # the edge is valid
    cols, _, _ = synth.synthesize_setup("series_bench", recording=ok)
    assert np.allclose(cols["phi_b"], math.radians(120.0))
    with pytest.raises(InvalidParameterError, match="bend_rad must be a number"):
        synth.Recording(bend_rad=True).validate()  # type: ignore[arg-type]


def test_synth_refuses_to_overwrite_its_input_file(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Issue 33: `fsarm synth OUT --input-file OUT.csv` overwrote its own input."""
    from conftest import run_fsarm

    f = tmp_path / "x.csv"
    t = np.arange(0.0, 2.0, 0.001)
    synth.write_input_file(f, t, 0.01 * np.sin(t), "series_bench")
    before = f.read_bytes()
    for out in (tmp_path / "x", f, tmp_path / "x.parquet"):
        code = run_fsarm(monkeypatch, "synth", str(out), "--input-file", str(f), "--rate", "100")
        err = capsys.readouterr().err
        if out.suffix == ".parquet":  # another file: a correct run
            assert code == 0, err
            continue
        (line,) = err.strip().splitlines()
        assert code == 2 and "is the trajectory file of --input-file (an input)" in line
    assert f.read_bytes() == before
    code = run_fsarm(monkeypatch, "synth", str(tmp_path / "b"), "--bend-deg", "500")
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and "bend_rad (--bend-deg): 8.727 rad (500.0 deg) is outside" in line
    assert not (tmp_path / "b.csv").exists()


def test_input_file_with_a_repeated_column_is_refused(tmp_path: Path) -> None:
    f = tmp_path / "in.csv"
    rows = "\n".join(f"{0.01 * i},{0.1 * i},{0.2 * i}" for i in range(20))
    f.write_text("t,theta_m,theta_m\n" + rows + "\n")
    with pytest.raises(InvalidParameterError, match=r"\['theta_m'\] are given twice"):
        synth.read_input_file(f, "series_bench")
    f.write_text("t,theta_m\n" + "0,0\n" * 3)
    with pytest.raises(InvalidParameterError, match=">= 10 finite rows"):
        synth.read_input_file(f, "series_bench")
