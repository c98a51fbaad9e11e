"""Shared fixtures. Every test that steps MuJoCo goes through code that raises on any warning."""

from __future__ import annotations

import io
import itertools
import os

os.environ.setdefault("MUJOCO_GL", "disable")

import sys
from typing import Any

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


def free_oscillation_energies(
    law: Any, tr: np.ndarray, act: np.ndarray, j: float, x0: float, dt: float, steps: int
) -> list[float]:
    """An inertia ``j`` on a transmission law's output (input held, no bend), started at twist
    ``x0`` at rest and integrated by RK4: the total energy (kinetic + ``law.potential_j``) after
    each step."""
    x, v = x0, 0.0
    out = []

    def acc(x_: float, v_: float) -> float:
        return float(-law.torque_nm(tr, x_, v_, 0.0, act, 0) / j)  # output side: x = -theta_s

    for _ in range(steps):
        k1x, k1v = v, acc(x, v)
        k2x, k2v = v + 0.5 * dt * k1v, acc(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v)
        k3x, k3v = v + 0.5 * dt * k2v, acc(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v)
        k4x, k4v = v + dt * k3v, acc(x + dt * k3x, v + dt * k3v)
        x += dt * (k1x + 2 * k2x + 2 * k3x + k4x) / 6
        v += dt * (k1v + 2 * k2v + 2 * k3v + k4v) / 6
        out.append(0.5 * j * v * v + law.potential_j(tr, x, 0.0, act, 0))
    return out


def check_free_oscillation(
    law: Any,
    blocks: tuple[np.ndarray, np.ndarray],
    act: np.ndarray,
    run: tuple[float, float, float, int],
    *,
    drift: float,
    rise: float,
    final: float,
) -> None:
    """The free oscillation of :func:`free_oscillation_energies` (``run`` = inertia, start
    twist, step, steps) keeps its energy within ``drift`` (relative) on ``blocks[0]`` (no
    damping), and on ``blocks[1]`` (damped) never gains more than ``rise`` J a step and ends
    below ``final`` of the start."""
    free_tr, damped_tr = blocks
    j, x0, dt, steps = run
    e0 = law.potential_j(damped_tr, x0, 0.0, act, 0)
    free = free_oscillation_energies(law, free_tr, act, j, x0, dt, steps)
    assert max(abs(e - e0) for e in free) < drift * e0
    damped = free_oscillation_energies(law, damped_tr, act, j, x0, dt, steps)
    assert all(b <= a + rise for a, b in itertools.pairwise(damped))
    assert damped[-1] < final * e0


def make_jitable(module: Any) -> None:
    """Register a law module's functions with numba (as the native backend does), so a test's
    ``numba.njit`` function may call them."""
    import inspect

    from numba.extending import register_jitable

    for _, fn in inspect.getmembers(module, inspect.isfunction):
        if fn.__module__ == module.__name__ and not getattr(fn, "_fsarm_jitable", False):
            register_jitable(error_model="numpy", _nrt=False)(fn)
            fn._fsarm_jitable = True


class FailingStdout(io.StringIO):
    """A standard output whose every write fails with OSError ``code`` (a full or closed
    device)."""

    def __init__(self, code: int) -> None:
        super().__init__()
        self.code = code

    def write(self, text: str) -> int:
        raise OSError(self.code, os.strerror(self.code))


def hold_table(q1: float, q2: float, q3: float, n: int = 1) -> np.ndarray:
    """Reference table holding one pose."""
    row = np.zeros((n, 9))
    row[:, 0], row[:, 1], row[:, 2] = q1, q2, q3
    return row


def joint3_gravity_balance(m: Any) -> tuple[float, float]:
    """At the model's initial state (``initial_state``): (the transmission's torque on joint 3,
    the gravity torque joint 3 must hold), both joint-side, N*m."""
    import mujoco

    from fsarm_sim.engine.model import read_structure
    from fsarm_sim.kernels import layout, physics
    from fsarm_sim.sim.simulation import initial_state

    d = mujoco.MjData(m)
    st = read_structure(m)
    initial_state(m, d, st)
    tau = physics.shaft_torque(m.numeric(layout.PARAMS_NAME).data, d.qpos, d.qvel, d.act)
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_rne(m, d, 0, d.qfrc_bias)
    return float(tau * st.coef_s), float(d.qfrc_bias[st.dof[2]])


def check_battery_printout(
    text: str, results: list, signature_ok: object, rates: dict, ci_misses: bool
) -> None:
    """What an expert battery's printout (``battery_expert.format_battery``) must say about
    ``results``: one row per case in order, marked ``ok`` exactly when the named effects and the
    unexplained flag are right and the case did not fail, its signature mark, the summary cut at
    90 characters, the error; the CI-miss lines where asked for; every rate as ``a/b (p %)``; a
    runtime line only when a runtime is known."""
    lines = text.split("\n")
    rows = [ln for ln in lines[1:] if ln.startswith(("ok ", "BAD"))]
    assert len(rows) == len(results)
    misses = [ln for ln in lines if ln.startswith("      CI misses: ")]
    for row, r in zip(rows, results, strict=True):
        good = set(r.named) == set(r.truth_names) and r.unexplained == bool(r.case.extra)
        assert row.startswith("ok " if good and not r.error else "BAD"), row
        assert f" {r.case.name} " in row and f"unexpl={r.unexplained}" in row
        assert f"joint={r.joint_steps} " in row and (",".join(r.named) or "none") in row
        sr = signature_ok(r)  # type: ignore[operator]
        mark = "" if sr is None else ("sig-ok " if sr else "sig-BAD ")
        summary = r.signature.get("summary", "-") if r.signature else "-"
        assert row.endswith(f"{mark}{summary[:90]}{r.error}"), row
    wrong = [[n for n, c in r.covered if not c] for r in results]
    expected = [f"      CI misses: {', '.join(w)}" for w in wrong if w] if ci_misses else []
    assert misses == expected
    for key, (a, b) in rates.items():
        assert f"  {key:<24} {a}/{b} ({100 * a / max(b, 1):.0f} %)" in lines, key
    known = any(np.isfinite(r.runtime_s) for r in results)
    assert any(ln.startswith("  runtime per record") for ln in lines) == known
