"""Shared fixtures. Every test that steps MuJoCo goes through code that raises on any warning."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np
import pytest

from fsarm_sim.shaft import ShaftParams, load_catalogue


@pytest.fixture(scope="session")
def prototype() -> ShaftParams:
    """The 9 mm x 450 mm prototype shaft of seed 000 from the default catalogue."""
    return load_catalogue().shaft()


def hold_table(q1: float, q2: float, q3: float, n: int = 1) -> np.ndarray:
    """Reference table holding one pose."""
    row = np.zeros((n, 9))
    row[:, 0], row[:, 1], row[:, 2] = q1, q2, q3
    return row
