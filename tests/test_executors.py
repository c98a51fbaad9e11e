"""Executors: inline, a local process pool, threads and a Dask cluster give the same results."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from fsarm_sim.executors import START_METHOD_ENV, ExecutorError, Outcome, run_tasks, start_method
from fsarm_sim.records.store import ResultStore
from fsarm_sim.studies import sweep as sw


def _tiny_tasks() -> list[dict[str, Any]]:
    spec = sw.build_spec(
        grid=["diameter_mm=4,13", "payload_kg=0,5"],
        fixed=["duration_s=0.5"],
        outputs=["tracking", "relief"],
    )
    return [{"point": p, "catalogue_toml": None} for p in sw.points(spec)]


def _by_point(outcomes: list[Outcome]) -> dict[tuple[float, float], dict[str, Any]]:
    out = {}
    for o in outcomes:
        assert o.error is None, o.error
        assert o.result is not None
        out[(o.task["point"]["diameter_mm"], o.task["point"]["payload_kg"])] = o.result
    return out


@pytest.fixture(scope="module")
def inline() -> dict[tuple[float, float], dict[str, Any]]:
    return _by_point(run_tasks(sw.evaluate_point, _tiny_tasks(), workers=1))


def test_local_pool_matches_inline(inline: dict[tuple[float, float], dict[str, Any]]) -> None:
    seen: list[int] = []
    outs = run_tasks(
        sw.evaluate_point, _tiny_tasks(), workers=2, on_done=lambda o: seen.append(o.index)
    )
    assert sorted(seen) == [0, 1, 2, 3]
    assert _by_point(outs) == inline  # bit-identical: each point is deterministic
    # physics sanity: the payload loads the motor
    assert inline[(13.0, 5.0)]["peak_motor_torque_nm"] > inline[(13.0, 0.0)]["peak_motor_torque_nm"]


@pytest.mark.parametrize("start", ["fork", "spawn"])
def test_pool_start_methods_match_inline(
    inline: dict[tuple[float, float], dict[str, Any]],
    start: str,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Forked and spawned workers give the same results; ``prepare`` runs here only before a
    fork, ``on_start`` once, before the first result."""
    monkeypatch.setenv(START_METHOD_ENV, "" if start == "fork" else "spawn")
    forks = start_method() == "fork"
    if start == "fork" and not forks:
        pytest.skip("this process runs other threads (or no fork here): the pool spawns")
    events: list[str] = []
    outs = run_tasks(
        sw.evaluate_point,
        _tiny_tasks(),
        workers=2,
        prepare=lambda: events.append("prepare"),
        on_start=lambda: events.append("start"),
        on_done=lambda o: events.append("done"),
    )
    assert _by_point(outs) == inline
    assert events[: 2 if forks else 1] == (["prepare", "start"] if forks else ["start"])
    assert events.count("start") == 1 and events.count("done") == 4


def test_start_method_spawns_beside_other_threads(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fork copies only the calling thread: with another thread running (a progress bar
    holding a lock, say), the pool spawns; ``FSARM_START_METHOD=spawn`` always spawns."""
    monkeypatch.delenv(START_METHOD_ENV, raising=False)
    release = threading.Event()
    other = threading.Thread(target=release.wait)
    other.start()
    try:
        assert start_method() == "spawn"
    finally:
        release.set()
        other.join()
    monkeypatch.setenv(START_METHOD_ENV, "spawn")
    assert start_method() == "spawn"
    monkeypatch.delenv(START_METHOD_ENV)
    if threading.active_count() == 1 and sys.platform == "linux":
        assert start_method() == "fork"


def test_threads_match_inline(inline: dict[tuple[float, float], dict[str, Any]]) -> None:
    """Tasks in parallel threads of one process (no lock): the same, bit for bit."""
    seen: list[int] = []
    outs = run_tasks(
        sw.evaluate_point,
        _tiny_tasks() * 2,  # 8 tasks on 3 threads: several runs step at the same time
        executor="threads",
        workers=3,
        on_done=lambda o: seen.append(o.index),
    )
    assert sorted(seen) == list(range(8))
    for o in outs:
        assert o.error is None, o.error
        assert o.result == inline[(o.task["point"]["diameter_mm"], o.task["point"]["payload_kg"])]


def test_dask_local_cluster_matches_inline(
    inline: dict[tuple[float, float], dict[str, Any]], tmp_path: Path
) -> None:
    outs = run_tasks(sw.evaluate_point, _tiny_tasks(), executor="dask", workers=2, processes=False)
    assert _by_point(outs) == inline
    spec = sw.build_spec(fixed=["duration_s=0.5"], grid=["payload_kg=0,5"], outputs=["tracking"])
    rep = sw.run_sweep(spec, tmp_path / "d.sqlite", executor="dask", workers=2, processes=False)
    assert rep.computed == 2 and rep.failed == 0
    with ResultStore(tmp_path / "d.sqlite") as st:
        assert st.count("ok") == 2


def test_task_errors_are_captured_not_raised() -> None:
    (task,) = _tiny_tasks()[:1]
    bad = {**task, "point": {**task["point"], "scenario": "moonwalk"}}
    (o,) = run_tasks(sw.evaluate_point, [bad], workers=1)
    assert o.result is None
    assert o.error is not None and o.error.startswith("ScenarioNotFoundError")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"executor": "spark"}, "executor must be"),
        ({"workers": 0}, ">= 1"),
        ({"workers": 1.5}, "whole number"),
        ({"scheduler": "tcp://127.0.0.1:1"}, "only makes sense"),
    ],
)
def test_bad_executor_settings(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(ExecutorError, match=match):
        run_tasks(sw.evaluate_point, _tiny_tasks(), **kwargs)


def _children(pid: int) -> list[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.append(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads the process table from /proc")
@pytest.mark.parametrize("start", ["fork", "spawn"])
def test_pool_workers_end_when_the_sweep_is_killed(tmp_path: Path, start: str) -> None:
    """kill -9 of a sweep must not leave its workers computing on as orphans (forked workers,
    the default where safe, and spawned ones)."""
    cmd = [
        sys.executable,
        "-c",
        "from fsarm_sim.cli import main; main()",
        "sweep",
        "--store",
        str(tmp_path / "r.sqlite"),
        "--grid",
        "payload_kg=0:15:8",
        "--set",
        "duration_s=60",
        "--outputs",
        "tracking",
        "--workers",
        "2",
        "--executor",
        "local",  # (tracking points default to threads: sweep.pick_executor)
        "--no-progress",
    ]
    env = {**os.environ, "MUJOCO_GL": "disable", START_METHOD_ENV: start}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 60.0
    workers: list[int] = []
    while len(workers) < 2 and time.monotonic() < deadline:
        time.sleep(0.2)
        # the pool's workers are the sweep's children (besides a resource tracker, and a build
        # of the native library the sweep may have started); spawned ones say so
        workers = [
            c
            for c in _children(proc.pid)
            if not any(s in _cmdline(c) for s in ("resource_tracker", "native_lib"))
            and (start == "fork" or "spawn_main" in _cmdline(c))
        ]
    assert len(workers) == 2, "the pool did not start"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 10.0
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = [w for w in workers if _alive(w)]
    for w in left:
        os.kill(w, signal.SIGKILL)
    assert not left, f"orphaned workers still running: {left}"


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""
