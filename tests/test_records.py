"""One typed record schema (fsarm_sim.records.sidecar): every writer's sidecar reads back equal, legacy
sidecars still load, unknown keys and wrong types are named errors, and a record written by
``fsarm run`` is diagnosed as it is (unused columns listed, not refused)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsarm_sim.discrepancy import arm, arm_synth, synth
from fsarm_sim.discrepancy import arm_modelfile as MF
from fsarm_sim.engine.model import Effects, SimConfig
from fsarm_sim.plant import transmissions
from fsarm_sim.records import sidecar as rec
from fsarm_sim.records import timeseries
from fsarm_sim.records.measured import SidecarError, load_dataset
from fsarm_sim.sim.simulation import run_scenario

from conftest import run_fsarm

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "data"
LEGACY_RUN = Path(__file__).resolve().parent / "data" / "run_sidecar_0.2.0.json"
RUN_S = 2.0  # s of fig14-sine: the arm diagnosis needs MIN_SAMPLES (0.2 s); 2 s are half a sweep


def _reads_back(path: Path) -> rec.Sidecar:
    """The sidecar file parsed, and written again identically."""
    record, raw = rec.read_sidecar(path)
    assert record.to_json() == raw
    assert rec.Sidecar.from_json(record.to_json(), path) == record
    return record


# ------------------------------------------------------------------ writers


def test_run_columns_are_the_simulators() -> None:
    result = run_scenario("fig14-sine", SimConfig(), duration_s=0.05, backend="native")
    assert tuple(result.columns) == rec.RUN_COLUMNS
    assert set(rec.RUN_COLUMNS) <= set(rec.UNITS)


def test_run_sidecar_reads_back_equal(tmp_path: Path) -> None:
    result = run_scenario("fig14-sine", SimConfig(), duration_s=0.3, backend="native")
    table = timeseries.write_timeseries(result, tmp_path)
    record = _reads_back(table.with_suffix(".json"))
    assert record == timeseries.run_record(result)
    assert record.is_run and record.writer == rec.WRITER_RUN and record.schema == rec.SCHEMA
    assert record.columns is not None and tuple(record.columns) == rec.RUN_COLUMNS
    assert record.transmission is not None and record.transmission.name == "flexible-shaft"
    assert rec.shaft_params_of(record) == result.config.shaft
    ds = load_dataset(table)  # accepted as it is: every column declared, the unused listed
    assert ds.undeclared_columns == ()
    assert set(ds.unused_columns) == set(rec.RUN_COLUMNS) - set(rec.READ["arm"])


def test_parquet_carries_units_and_sidecar(tmp_path: Path) -> None:
    """A run Parquet file describes itself: each column's unit as field metadata, the sidecar as
    schema metadata (equal to the JSON sidecar beside it)."""
    import pyarrow.parquet as pq

    result = run_scenario("step-q3", SimConfig(), duration_s=0.05, backend="native")
    path = timeseries.write_timeseries(result, tmp_path, "parquet")
    schema = pq.read_schema(path)
    for name in result.columns:
        field = schema.field(name)
        assert field.metadata is not None
        assert field.metadata[b"unit"].decode() == rec.UNITS[name]
    assert schema.metadata is not None
    embedded = json.loads(schema.metadata[timeseries.PARQUET_SIDECAR_KEY.encode()])
    assert embedded == json.loads(path.with_suffix(".json").read_text())
    assert schema.field("q3").metadata[b"unit"] == b"rad"


def test_synthetic_sidecars_read_back_equal(tmp_path: Path) -> None:
    for setup in ("series_bench", "parallel_bench"):
        truth = synth.truth_model(
            setup, load_inertia_kgm2=0.01 if setup == "series_bench" else None
        )
        table, side = synth.write_synthetic(
            tmp_path / setup, truth, synth.Recording(duration_s=1.0, trajectory="steps")
        )
        record = _reads_back(side)
        assert record.writer == rec.WRITER_SYNTH and record.synthetic is not None
        assert load_dataset(table).undeclared_columns == ()
    arm_rec = arm_synth.ArmRecording(duration_s=0.5)
    table, side = arm_synth.write_arm_synthetic(tmp_path / "arm", arm_synth.truth_model(), arm_rec)
    record = _reads_back(side)
    assert record.setup == "arm" and record.gains is not None and not record.is_run
    assert record == rec.Sidecar.from_json(
        arm_synth.synthesize_arm(arm_synth.truth_model(), arm_rec)[1]
    )


# ------------------------------------------------------------------ legacy shapes


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.json")))
def test_example_sidecars_still_load(name: str) -> None:
    record = _reads_back(EXAMPLES / name)
    assert record.schema is None and record.synthetic is not None
    ds = load_dataset(EXAMPLES / name)
    assert ds.record == record and ds.undeclared_columns == ()


def test_version_0_2_0_run_sidecar_still_loads(tmp_path: Path) -> None:
    """The 0.2.0 run sidecar: no schema, nulls for defaults, the transmission as a table."""
    record, raw = rec.read_sidecar(LEGACY_RUN)
    assert raw["timestep_s"] is None and "schema" not in raw
    assert record.is_run and record.timestep_s is None and record.integrator is None
    assert record.transmission is not None and record.transmission.params["k_pos"] > 0.0
    assert set(record.declared_columns()) >= set(rec.RUN_COLUMNS)
    # its effects' own keys for the laws (all 0 there: no law on), and with values set
    assert rec.effects_of(record, LEGACY_RUN) == Effects()
    raw["effects"].update(q3_friction_nm=0.4, backlash_width_rad=0.02, backlash_center_rad=0.0)
    old = rec.Sidecar.from_json(raw, LEGACY_RUN)
    assert rec.effects_of(old, LEGACY_RUN) == Effects(
        laws=(
            ("coulomb_friction", (("f_c_nm", 0.4),)),
            ("backlash", (("width_rad", 0.02), ("center_rad", 0.0))),
        )
    )
    raw["effects"]["q3_friction_nm"] = -1.0  # a value the law refuses: named, with the file
    with pytest.raises(SidecarError, match=r"coulomb_friction\.f_c_nm must be within"):
        rec.effects_of(rec.Sidecar.from_json(raw, LEGACY_RUN), LEGACY_RUN)
    sh = rec.shaft_params_of(record, LEGACY_RUN)  # fields added since: their defaults
    assert sh is not None and sh.k_pos == raw["shaft_params"]["k_pos"]
    assert list(sh.conduit_tau) == raw["shaft_params"]["conduit_tau"]
    # and the plain-name transmission of the measured-data sidecars
    legacy = dict(raw, transmission="flexible-shaft")
    assert rec.Sidecar.from_json(legacy).transmission == rec.TransmissionRef("flexible-shaft")


# ------------------------------------------------------------------ named errors


@pytest.mark.parametrize(
    ("change", "err", "key"),
    [
        ({"operator": "me"}, rec.SidecarKeyError, "'operator'"),
        ({"gains": {"wn": [1, 2, 3]}}, rec.SidecarKeyError, "'gains.wn'"),
        ({"shaft": {"diameter_mm": 9.0, "length": 450.0}}, rec.SidecarKeyError, "'shaft.length'"),
        ({"transmission": {"name": "rtca", "gain": 1}}, rec.SidecarKeyError, "'transmission.gain'"),
        ({"effects": {"spring": True}}, rec.SidecarKeyError, "'effects.spring'"),
        ({"payload_kg": "0.5"}, rec.SidecarTypeError, "'payload_kg'"),
        ({"interrupted": 0}, rec.SidecarTypeError, "'interrupted'"),
        ({"gains": {"speed_ff": 1}}, rec.SidecarTypeError, "'gains.speed_ff'"),
        ({"gains": {"zeta": "1"}}, rec.SidecarTypeError, "'gains.zeta'"),
        # an object where a number belongs (only effects.laws is a nested entry)
        ({"gains": {"zeta": {"a": 1}}}, rec.SidecarTypeError, "'gains.zeta'"),
        (
            {"effects": {"backlash_width_rad": {"w": 1}}},
            rec.SidecarTypeError,
            "'effects.backlash_width_rad'",
        ),
        ({"shaft_params": {"k_pos": None}}, rec.SidecarTypeError, "'shaft_params.k_pos'"),
        ({"transmission": {"name": 3}}, rec.SidecarTypeError, "'transmission.name'"),
        ({"extra_columns": "tau"}, rec.SidecarTypeError, "'extra_columns'"),
        ({"columns": {"t": "ms"}}, SidecarError, "'columns.t'"),
        ({"shaft": {"diameter_mm": 12.0, "length_mm": 450.0}}, SidecarError, "shaft.diameter_mm"),
    ],
)
def test_bad_sidecar_is_a_named_error(
    tmp_path: Path, change: dict[str, object], err: type[Exception], key: str
) -> None:
    """Unknown keys and wrong types name the file and the key (nested keys with their path)."""
    result = run_scenario("fig14-sine", SimConfig(), duration_s=0.3, backend="native")
    table = timeseries.write_timeseries(result, tmp_path)
    side = table.with_suffix(".json")
    raw = json.loads(side.read_text())
    for k, v in change.items():
        raw[k] = dict(raw[k], **v) if isinstance(v, dict) and isinstance(raw.get(k), dict) else v
    side.write_text(json.dumps(raw))
    with pytest.raises(err) as info:
        load_dataset(table)
    assert str(side) in str(info.value) and key in str(info.value)


# ------------------------------------------------------------------ run -> diagnose


@pytest.mark.parametrize("transmission", transmissions.names())
def test_run_record_is_diagnosed_as_it_is(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, transmission: str
) -> None:
    """``fsarm run`` then ``fsarm diagnose`` on its record, unchanged: exit 0, nothing named,
    the columns the diagnosis does not read listed; the final model keeps the transmission."""
    out, res, model = tmp_path / "run", tmp_path / "f.json", tmp_path / "model.json"
    args = ["run", "fig14-sine", "--out", str(out), "--duration", str(RUN_S)]
    assert run_fsarm(monkeypatch, *args, "--transmission", transmission) == 0
    table = out / "fig14-sine.csv"
    code = run_fsarm(monkeypatch, "diagnose", str(table), "--json", str(res), "--model", str(model))
    assert code == 0
    d = json.loads(res.read_text())
    assert d["named_effects"] == [] and d["nothing_missing"] is True
    assert d["transmission"] == transmission
    assert set(d["unused_columns"]) == set(rec.RUN_COLUMNS) - set(rec.READ["arm"])
    assert d["undeclared_columns"] == []
    cfg = MF.load_arm_config(model)  # the final model: the run's transmission and exact shaft
    assert cfg.transmission == transmission
    stated = load_dataset(table).shaft
    assert cfg.controller_shaft == stated and cfg.shaft.slip_k == stated.slip_k
    if transmission == "flexible-shaft":  # the 0.2.0 sidecar of the same run reads the same
        (out / "fig14-sine.json").write_text(LEGACY_RUN.read_text())
        run = arm.arm_run(load_dataset(table))
        assert run.flexible_shaft and run.gains == SimConfig().gains and run.timestep_s is None
