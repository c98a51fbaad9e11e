"""Shared fixtures. Every test that steps MuJoCo goes through code that raises on any warning."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "disable")

import sys

import numpy as np
import pytest

from fsarm_sim.plant.shaft import ShaftParams, load_catalogue


@pytest.fixture(scope="session")
def prototype() -> ShaftParams:
    """The 9 mm x 450 mm prototype shaft of seed 000 from the default catalogue, its eq. 8 law
    alone (series hysteresis off: the tests of the elastic law need it exact)."""
    return load_catalogue().shaft(series_hysteresis=False)


def run_fsarm(monkeypatch: pytest.MonkeyPatch, *args: str) -> int:
    """Run the ``fsarm`` command in-process as a user would; return its exit code."""
    from fsarm_sim import cli

    monkeypatch.setattr(sys, "argv", ["fsarm", *args])
    try:
        cli.main()
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def hold_table(q1: float, q2: float, q3: float, n: int = 1) -> np.ndarray:
    """Reference table holding one pose."""
    row = np.zeros((n, 9))
    row[:, 0], row[:, 1], row[:, 2] = q1, q2, q3
    return row
