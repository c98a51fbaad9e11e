"""Shaft catalogue and coefficient files (seed 000 eq. 3, 4)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.errors import CoefficientFileError, ShaftRangeError
from fsarm_sim.plant.shaft import load_catalogue

CAT = load_catalogue()
BENDS = np.linspace(0.0, 2.0 * math.pi / 3.0, 9)


def test_prototype_magnitudes() -> None:
    s = CAT.shaft(9.0, 450.0)
    assert s.k_series(0.0, +1) == pytest.approx(15.0, rel=1e-5)
    assert s.k_series(0.0, -1) == pytest.approx(12.0, rel=1e-5)
    # ~8 N*m static relief on joint 2 at 90 deg bend (seed 000 Sec. V)
    assert s.static_relief_nm(math.pi / 2) == pytest.approx(8.0, abs=1e-3)
    # carries the rated joint-3 torque (67 N*m / i_G2) within its rating
    assert s.rating_nm > 6.7


@pytest.mark.parametrize("d", np.linspace(4.0, 13.0, 7))
@pytest.mark.parametrize("ell", np.linspace(235.0, 535.0, 5))
def test_trends_over_validity_box(d: float, ell: float) -> None:
    s = CAT.shaft(d, ell)
    for phi in BENDS:
        kp, kn = s.k_series(phi, +1), s.k_series(phi, -1)
        assert 0.0 < kn < kp, "winding side must be stiffer and both positive"
    # falls (linearly) with bend angle, either bend direction
    kp = [s.k_series(p, +1) for p in BENDS]
    assert np.all(np.diff(kp) < 0.0)
    assert np.allclose(np.diff(kp, 2), 0.0, atol=1e-12)
    assert s.k_series(-0.5, +1) == pytest.approx(s.k_series(0.5, +1))
    if ell < 535.0:  # falls with length
        assert CAT.shaft(d, ell + 50.0).k_series(0.3, +1) < s.k_series(0.3, +1)
        assert CAT.shaft(d, ell + 50.0).kb < s.kb
    if d < 13.0:  # rises with diameter
        assert CAT.shaft(d + 1.0, ell).k_series(0.3, +1) > s.k_series(0.3, +1)
        assert CAT.shaft(d + 1.0, ell).kb > s.kb


@pytest.mark.parametrize(("d", "ell"), [(3.9, 450.0), (13.1, 450.0), (9.0, 200.0), (9.0, 600.0)])
def test_out_of_range_is_named_error(d: float, ell: float) -> None:
    with pytest.raises(ShaftRangeError, match="validity range"):
        CAT.shaft(d, ell)


def test_extrapolation_is_opt_in() -> None:
    s = CAT.shaft(9.0, 600.0, extrapolate=True)
    assert s.k_series(0.0, 1) < CAT.shaft(9.0, 535.0).k_series(0.0, 1)
    with pytest.raises(ShaftRangeError, match="non-positive"):
        CAT.shaft(4.0, 2000.0, extrapolate=True)  # eq. 3 goes negative there: still refused


@pytest.mark.parametrize("bad", [float("nan"), -1.0, 0.0, float("inf")])
def test_non_finite_dimensions(bad: float) -> None:
    with pytest.raises(ShaftRangeError):
        CAT.shaft(bad, 450.0, extrapolate=True)


def test_nine_bench_shafts() -> None:
    assert len(CAT.shafts) == 9
    assert any(s.diameter_mm == 9.0 and s.length_mm == 450.0 for s in CAT.shafts)
    for s in CAT.shafts:
        CAT.shaft(s.diameter_mm, s.length_mm)


def _default_text() -> str:
    from importlib import resources

    return resources.files("fsarm_sim.data").joinpath("shafts.toml").read_text("utf-8")


def test_user_file_loads(tmp_path: Path) -> None:
    text = _default_text().replace("stiffening_per_rad2 = 0.1", "stiffening_per_rad2 = 0.0")
    f = tmp_path / "mine.toml"
    f.write_text(text)
    s = load_catalogue(f).shaft()
    assert s.beta == 0.0
    assert s.static_relief_nm(1.0) == pytest.approx(s.kb)


def test_missing_file() -> None:
    with pytest.raises(CoefficientFileError, match="not found"):
        load_catalogue("/nonexistent/shafts.toml")


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: t.replace("[series.positive]", "[series.pos]"), "series.positive"),
        (lambda t: t.replace("p = [0.434, ", "p = ["), "list of 7"),
        (lambda t: t.replace("p = [0.434, ", 'p = ["x", '), "finite number"),
        (lambda t: t.replace("stiffening_per_rad2 = 0.1", "stiffening_per_rad2 = nan"), "finite"),
        (
            lambda t: t.replace(
                "branch_time_constant_s = [0.15, 1.5]", "branch_time_constant_s = [0.0, 1.5]"
            ),
            "> 0",
        ),
        (
            lambda t: t.replace("diameter_mm = [4.0, 13.0]", "diameter_mm = [13.0, 4.0]"),
            "low < high",
        ),
        (lambda t: t + "\n[[[broken", "not valid TOML"),
    ],
)
def test_malformed_files(tmp_path: Path, edit, message: str) -> None:  # type: ignore[no-untyped-def]
    f = tmp_path / "bad.toml"
    f.write_text(edit(_default_text()))
    with pytest.raises(CoefficientFileError, match=message) as info:
        load_catalogue(f)
    assert str(f) in str(info.value)
