"""The diagnosis recording's panels name their quantities with units (issue 31)."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

from fsarm_sim.cli import diagnose_rrd

T = np.linspace(0.0, 1.0, 11)


def _models(**per_model: object) -> dict[str, SimpleNamespace]:
    return {m: SimpleNamespace(**per_model) for m in diagnose_rrd.MODELS}


@pytest.mark.parametrize(
    ("inp", "out", "in_unit", "out_unit"),
    [("theta_m", "tau_s", "rad", "N·m"), ("phi_b", "m_b", "rad", "N·m")],
)
def test_bench_panels_and_loops_carry_units(
    inp: str, out: str, in_unit: str, out_unit: str
) -> None:
    diag = SimpleNamespace(
        ctx=SimpleNamespace(inp=SimpleNamespace(t=T, y=np.sin(T), u=T)),
        dataset=SimpleNamespace(input_column=inp, output_column=out),
        **_models(yhat=0.9 * np.sin(T)),
    )
    _, panels, loops = diagnose_rrd._bench(diag)
    titles = {p.name: p.title for p in panels}
    assert titles == {
        "output": f"{out} [{out_unit}]: measured vs models",
        "residual": f"{out} residual [{out_unit}] (measured - model)",
        "input": f"{inp} [{in_unit}]",
    }
    for lp in loops:
        assert (lp.x_label, lp.y_label) == (f"{inp} [{in_unit}]", f"{out} residual [{out_unit}]")


def test_arm_panels_and_loops_carry_units() -> None:
    channels = ("q3", "theta_m", "q2", "twist")
    y = {c: np.sin(T) for c in channels}
    diag = SimpleNamespace(ctx=SimpleNamespace(y=y, run=SimpleNamespace(t=T)), **_models(pred=y))
    _, panels, loops = diagnose_rrd._arm(diag)
    assert len(panels) == 8 and len(loops) == 2
    for p in panels:
        assert re.search(r"\[rad\]", p.title), p.title
    assert (loops[0].x_label, loops[0].y_label) == ("q3 [rad]", "twist residual [rad]")


def test_label_names_the_unit_or_keeps_a_bare_name() -> None:
    assert diagnose_rrd.label("tau_s", "residual") == "tau_s residual [N·m]"
    assert diagnose_rrd.label("qdd1_ref") == "qdd1_ref [rad/s^2]"
    assert diagnose_rrd.label("my_sensor") == "my_sensor"
