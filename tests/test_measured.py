"""Measured datasets: the format of specs/measured-data.md and its named errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.records import measured


def _series_cols(n: int = 500) -> dict[str, np.ndarray]:
    t = np.arange(n) * 1e-3
    th = 0.2 * np.sin(2 * np.pi * t)
    return {
        "t": t,
        "theta_m": th,
        "theta_s": np.zeros(n),
        "phi_b": np.full(n, 0.5),
        "tau_s": 15.0 * th,
    }


SIDE = {
    "setup": "series_bench",
    "shaft": {"diameter_mm": 9.0, "length_mm": 450.0},
    "load": {"type": "blocked"},
    "notes": "test",
}


def _write_csv(tmp: Path, cols: dict[str, np.ndarray], side: dict, name: str = "d") -> Path:
    import pandas as pd

    p = tmp / f"{name}.csv"
    pd.DataFrame(cols).to_csv(p, index=False)
    (tmp / f"{name}.json").write_text(json.dumps(side))
    return p


def test_roundtrip_csv_and_parquet(tmp_path: Path) -> None:
    cols = _series_cols()
    for suffix in (".csv", ".parquet"):
        table, side = measured.write_dataset(tmp_path / f"x{suffix}", cols, SIDE)
        assert side.name == "x.json"
        for how in (table, tmp_path / "x.json", tmp_path / "x"):
            if how == tmp_path / "x" and suffix == ".parquet":
                continue  # the CSV of the first round is found first
            ds = measured.load_dataset(how)
            assert ds.setup == "series_bench" and ds.n == 500
            assert ds.dt == pytest.approx(1e-3)
            assert np.allclose(ds.columns["tau_s"], cols["tau_s"])
            assert ds.shaft.diameter_mm == 9.0 and ds.load_inertia_kgm2 is None
            assert ds.input_column == "theta_m" and ds.output_column == "tau_s"


def test_parallel_and_inertia_sidecars(tmp_path: Path) -> None:
    n = 300
    t = np.arange(n) * 1e-3
    side = {"setup": "parallel_bench", "shaft": {"name": "MF09-450"}}
    p = _write_csv(tmp_path, {"t": t, "phi_b": 0.1 * t, "m_b": 0.4 * t}, side)
    ds = measured.load_dataset(p)
    assert ds.setup == "parallel_bench" and ds.shaft.length_mm == 450.0
    side2 = dict(SIDE, load={"type": "inertia", "inertia_kgm2": 0.02})
    ds2 = measured.load_dataset(_write_csv(tmp_path, _series_cols(), side2, "i"))
    assert ds2.load_inertia_kgm2 == 0.02


@pytest.mark.parametrize(
    "mutate,err,words",
    [
        (lambda c: c.pop("tau_s"), measured.MissingColumnError, ["'tau_s'", "required"]),
        (
            lambda c: c["tau_s"].__setitem__(123, np.nan),
            measured.NonFiniteError,
            ["'tau_s'", "row 123"],
        ),
        (
            lambda c: c["theta_m"].__setitem__(7, np.inf),
            measured.NonFiniteError,
            ["'theta_m'", "row 7"],
        ),
        (
            lambda c: c["t"].__setitem__(50, c["t"][48]),
            measured.TimeAxisError,
            ["strictly increasing", "row 50"],
        ),
        (
            lambda c: c["t"].__setitem__(slice(100, None), c["t"][100:] + 5e-4),
            measured.TimeAxisError,
            ["evenly sampled", "row 100"],
        ),
    ],
)
def test_named_errors_say_file_column_row(
    tmp_path: Path, mutate: object, err: type[Exception], words: list[str]
) -> None:
    cols = _series_cols()
    mutate(cols)  # type: ignore[operator]
    p = _write_csv(tmp_path, cols, SIDE)
    with pytest.raises(err) as info:
        measured.load_dataset(p)
    msg = str(info.value)
    assert "d.csv" in msg
    for w in words:
        assert w in msg
    assert isinstance(info.value, measured.MeasuredDataError)


def test_extra_columns_allowed_when_declared(tmp_path: Path) -> None:
    cols = _series_cols()
    cols["temperature"] = np.zeros(500)
    ds = measured.load_dataset(
        _write_csv(tmp_path, cols, dict(SIDE, extra_columns=["temperature"]))
    )
    assert ds.extra_columns == ("temperature",)
    assert ds.unused_columns == ("temperature",) and ds.undeclared_columns == ()


def test_undeclared_columns_are_listed_not_refused(tmp_path: Path) -> None:
    """Reading lists a column the setup does not define (a misspelt name shows); writing
    refuses it (the project's writers declare every column)."""
    cols = _series_cols()
    cols["extra"] = cols["t"] * 0
    ds = measured.load_dataset(_write_csv(tmp_path, cols, SIDE))
    assert ds.undeclared_columns == ("extra",) and ds.unused_columns == ("extra",)
    assert any("'extra'" in line and "extra_columns" in line for line in ds.column_notes())
    with pytest.raises(measured.ExtraColumnError, match="'extra'"):
        measured.write_dataset(tmp_path / "w.csv", cols, SIDE)


def test_wrong_and_unknown_setup(tmp_path: Path) -> None:
    p = _write_csv(tmp_path, _series_cols(), dict(SIDE, setup="parallel_bench"))
    with pytest.raises(measured.SetupError, match="look like a 'series_bench'"):
        measured.load_dataset(p)
    p = _write_csv(tmp_path, _series_cols(), dict(SIDE, setup="lathe"))
    with pytest.raises(measured.SetupError, match="one of series_bench"):
        measured.load_dataset(p)
    p = _write_csv(tmp_path, _series_cols(), SIDE)
    with pytest.raises(measured.SetupError, match="expected a 'parallel_bench'"):
        measured.load_dataset(p, expect_setup="parallel_bench")


def test_too_few_samples_and_non_numeric(tmp_path: Path) -> None:
    with pytest.raises(measured.TooFewSamplesError, match=f"at least {measured.MIN_SAMPLES}"):
        measured.load_dataset(_write_csv(tmp_path, _series_cols(50), SIDE))
    p = _write_csv(tmp_path, _series_cols(), SIDE)
    lines = p.read_text().splitlines()
    parts = lines[11].split(",")
    parts[4] = "abc"
    lines[11] = ",".join(parts)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(measured.NonNumericError, match=r"column 'tau_s', row 10 .*CSV line 12"):
        measured.load_dataset(p)


@pytest.mark.parametrize(
    "shaft,words",
    [
        ({"name": "MF99-999"}, "not in"),
        ({"diameter_mm": 30.0, "length_mm": 450.0}, "outside the validity range"),
        ({"diameter_mm": 9.0}, "needs 'diameter_mm' and 'length_mm'"),
    ],
)
def test_unknown_shaft(tmp_path: Path, shaft: object, words: str) -> None:
    with pytest.raises(measured.UnknownShaftError, match=words):
        measured.load_dataset(_write_csv(tmp_path, _series_cols(), dict(SIDE, shaft=shaft)))


def test_shaft_of_the_wrong_type_is_a_sidecar_type_error(tmp_path: Path) -> None:
    with pytest.raises(measured.SidecarError, match="'shaft' must be an object"):
        measured.load_dataset(_write_csv(tmp_path, _series_cols(), dict(SIDE, shaft="nine")))


def test_shaft_extrapolate_and_coefficient_file(tmp_path: Path) -> None:
    side = dict(SIDE, shaft={"diameter_mm": 13.5, "length_mm": 450.0, "extrapolate": True})
    assert (
        measured.load_dataset(_write_csv(tmp_path, _series_cols(), side)).shaft.diameter_mm == 13.5
    )
    side = dict(
        SIDE, shaft={"diameter_mm": 9.0, "length_mm": 450.0, "coefficient_file": "none.toml"}
    )
    with pytest.raises(measured.UnknownShaftError, match="coefficient file"):
        measured.load_dataset(_write_csv(tmp_path, _series_cols(), side))


def test_sidecar_problems(tmp_path: Path) -> None:
    p = _write_csv(tmp_path, _series_cols(), SIDE)
    (tmp_path / "d.json").unlink()
    with pytest.raises(measured.SidecarError, match="not found"):
        measured.load_dataset(p)
    (tmp_path / "d.json").write_text("{not json")
    with pytest.raises(measured.SidecarError, match="not a readable JSON"):
        measured.load_dataset(p)
    (tmp_path / "d.json").write_text(json.dumps(dict(SIDE, load={"type": "inertia"})))
    with pytest.raises(measured.SidecarError, match="inertia_kgm2"):
        measured.load_dataset(p)
    with pytest.raises(measured.MeasuredDataError, match="no table"):
        measured.load_dataset(tmp_path / "missing")


def test_arm_columns_are_defined(tmp_path: Path) -> None:
    n = 300
    cols = {c: np.zeros(n) for c in measured.REQUIRED["arm"]}
    cols["t"] = np.arange(n) * 1e-3
    cols["tau_m"] = np.zeros(n)
    side = {"setup": "arm", "shaft": {"diameter_mm": 9.0, "length_mm": 450.0}, "payload_kg": 0.0}
    ds = measured.load_dataset(_write_csv(tmp_path, cols, side))
    assert ds.setup == "arm" and "tau_m" in ds.columns


def test_a_repeated_column_name_is_refused_from_the_header(tmp_path: Path) -> None:
    """Issue 33: pandas renames a repeated header (tau_s, tau_s.1) and one was used silently."""
    import shutil

    from fsarm_sim.errors import FsarmError

    data = Path(__file__).resolve().parents[1] / "examples" / "data"
    lines = (data / "series_null.csv").read_text().splitlines()
    head = lines[0].split(",")
    i = head.index("tau_s")
    rows = [",".join([*r.split(","), str(2 * float(r.split(",")[i]))]) for r in lines[1:]]
    (tmp_path / "d.csv").write_text(",".join([*head, " tau_s"]) + "\n" + "\n".join(rows) + "\n")
    shutil.copy(data / "series_null.json", tmp_path / "d.json")
    with pytest.raises(FsarmError, match=r"the column name 'tau_s' is given twice \(columns"):
        measured.load_dataset(tmp_path / "d.csv")
    (tmp_path / "d.csv").write_text("\n".join(lines) + "\n")  # the same without it: fine
    assert measured.load_dataset(tmp_path / "d.csv") is not None


def test_a_deeply_nested_sidecar_is_a_named_error(tmp_path: Path) -> None:
    from fsarm_sim.records.sidecar import SidecarError, read_sidecar

    f = tmp_path / "s.json"
    f.write_text('{"setup": "series_bench", "x": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(SidecarError, match="nest deeper than 32 levels"):
        read_sidecar(f)
