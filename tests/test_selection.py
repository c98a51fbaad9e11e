"""Shaft selection: seed 000 Algorithm 1 against the closed-form selector."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies.shaft_selection import (
    SelectionRequest,
    ShaftSelectionError,
    algorithm1,
    candidates,
    select_shaft,
    stiffness,
)

from conftest import run_fsarm

CAT = load_catalogue()
DIAMETERS = sorted({s.diameter_mm for s in CAT.shafts})


def _reachable_requests(kind: str, n: int, seed: int) -> list[tuple[SelectionRequest, float]]:
    """Requests whose K_des a catalogue shaft reaches exactly: (request, that shaft's D)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        d = float(rng.choice(DIAMETERS))
        ell = float(rng.uniform(*CAT.length_range))
        bend = float(rng.uniform(0.0, math.radians(90.0))) if kind == "series" else 0.0
        side = int(rng.choice([1, -1])) if kind == "series" else 1
        k = stiffness(CAT, kind, d, ell, bend, side)
        out.append((SelectionRequest(k_des=k, kind=kind, bend_rad=bend, side=side), d))  # type: ignore[arg-type]
    return out


@pytest.mark.parametrize("kind", ["series", "parallel"])
def test_closed_form_reaches_every_reachable_stiffness(kind: str) -> None:
    for req, d_true in _reachable_requests(kind, 25, seed=1):
        sel = select_shaft(CAT, req)
        assert sel.feasible
        assert sel.k_nm_per_rad == pytest.approx(req.k_des, rel=1e-9)
        assert sel.diameter_mm <= d_true  # the smallest diameter that reaches K_des wins
        lo, hi = CAT.length_range
        assert lo <= sel.length_mm <= hi
        # the answer is the model's own value at the chosen shaft
        assert stiffness(CAT, kind, sel.diameter_mm, sel.length_mm, req.bend_rad, req.side) == (
            pytest.approx(sel.k_nm_per_rad, rel=1e-12)
        )


@pytest.mark.parametrize("kind", ["series", "parallel"])
def test_algorithm1_lands_within_one_step_and_never_beats_closed_form(kind: str) -> None:
    lo, hi = CAT.length_range
    n_itr = math.floor(hi - lo) + 1  # 1 mm grid
    step = (hi - lo) / n_itr
    for req, _ in _reachable_requests(kind, 15, seed=2):
        best = select_shaft(CAT, req)
        alg = algorithm1(CAT, req)
        if alg.diameter_mm != best.diameter_mm:
            continue  # Algorithm 1 fixes D from the torque need alone
        if best.k_nm_per_rad != pytest.approx(req.k_des, rel=1e-9):
            continue  # K_des just outside this D's range, accepted within the tolerance only
        # steepest |dK/dL| over the range: anywhere for the affine eq. 3 and eq. 4, at L_min for
        # the inverse length law option (K ~ 1/L)
        slope = abs(
            stiffness(CAT, kind, alg.diameter_mm, lo + 1.0, req.bend_rad, req.side)
            - stiffness(CAT, kind, alg.diameter_mm, lo, req.bend_rad, req.side)
        )
        assert abs(alg.k_nm_per_rad - req.k_des) <= slope * step * (1 + 1e-9)
        assert abs(alg.k_nm_per_rad - req.k_des) >= abs(best.k_nm_per_rad - req.k_des)
        assert lo <= alg.length_mm <= hi


def test_algorithm1_is_deterministic_by_default_and_seedable() -> None:
    req = SelectionRequest(k_des=15.0, kind="series", torque_nm=6.7)
    a, b = algorithm1(CAT, req), algorithm1(CAT, req)
    assert a == b
    starts = {algorithm1(CAT, req, seed=s).length_trace_mm[0] for s in range(6)}
    assert len(starts) > 1  # rand(L) really draws from the range


def test_algorithm1_picks_diameter_from_torque_need_only() -> None:
    # 6.7 N*m (the prototype's joint-3 torque / i_G2) needs the 9 mm shaft's 8.54 N*m rating
    req = SelectionRequest(k_des=15.0, kind="series", torque_nm=6.7)
    alg = algorithm1(CAT, req)
    assert alg.diameter_mm == 9.0
    assert CAT.rating_nm(alg.diameter_mm) >= 6.7 > CAT.rating_nm(8.0)
    assert alg.feasible
    assert alg.length_mm == pytest.approx(450.0, abs=1.0)  # the prototype (catalogue anchor)


def test_literal_algorithm1_walks_out_of_the_range() -> None:
    # as printed: delta computed once and +step when more stiffness is wanted, but eq. 3 falls with L
    req = SelectionRequest(k_des=15.0, kind="series", torque_nm=6.7)
    lit = algorithm1(CAT, req, variant="literal")
    lo, hi = CAT.length_range
    assert not lo <= lit.length_mm <= hi
    assert not lit.feasible
    steps = np.diff(lit.length_trace_mm)
    assert np.all(steps == steps[0])  # monotone walk


def test_unreachable_stiffness_is_a_named_error_with_the_reachable_ranges() -> None:
    # 4 and 5 mm shafts reach at most K(5 mm, 235 mm) = 6.5 N*m/rad
    req = SelectionRequest(k_des=10.0, kind="series", diameters_mm=(4.0, 5.0))
    with pytest.raises(ShaftSelectionError, match="not reachable") as info:
        select_shaft(CAT, req)
    assert "D 5: [" in str(info.value)
    near = select_shaft(CAT, req, nearest=True)
    assert not near.feasible
    assert near.diameter_mm == 5.0
    assert near.length_mm == CAT.length_range[0]  # the shortest: the stiffest
    alg = algorithm1(CAT, req)
    assert not alg.feasible and alg.diameter_mm == 4.0  # D from torque 0: the thinnest


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"k_des": math.nan}, "K_des"),
        ({"k_des": -1.0}, "K_des"),
        ({"k_des": 5.0, "torque_nm": 100.0}, "no shaft carries"),
        ({"k_des": 5.0, "bend_rad": math.radians(130.0)}, "bend angle"),
        ({"k_des": 5.0, "length_range_mm": (400.0, 300.0)}, "L_min < L_max"),
        ({"k_des": 5.0, "length_range_mm": (100.0, 300.0)}, "validity range"),
        ({"k_des": 5.0, "kind": "torsional"}, "kind"),
        ({"k_des": 5.0, "side": 0}, "side"),
        ({"k_des": 5.0, "kind": "parallel", "bend_rad": 0.3}, "does not depend"),
        ({"k_des": 5.0, "diameters_mm": (3.0,)}, "validity range"),
    ],
)
def test_bad_requests_raise_named_errors(kwargs: dict[str, object], match: str) -> None:
    req = SelectionRequest(**kwargs)  # type: ignore[arg-type]
    with pytest.raises(ShaftSelectionError, match=match):
        select_shaft(CAT, req)
    with pytest.raises(ShaftSelectionError, match=match):
        algorithm1(CAT, req)


def test_physics_of_the_choice() -> None:
    # stiffer wanted at the same diameter -> shorter shaft (eq. 3 and eq. 4 fall with L)
    for kind in ("series", "parallel"):
        k_lo = stiffness(CAT, kind, 9.0, 500.0)
        k_hi = stiffness(CAT, kind, 9.0, 300.0)
        a = select_shaft(CAT, SelectionRequest(k_des=k_lo, kind=kind, diameters_mm=(9.0,)))  # type: ignore[arg-type]
        b = select_shaft(CAT, SelectionRequest(k_des=k_hi, kind=kind, diameters_mm=(9.0,)))  # type: ignore[arg-type]
        assert b.length_mm < a.length_mm
    # a bent shaft is softer: the same K_des at 90 deg needs a shorter (or thicker) shaft
    k = stiffness(CAT, "series", 9.0, 400.0)
    straight = select_shaft(CAT, SelectionRequest(k_des=k, diameters_mm=(9.0,)), nearest=True)
    bent = select_shaft(
        CAT,
        SelectionRequest(k_des=k, bend_rad=math.radians(90.0), diameters_mm=(9.0,)),
        nearest=True,
    )
    assert bent.length_mm < straight.length_mm or bent.k_nm_per_rad < k
    # every candidate carries the torque need
    for c in candidates(CAT, SelectionRequest(k_des=15.0, torque_nm=6.7)):
        assert c.rating_nm >= 6.7


def test_cli_select_shaft(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        run_fsarm(
            monkeypatch, "select-shaft", "--k-des", "15", "--kind", "series", "--torque-nm", "6.7"
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "Algorithm 1 lands" in out and "closed" in out
    # stiffer than the stiffest shaft (13 mm x 235 mm, ~47 N*m/rad)
    code = run_fsarm(monkeypatch, "select-shaft", "--k-des", "100", "--kind", "series")
    assert code == 2
    assert "not reachable" in capsys.readouterr().err
    assert (
        run_fsarm(
            monkeypatch, "select-shaft", "--k-des", "5", "--kind", "parallel", "--torque-nm", "6.7"
        )
        == 0
    )


def test_length_is_the_series_stiffness_lever() -> None:
    """Eq. 3 as printed (the default): K falls linearly with L for every D, bend and side, so
    Algorithm 1 reaches a K_des between two of a diameter's stiffnesses by choosing L; with the
    inverse length law option (shafts_inverse_length.toml) K(L) L is constant instead."""
    assert CAT.series_reference_length_mm == 0.0
    for d in (4.0, 9.0, 13.0):
        for side in (1, -1):
            for bend in (0.0, 1.2):
                k = [stiffness(CAT, "series", d, ell, bend, side) for ell in (235.0, 385.0, 535.0)]
                assert k[0] > k[1] > k[2]
                assert k[1] == pytest.approx(0.5 * (k[0] + k[2]), rel=1e-12)  # linear in L
    k_300 = stiffness(CAT, "series", 9.0, 300.0)
    req = SelectionRequest(k_des=k_300, torque_nm=6.7, diameters_mm=(9.0,))
    sel = select_shaft(CAT, req)
    assert sel.feasible and sel.length_mm == pytest.approx(300.0, rel=1e-9)
    alg = algorithm1(CAT, req)
    assert alg.feasible and abs(alg.length_mm - 300.0) <= 1.0
    inverse = load_catalogue(
        Path(__file__).resolve().parents[1] / "src/fsarm_sim/data/shafts_inverse_length.toml"
    )
    for d in (4.0, 9.0, 13.0):
        k = [stiffness(inverse, "series", d, ell) * ell for ell in (235.0, 535.0)]
        assert k[0] == pytest.approx(k[1], rel=1e-12)
