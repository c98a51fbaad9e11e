from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.studies import task_selection as ts

from conftest import run_fsarm

TASK = ts.Task(scenario="fig14-sine", duration_s=0.3)


def test_optimiser_matches_a_coarse_grid_and_resumes_from_the_store(tmp_path: Path) -> None:
    store = tmp_path / "s.sqlite"
    s = ts.select(TASK, store, "q3_rmse_deg", budget=32)
    assert s.best is not None and s.simulations == len(s.evaluated) <= 40
    g_best, n = ts.grid(
        TASK, tmp_path / "g.sqlite", "q3_rmse_deg", np.linspace(4, 13, 7), np.linspace(235, 535, 5)
    )
    assert g_best is not None and n == 35
    # continuous search is at least as good as the coarse grid
    assert s.best.outputs["q3_rmse_deg"] <= g_best.outputs["q3_rmse_deg"] * 1.001
    again = ts.select(TASK, store, "q3_rmse_deg", budget=32)
    assert again.simulations == 0 and again.best == s.best  # all read back from the store
    assert len(s.nearest_names) == 3


def test_constraints_exclude_and_pareto_front_is_non_dominated(tmp_path: Path) -> None:
    strict = ts.Task(scenario="fig14-sine", duration_s=0.3, rating_margin=1e6)
    s = ts.select(strict, tmp_path / "s.sqlite", budget=16)
    assert s.best is None and all("rating margin" in e.why for e in s.evaluated)
    moving = ts.Task(scenario="p2p-payload", bandwidth_floor_hz=5.0)
    with pytest.raises(ts.SelectionError, match="--bandwidth-floor"):
        ts.Evaluator(moving, tmp_path / "m.sqlite")
    front, evaluated, _ = ts.pareto(
        TASK, tmp_path / "p.sqlite", ("q3_rmse_deg", "motor_energy_j"), weights=3, budget_each=16
    )
    assert front
    for f in front:
        assert not any(
            e.outputs["q3_rmse_deg"] < f.outputs["q3_rmse_deg"]
            and e.outputs["motor_energy_j"] < f.outputs["motor_energy_j"]
            for e in evaluated
            if e.feasible
        )


def test_select_command(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["select", "fig14-sine", "--duration", "0.3", "--budget", "16"]
    store = ["--store", str(tmp_path / "s.sqlite"), "--out", str(tmp_path)]
    assert run_fsarm(monkeypatch, *args, *store) == 0
    assert "optimum: D =" in capsys.readouterr().out
    data = json.loads((tmp_path / "select.json").read_text())
    assert 4.0 <= data["best"]["diameter_mm"] <= 13.0
    assert run_fsarm(monkeypatch, *args, *store, "--objective", "speed") == 2
    err = capsys.readouterr().err
    assert "objective must be one of" in err and "Traceback" not in err
