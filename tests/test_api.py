"""The top-level API: a first script's run, its units and its files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsarm_sim import (
    FsarmError,
    SimConfig,
    column_units,
    load_catalogue,
    run_scenario,
    scenario_names,
    write_run,
)


def test_first_script(tmp_path: Path) -> None:
    shaft = load_catalogue().shaft(diameter_mm=9.0, length_mm=450.0)
    result = run_scenario("step-q3", SimConfig(shaft=shaft), duration_s=0.05)
    units = column_units(result)
    assert units["q3"] == "rad" and units["tau_shaft"] == "N*m"
    path = write_run(result, tmp_path / "runs", "parquet")
    assert path.is_file() and path.with_suffix(".json").is_file()
    summary = json.loads((tmp_path / "runs" / "step-q3.summary.json").read_text())
    assert summary["rmse_rad"]["q3"] == pytest.approx(result.metrics["rmse_rad"]["q3"])  # type: ignore[index]
    assert "fig14-sine" in scenario_names()


def test_unknown_name_is_an_attribute_error() -> None:
    import fsarm_sim

    with pytest.raises(AttributeError):
        fsarm_sim.not_a_name  # noqa: B018
    with pytest.raises(FsarmError):
        run_scenario("no-such-scenario", SimConfig())
