"""The speed benchmark's sweep part: forked process workers cost no interpreter start."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from fsarm_sim.studies import speed

_PROBE = """
import json
from fsarm_sim.executors import start_method
from fsarm_sim.studies import speed
method = start_method()
n, rtf, cpu = speed._sweep(reps=1, duration_s=0.2, max_workers=2)
print(json.dumps({"method": method, "n": n, "rtf": rtf, "cpu": cpu}))
"""


def _sweep(start: str) -> dict[str, object]:
    got = subprocess.run(  # a fresh process: no thread of another test keeps the pool from forking
        [sys.executable, "-c", _PROBE],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MUJOCO_GL": "disable", "FSARM_START_METHOD": start},
        check=True,
    )
    out: dict[str, object] = json.loads(got.stdout.strip().splitlines()[-1])
    return out


def test_forked_sweep_workers_cost_little_cpu_beyond_the_points() -> None:
    """Two forked workers take about the CPU of one; spawned ones pay ~0.5 s each to start
    (interpreter, imports, kernel load) - the difference the fork makes."""
    forked = _sweep("")
    if sys.platform.startswith("linux"):
        assert forked["method"] == "fork"
    assert forked["n"] == 12
    rtf, cpu = forked["rtf"], forked["cpu"]
    assert isinstance(rtf, dict) and isinstance(cpu, dict)
    assert set(rtf) == set(cpu) == {"1", "2"}
    assert all(v[0] > 0.0 for v in rtf.values())
    if forked["method"] == "fork":
        assert cpu["1"][0] > 0.0 and cpu["2"][0] < cpu["1"][0] + 0.4, cpu
    spawned = _sweep("spawn")
    assert spawned["method"] == "spawn"
    cpu_s = spawned["cpu"]
    assert isinstance(cpu_s, dict)
    if forked["method"] == "fork":
        assert cpu_s["2"][0] > cpu["2"][0] + 0.3, (cpu, cpu_s)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"reps": 0}, "reps (--reps) must be a whole number >= 1"),
        ({"reps": True}, "reps (--reps) must be a whole number"),
        ({"reps": 10**6}, "<= 1000"),
        ({"max_workers": 0}, "max_workers (--max-workers) must be a whole number >= 1"),
        ({"max_workers": 10**6}, "<= 256"),
        ({"batch_runs": 0}, "batch_runs"),
        ({"rtf_duration_s": 1e9}, "rtf_duration_s must be > 0 and <= 3600 s"),
        ({"sweep_reps": -1}, "sweep_reps"),
    ],
)
def test_sizes_that_scale_the_benchmark_are_capped(kwargs: dict[str, object], words: str) -> None:
    """Issue 33: checked before any timing (``max_workers=0`` used to mean every core)."""
    from fsarm_sim.errors import FsarmError

    with pytest.raises(FsarmError) as info:
        speed.measure_speed(**kwargs)  # type: ignore[arg-type]
    assert words in str(info.value)


@pytest.mark.parametrize(
    "args", [["--reps", "0"], ["--reps", "0", "--quick"], ["--max-workers", "0", "--quick"]]
)
def test_bench_speed_refuses_zero_at_once(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], args: list[str]
) -> None:
    from conftest import run_fsarm

    assert run_fsarm(monkeypatch, "bench-speed", *args) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"error: {args[0]} must be a whole number >= 1")
