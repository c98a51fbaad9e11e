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


def _filling_store(monkeypatch: pytest.MonkeyPatch, spare_pages: int) -> None:
    """Every ResultStore opened from now on may grow by ``spare_pages`` pages only: SQLite's
    own "database or disk is full" (SQLITE_FULL), as on a full disk."""
    opened = ResultStore.__init__

    def init(self: ResultStore, path: str | Path) -> None:
        opened(self, path)
        pages = self._db.execute("PRAGMA page_count").fetchone()[0]
        self._db.execute(f"PRAGMA max_page_count = {pages + spare_pages}")

    monkeypatch.setattr(ResultStore, "__init__", init)


def test_a_full_disk_is_a_named_error_that_keeps_the_stored_points(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Issue 33: sqlite3.OperationalError became a StoreError that says the points stored before
    are kept; the same sweep then resumes where it stopped."""
    from fsarm_sim.studies import sweep as sw

    spec = sw.build_spec(grid=["diameter_mm=4,6,9,13", "length_mm=235,535"], outputs=["relief"])
    store = tmp_path / "r.sqlite"
    with monkeypatch.context() as m:
        _filling_store(m, 1)
        with pytest.raises(StoreError, match="database or disk is full") as info:
            sw.run_sweep(spec, store, workers=1)
    with ResultStore(store) as st:
        kept = st.count()
    assert 0 < kept < 8 and f"the {kept} point(s) stored before are kept" in str(info.value)
    assert "rerun the same command to resume" in str(info.value)
    again = sw.run_sweep(spec, store, workers=1)  # space again: the rest, nothing twice
    assert (again.already, again.computed, again.failed) == (kept, 8 - kept, 0)


def test_a_full_disk_in_the_sweep_command_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from conftest import run_fsarm

    _filling_store(monkeypatch, 1)
    args = ["sweep", "--store", str(tmp_path / "r.sqlite"), "--grid", "diameter_mm=4:13:10"]
    code = run_fsarm(monkeypatch, *args, "--outputs", "relief", "--workers", "1", "--no-progress")
    err = capsys.readouterr().err
    (line,) = err.strip().splitlines()
    assert code == 2 and line.startswith("error: results store") and "are kept" in line


def test_store_paths_the_os_refuses_are_named(tmp_path: Path) -> None:
    (tmp_path / "loop.sqlite").symlink_to("loop.sqlite")
    for path, words in (
        (tmp_path / "loop.sqlite", "loop of symbolic links"),
        (tmp_path / ("a" * 300 + ".sqlite"), "longer than the file system allows"),
    ):
        with pytest.raises(StoreError, match=words):
            ResultStore(path)
