"""Seed 003's arc-magnet comparison spring (26 / 11 deg) beside the flat-magnet one."""

from __future__ import annotations

import pytest

from fsarm_sim.plant.transmissions import magnetic_spring as ms
from fsarm_sim.studies import magnetic_spring_arc as arc


def test_solving_the_fms_numbers_gives_the_modules_shape() -> None:
    r2, r3 = arc.solve_shape(31.5, 19.7)
    b = ms.default_block()
    assert r2 == pytest.approx(b[ms.I_B2] / b[ms.I_B1], abs=2e-4)
    assert r3 == pytest.approx(b[ms.I_B3] / b[ms.I_B1], abs=2e-4)


def test_arc_spring_has_the_published_ranges_and_the_same_peak() -> None:
    fms, ams = arc.compare()
    assert ams.stable_deg == pytest.approx(26.0, abs=1e-3)
    assert ams.linear_deg == pytest.approx(11.0, abs=1e-3)
    assert ams.max_torque_nm == pytest.approx(fms.max_torque_nm, rel=1e-9)
    # trapezoidal (Sec. 3): at equal peak torque the arc spring is stiffer at the centre
    assert ams.stiffness_nm_per_rad > fms.stiffness_nm_per_rad


def test_impossible_ranges_are_refused() -> None:
    with pytest.raises(arc.ArcSpringError):
        arc.solve_shape(20.0, 25.0)
    with pytest.raises(arc.ArcSpringError):
        arc.solve_shape(70.0, 10.0)
