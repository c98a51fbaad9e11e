"""Sweep field units and labels (the tidy table's schema and the maps' axes)."""

from __future__ import annotations

import pytest

from fsarm_sim.studies import sweep_table


@pytest.mark.parametrize(
    ("name", "unit"),
    [
        ("diameter_mm", "mm"),
        ("bend_deg", "deg"),
        ("peak_motor_speed_rad_s", "rad/s"),
        ("peak_twist_rad", "rad"),
        ("torque_bandwidth_hz", "Hz"),
        ("static_relief_nm", "N*m"),
        ("bend_loop_energy_j", "J"),
        ("wall_s", "s"),
        ("k_sp", "N*m/rad"),
        ("scenario", ""),
    ],
)
def test_units_from_names(name: str, unit: str) -> None:
    assert sweep_table.unit(name) == unit


def test_labels_read_like_axes() -> None:
    assert sweep_table.label("diameter_mm") == "shaft diameter D [mm]"
    assert sweep_table.label("q3_rmse_deg") == "joint-3 tracking RMSE [deg]"
    assert sweep_table.label("something_new") == "something_new"
