"""Shaft catalogue and coefficient files (seed 000 eq. 3, 4)."""

from __future__ import annotations

import math
from collections.abc import Callable
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


def test_seed_001_masterflex08_cannot_be_built_from_the_catalogue() -> None:
    # seed 001's 8 x 865 mm shaft: outside eq. 3/4's lengths, and eq. 4's bending stiffness is
    # negative there (why 001-*-flexible-shaft are not judged on our shaft model)
    with pytest.raises(ShaftRangeError, match="validity range"):
        CAT.shaft(8.0, 865.0)
    with pytest.raises(ShaftRangeError, match=r"bending -0\.886"):
        CAT.shaft(8.0, 865.0, extrapolate=True)


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
        (lambda t: t.replace("p = [1.334, ", "p = ["), "list of 7"),
        (lambda t: t.replace("p = [1.334, ", 'p = ["x", '), "finite number"),
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


# --- eq. 3's length law, eq. 4 as identified, the slip elements' apparent stiffness -------------


INVERSE_FILE = Path(__file__).resolve().parents[1] / "src/fsarm_sim/data/shafts_inverse_length.toml"
INVERSE = load_catalogue(INVERSE_FILE)


def _with(tmp_path: Path, edit: Callable[[str], str], text: str | None = None) -> Path:
    f = tmp_path / "edited.toml"
    f.write_text(edit(_default_text() if text is None else text))
    return f


def test_default_is_eq3_as_printed_affine_in_length() -> None:
    """Seed 000 eq. 3 as printed (issue 27): K_s = p0 + ... + p4 L + ..., falling linearly with
    L for every D, and the prototype's 15 N*m/rad at 9 mm x 450 mm."""
    assert CAT.series_reference_length_mm == 0.0
    for p in (CAT.p_pos, CAT.p_neg):
        assert p[4] < 0.0
    for d in (4.0, 9.0, 13.0):
        for side in (1, -1):
            p = CAT.p_pos if side > 0 else CAT.p_neg
            for ell in (235.0, 335.0, 535.0):
                k = CAT.shaft(d, ell).k_series(0.0, side)
                want = p[0] + d * p[1] + d**2 * p[2] + d**3 * p[3] + p[4] * ell
                assert k == pytest.approx(want, rel=1e-12)
    assert CAT.shaft(9.0, 450.0).k_series(0.0, 1) == pytest.approx(15.0, rel=1e-5)


def test_inverse_length_law_option_scales_eq3_by_l_ref_over_l() -> None:
    assert INVERSE.series_reference_length_mm == 450.0
    for d in (4.0, 9.0, 13.0):
        ref = INVERSE.shaft(d, 450.0)
        for ell in (235.0, 335.0, 535.0):
            s = INVERSE.shaft(d, ell)
            for side in (1, -1):
                for b in (0.0, 1.0):
                    assert s.k_series(b, side) == pytest.approx(
                        ref.k_series(b, side) * 450.0 / ell, rel=1e-12
                    )
    # seed 001's measured MasterFlex08 (8 mm x 865 mm, ~5.3 N*m/rad secant at 90 deg twist)
    k, _ = INVERSE.eq3(8.0, 865.0, 1)  # beyond the 535 mm validity (eq. 4 is negative there)
    assert k == pytest.approx(5.3, rel=0.1)
    # eq. 3 as printed cannot: its one p4 L term is the same for every D
    k_affine, _ = CAT.eq3(8.0, 865.0, 1)
    assert k_affine > 1.3 * 5.3


def test_the_two_length_laws_differ_only_in_the_length_term() -> None:
    """The option file is the default but for eq. 3's length law: every other parameter equal,
    and the same series stiffness at its 450 mm reference (the default arm's shaft)."""
    from dataclasses import fields

    differ = {"source", "p_pos", "p_neg", "series_reference_length_mm"}
    for f in fields(CAT):
        if f.name not in differ:
            assert getattr(CAT, f.name) == getattr(INVERSE, f.name), f.name
    for d in (4.0, 6.5, 9.0, 13.0):
        for side in (1, -1):
            for b in (0.0, 0.7, 2.0):
                a = CAT.shaft(d, 450.0).k_series(b, side)
                assert a == pytest.approx(INVERSE.shaft(d, 450.0).k_series(b, side), rel=1e-9)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: t.replace('length_law = "inverse"', 'length_law = "log"'), "length_law"),
        (lambda t: t.replace("reference_length_mm = 450.0\n", ""), "needs 'series.reference"),
        (lambda t: t.replace("reference_length_mm = 450.0", "reference_length_mm = -1.0"), "> 0"),
        (lambda t: t.replace("0.03024786, 0.0,", "0.03024786, -0.005,"), "p4 L term"),
        (
            lambda t: t.replace('length_law = "inverse"\n', 'length_law = "affine"\n'),
            "only read with length_law = 'inverse'",
        ),
        (lambda t: t.replace("eq2_test_period_s = 8.0\n", ""), "needs 'bending.eq2_test_period_s'"),
        (lambda t: t.replace("eq2_test_period_s = 8.0", "eq2_test_period_s = 0.0"), "> 0"),
        (
            lambda t: t.replace(
                "apparent_stiffness_neg = [0.0298", "apparent_stiffness_neg = [nan"
            ),
            "finite",
        ),
    ],
)
def test_length_law_and_identification_keys_are_checked(
    tmp_path: Path, edit: Callable[[str], str], message: str
) -> None:
    with pytest.raises(CoefficientFileError, match=message):
        load_catalogue(_with(tmp_path, edit, INVERSE_FILE.read_text("utf-8")))


def test_eq4_is_what_eq2_identifies_and_the_elastic_kb_relieves_8nm(tmp_path: Path) -> None:
    s = CAT.shaft()
    gain = CAT.eq2_fit_gain()
    # 1 + 3/4 beta A^2 + sum f_i (w tau_i)^2 / (1 + (w tau_i)^2), A = 90 deg, period 8 s
    w = 2.0 * math.pi / 8.0
    want = 1.0 + 0.75 * 0.1 * (math.pi / 2) ** 2
    want += sum(f * (w * t) ** 2 / (1 + (w * t) ** 2) for f, t in ((0.35, 0.15), (0.25, 1.5)))
    assert gain == pytest.approx(want, rel=1e-12)
    assert s.kb_eq4 == pytest.approx(gain * s.kb, rel=1e-12)
    assert s.kb == pytest.approx(4.085, rel=1e-3)  # the elastic K_b behind the 8 N*m relief
    no_test = load_catalogue(
        _with(
            tmp_path,
            lambda t: t.replace("eq2_test_amplitude_rad = 1.5707963267948966\n", "").replace(
                "eq2_test_period_s = 8.0\n", ""
            ),
        )
    )
    assert no_test.eq2_fit_gain() == 1.0
    assert no_test.shaft().kb == no_test.shaft().kb_eq4 == pytest.approx(s.kb_eq4, rel=1e-12)


def test_spring_is_eq3_less_the_elements_apparent_stiffness() -> None:
    on = CAT.shaft(series_hysteresis=True)
    off = CAT.shaft(series_hysteresis=False)
    assert off.slip_apparent == (0.0, 0.0, 0.0, 0.0)
    a = CAT.slip_apparent_fraction
    for b in (0.0, 1.0):
        assert off.k_spring(b, 1) == off.k_series(b, 1)
        assert on.k_spring(b, 1) == pytest.approx(on.k_series(b, 1) - (a[0] + a[1] * b) * on.k_pos)
        assert on.k_spring(b, -1) == pytest.approx(
            on.k_series(b, -1) - (a[2] + a[3] * b) * on.k_pos
        )
        assert 0.0 < on.k_spring(b, -1) < on.k_series(b, -1)


def test_a_deeply_nested_coefficient_file_is_a_named_error(tmp_path: Path) -> None:
    """Issue 33: nested arrays gave a RecursionError out of tomllib."""
    from fsarm_sim.errors import CoefficientFileError
    from fsarm_sim.plant.shaft import load_catalogue

    for depth in (40, 50_000):
        f = tmp_path / f"deep{depth}.toml"
        f.write_text("x = " + "[" * depth + "]" * depth + "\n")
        with pytest.raises(CoefficientFileError, match=f"{f}: arrays/tables nest deeper than 32"):
            load_catalogue(f)
    (tmp_path / "loop.toml").symlink_to("loop.toml")
    with pytest.raises(CoefficientFileError, match=r"loop\.toml: it is a loop of symbolic links"):
        load_catalogue(tmp_path / "loop.toml")
