"""The reduced bounded least squares (discrepancy/lsq.py) against scipy's solve of the full one."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from fsarm_sim.discrepancy import lsq


def _problem(kind: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    n, k = 3000, 6
    a = rng.normal(size=(n, k))
    if kind == "near_dependent":  # a look-alike pair of columns: the QR path
        a[:, 1] = a[:, 0] + 1e-6 * rng.normal(size=n)
    elif kind == "zero_column":  # a candidate whose column vanishes on these rows
        a[:, 2] = 0.0
    y = a @ rng.uniform(-1.0, 1.0, k) + 0.1 * rng.normal(size=n)
    return a, y


@pytest.mark.parametrize("kind", ["plain", "near_dependent", "zero_column"])
@pytest.mark.parametrize("bound", [np.inf, 0.3])
def test_reduced_solve_matches_the_full_one(kind: str, bound: float) -> None:
    rng = np.random.default_rng(7)
    a, y = _problem(kind, rng)
    lo, hi = np.full(a.shape[1], -bound), np.full(a.shape[1], bound)
    full = lsq_linear(a, y, bounds=(lo, hi), method="bvls")
    x = lsq.bounded(a, y, lo, hi)
    assert np.all(x >= lo) and np.all(x <= hi)
    # the same minimum (the minimiser itself is not unique where a column is zero or two are
    # nearly equal: there only the residual is compared)
    cost = float(np.sum((a @ x - y) ** 2))
    assert cost == pytest.approx(float(np.sum((a @ full.x - y) ** 2)), rel=1e-9)
    if kind == "plain":
        np.testing.assert_allclose(x, full.x, rtol=1e-8, atol=1e-10)


def test_the_triangle_keeps_the_residual_up_to_a_constant() -> None:
    rng = np.random.default_rng(8)
    for kind in ("plain", "near_dependent"):
        a, y = _problem(kind, rng)
        r, qty = lsq.triangle(a, y)
        assert r.shape == (a.shape[1], a.shape[1])
        offset = None
        for _ in range(5):
            x = rng.normal(size=a.shape[1])
            d = float(np.sum((a @ x - y) ** 2) - np.sum((r @ x - qty) ** 2))
            offset = d if offset is None else offset
            assert d == pytest.approx(offset, rel=1e-7, abs=1e-6)


def test_bounded_hands_bvls_the_triangle_of_a_tall_problem(monkeypatch: pytest.MonkeyPatch) -> None:
    """Told apart by what BVLS is handed (the tall problem or its n x n triangle): the two
    solutions can agree to the last bit on some BLAS builds, so their values cannot."""
    rng = np.random.default_rng(9)
    a, y = _problem("plain", rng)
    lo, hi = np.full(a.shape[1], -0.5), np.full(a.shape[1], 0.5)  # some bounds active
    shapes: list[tuple[int, ...]] = []

    def spy(m: np.ndarray, *args: object, **kw: object) -> object:
        shapes.append(m.shape)
        return lsq_linear(m, *args, **kw)

    monkeypatch.setattr(lsq, "lsq_linear", spy)
    r, qty = lsq.triangle(a, y)
    reduced = lsq_linear(r, qty, bounds=(lo, hi), method="bvls").x
    np.testing.assert_array_equal(lsq.bounded(a, y, lo, hi), reduced)
    assert shapes[-1] == (a.shape[1], a.shape[1])
    wide = a[: a.shape[1] - 1]  # not tall: nothing to reduce
    lsq.bounded(wide, y[: wide.shape[0]], lo, hi)
    assert shapes[-1] == wide.shape
