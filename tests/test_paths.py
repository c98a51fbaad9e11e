"""The one checked path helper (issue 33): loops of symbolic links, names too long, a vanished
working directory, no permission and deep nesting are named errors - from the helper, from the
readers that use it, and from the ``fsarm`` commands (one line ``error: ...``, exit code 2)."""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fsarm_sim.errors import CoefficientFileError, FilePathError, FsarmError
from fsarm_sim.paths import (
    MAX_NESTING,
    bounded_json,
    bounded_toml,
    checked_path,
    named_os_errors,
    nesting_depth,
    os_problem,
)

from conftest import run_fsarm

DATA = Path(__file__).resolve().parents[1] / "examples" / "data"
LONG = "a" * 300  # longer than any file system's 255-byte names


def _loop(tmp: Path, name: str = "loop") -> Path:
    link = tmp / name
    link.symlink_to(name)  # points at itself
    return link


def test_checked_path_names_a_loop_a_long_name_and_a_nul(tmp_path: Path) -> None:
    loop = _loop(tmp_path)
    for path, words in (
        (loop, "loop of symbolic links"),
        (loop / "inside.json", "loop of symbolic links"),
        (tmp_path / LONG, "longer than the file system allows"),
        (tmp_path / LONG / "x.csv", "longer than the file system allows"),
        (f"{tmp_path}/a\x00b", "NUL character"),
    ):
        with pytest.raises(FilePathError, match=words) as info:
            checked_path(path, "--json")
        assert str(info.value).startswith("--json ")
    # what merely does not exist (yet) is fine: the caller decides
    assert checked_path(tmp_path / "new" / "x.json", "--json") == tmp_path / "new" / "x.json"
    assert checked_path(tmp_path / "a" / ".." / "b", "--out") == tmp_path / "b"


def test_checked_path_raises_the_callers_error(tmp_path: Path) -> None:
    with pytest.raises(CoefficientFileError, match="loop"):
        checked_path(_loop(tmp_path), "coefficient file", CoefficientFileError)


def test_a_vanished_working_directory_is_named(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    def gone() -> str:
        raise FileNotFoundError(errno.ENOENT, "No such file or directory")

    monkeypatch.setattr(os, "getcwd", gone)
    with pytest.raises(FilePathError, match="working directory no longer exists"):
        checked_path("runs", "--out")
    assert checked_path(tmp_path, "--out") == tmp_path  # absolute paths still work


def test_named_os_errors_words_the_operating_systems_errors(tmp_path: Path) -> None:
    for code, words in (
        (errno.ENOSPC, "no space left on the device"),
        (errno.EACCES, "permission denied"),
        (errno.EROFS, "the file system is read-only"),
        (errno.ENAMETOOLONG, "the name is longer than the file system allows"),
    ):
        with (
            pytest.raises(FilePathError, match=f"^the store {tmp_path}: {words}"),
            named_os_errors("the store", tmp_path),
        ):
            raise OSError(code, os.strerror(code))
    with pytest.raises(ValueError, match="plain"), named_os_errors("the store", tmp_path):
        raise ValueError("plain")  # not an OS error: left alone
    assert os_problem(RuntimeError("Symlink loop from '/x'")) == "it is a loop of symbolic links"


def test_nesting_is_bounded_before_and_after_parsing() -> None:
    assert nesting_depth({"a": [1, [2, {"b": 3}]]}) == 4 and nesting_depth(3) == 0
    ok = "[" * MAX_NESTING + "]" * MAX_NESTING
    assert nesting_depth(bounded_json(ok, "f.json", FsarmError)) == MAX_NESTING
    for depth in (MAX_NESTING + 1, 100_000):  # parsed and refused / beyond Python's recursion
        deep = "[" * depth + "]" * depth
        with pytest.raises(FsarmError, match=f"deeper than {MAX_NESTING} levels"):
            bounded_json(deep, "f.json", FsarmError)
        with pytest.raises(FsarmError, match=r"f\.toml: arrays/tables nest deeper"):
            bounded_toml(f"x = {deep}\n", "f.toml", FsarmError)


# ------------------------------------------------------------------------ through the readers


def _deep_toml(tmp: Path) -> Path:
    f = tmp / "deep.toml"
    f.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    return f


def _setup(tmp: Path) -> None:
    _loop(tmp, "loop")
    _loop(tmp, "lt.csv")  # a table that is a loop
    shutil.copy(DATA / "series_null.csv", tmp / "m.csv")
    _loop(tmp, "m.json")  # a sidecar that is a loop
    shutil.copy(DATA / "series_null.csv", tmp / "n.csv")
    (tmp / "n.json").write_text('{"setup": ' + "[" * 5000 + "]" * 5000 + "}")
    _deep_toml(tmp)


# (arguments with {t} = the case's folder, words the one error line must contain)
REFUSED = [
    (
        ["run", "fig14-sine", "--duration", "0.1", "--out", "{t}/loop"],
        "--out {t}/loop: it is a loop",
    ),
    (["run", "fig14-sine", "--duration", "0.1", "--out", "{t}/o", "--json", "{t}/loop"], "--json"),
    (["run", "fig14-sine", "--out", "{t}/o", "--shaft-file", "{t}/loop"], "loop of symbolic"),
    (["run", "fig14-sine", "--out", "{t}/o", "--rrd", "{t}/loop/x.rrd"], "--rrd"),
    (["shafts", "--shaft-file", "{t}/loop"], "coefficient file {t}/loop: it is a loop"),
    (["shafts", "--shaft-file", "{t}/deep.toml"], "nest deeper than"),
    (["sweep", "--spec", "{t}/loop", "--store", "{t}/s.db", "--dry-run"], "--spec {t}/loop"),
    (["sweep", "--grid", "diameter_mm=9", "--store", "{t}/loop", "--dry-run"], "--store"),
    (["sweep-report", "--store", "{t}/loop", "--out", "{t}/r"], "--store {t}/loop: it is"),
    (["diagnose", "{t}/lt.csv"], "dataset {t}/lt.csv: it is a loop"),
    (["diagnose", "{t}/m.csv"], "the sidecar of the dataset {t}/m.csv {t}/m.json: it is a loop"),
    (["diagnose", "{t}/n.csv"], "nest deeper than"),
    (["synth", "{t}/lt.csv"], "OUT {t}/lt.csv: it is a loop"),
    (["synth", "{t}/s.csv", "--input-file", "{t}/loop"], "--input-file {t}/loop: it is a loop"),
    (["synth", "{t}/s.csv", "--model", "{t}/loop"], "--model {t}/loop: it is a loop"),
    (["run", "fig14-sine", "--out", "{t}/o", "--json", f"{{t}}/{LONG}.json"], "longer than"),
    (["synth", f"{{t}}/{LONG}"], "longer than the file system allows"),
    (["sweep", "--grid", "diameter_mm=9", "--store", f"{{t}}/{LONG}", "--dry-run"], "longer"),
]


@pytest.mark.parametrize(("args", "words"), REFUSED, ids=[" ".join(c[0][:2]) for c in REFUSED])
def test_paths_the_os_refuses_are_one_named_line(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    args: list[str],
    words: str,
) -> None:
    _setup(tmp_path)
    code = run_fsarm(monkeypatch, *(a.replace("{t}", str(tmp_path)) for a in args))
    cap = capsys.readouterr()
    assert "Traceback" not in cap.out + cap.err
    lines = cap.err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), cap.err
    assert words.replace("{t}", str(tmp_path)) in lines[0]
    assert not (tmp_path / "o").exists()  # refused before the run


def test_commands_run_from_a_deleted_working_directory(tmp_path: Path) -> None:
    """A process whose working directory was deleted: relative paths are a named error,
    absolute ones still work."""
    gone = tmp_path / "gone"
    gone.mkdir()
    fsarm = Path(sys.executable).with_name("fsarm")  # the installed command, as a user runs it
    script = 'cd "$1" && rmdir "$1" && shift && exec "$@"'
    env = {**os.environ, "MUJOCO_GL": "disable"}
    for args, want in (
        (["run", "fig14-sine", "--duration", "0.05"], 2),  # --out runs: relative
        (["diagnose", "m.csv"], 2),
        (["run", "fig14-sine", "--duration", "0.05", "--out", str(tmp_path / "abs")], 0),
    ):
        gone.mkdir(exist_ok=True)
        done = subprocess.run(
            ["sh", "-c", script, "sh", str(gone), str(fsarm), *args],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == want, done.stderr
        assert "Traceback" not in done.stderr
        if want == 2:
            (line,) = done.stderr.strip().splitlines()
            assert line.startswith("error: the working directory no longer exists")
    assert (tmp_path / "abs" / "fig14-sine.csv").is_file()
