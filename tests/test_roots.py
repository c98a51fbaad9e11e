"""plant.roots: the shared bisection."""

from __future__ import annotations

import math

from fsarm_sim.plant.roots import bisect


def test_bisect_finds_the_sign_change_of_a_rising_function() -> None:
    root = bisect(lambda x: x * x < 2.0, 0.0, 2.0)
    assert abs(root - math.sqrt(2.0)) <= math.ulp(math.sqrt(2.0))


def test_bisect_keeps_the_low_side_where_below_holds() -> None:
    # a falling function: "below" is True at the low end, so the bracket still closes on the root
    root = bisect(lambda x: math.cos(x) > 0.0, 0.0, 3.0, halvings=60)
    assert abs(root - 0.5 * math.pi) < 1e-12


def test_bisect_with_few_halvings_returns_the_middle_of_its_last_bracket() -> None:
    assert bisect(lambda x: x < 0.3, 0.0, 1.0, halvings=1) == 0.25
    assert bisect(lambda x: x < 0.3, 0.0, 1.0, halvings=0) == 0.5
