"""Results store: one row per point, keyed by the hash of its exact inputs, version recorded."""

from __future__ import annotations

import math
import sqlite3
from pathlib import Path

import pytest

import fsarm_sim
from fsarm_sim.records.store import ResultStore, StoreError, canonical_json, point_key

POINT = {
    "diameter_mm": 9.0,
    "length_mm": 450.0,
    "scenario": "fig14-sine",
    "bench": {"chirp_s": 4.0},
}


def test_insert_skip_duplicate_and_version(tmp_path: Path) -> None:
    path = tmp_path / "r.sqlite"
    with ResultStore(path) as st:
        assert st.put(POINT, {"q3_rmse_deg": 0.13}, sweep="s", wall_s=1.5) is True
        # same inputs, keys in another order: same point, not stored twice
        again = dict(reversed(list(POINT.items())))
        assert st.put(again, {"q3_rmse_deg": 99.0}, sweep="s") is False
        assert st.count() == 1
        assert POINT in st
        (row,) = list(st.rows())
    assert row.inputs == POINT
    assert row.outputs == {"q3_rmse_deg": 0.13}  # the first result is kept
    assert row.version == fsarm_sim.__version__
    assert row.status == "ok" and row.wall_s == 1.5
    assert row.key == point_key(POINT)
    # persisted, WAL journal, one row
    with ResultStore(path) as st:
        assert st.count() == 1
    db = sqlite3.connect(path)
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert db.execute("SELECT inputs_json FROM points").fetchone()[0] == canonical_json(POINT)
    db.close()


def test_canonical_json_is_order_free_and_rejects_nan() -> None:
    a = {"b": 1.0, "a": {"y": 2, "x": [1, 2]}}
    b = {"a": {"x": [1, 2], "y": 2}, "b": 1.0}
    assert canonical_json(a) == canonical_json(b) == '{"a":{"x":[1,2],"y":2},"b":1.0}'
    assert point_key(a) == point_key(b)
    assert point_key(a) != point_key({**a, "b": 1.5})
    with pytest.raises(StoreError, match="finite"):
        canonical_json({"d": math.nan})
    with pytest.raises(StoreError, match="finite"):
        point_key({"d": [1.0, math.inf]})


def test_errors_are_stored_and_can_be_retried(tmp_path: Path) -> None:
    with ResultStore(tmp_path / "r.sqlite") as st:
        st.put({"i": 1}, None, error="SimulationWarningError: unstable")
        st.put({"i": 2}, {"x": math.nan})  # NaN output -> null
        assert st.count() == 2 and st.count("error") == 1
        assert next(st.rows(status="ok")).outputs == {"x": None}
        assert st.delete_errors() == 1
        assert st.count() == 1
        assert {"i": 1} not in st
        frame = st.frame()
        assert list(frame["i"]) == [2]


def test_meta_and_bad_files(tmp_path: Path) -> None:
    with ResultStore(tmp_path / "r.sqlite") as st:
        st.set_meta("spec:s", "{}")
        assert st.meta("spec:s") == "{}"
        assert st.meta("nothing") is None
    junk = tmp_path / "junk.sqlite"
    junk.write_bytes(b"this is not a database" * 100)
    with pytest.raises(StoreError, match="not a usable"):
        ResultStore(junk)
    with pytest.raises(StoreError, match="not a file"):
        ResultStore(tmp_path)
