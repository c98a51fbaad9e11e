"""Scenario registry: name -> reference trajectory, duration, payload.

Add a scenario with ``@register``; every registered scenario is run by the generic tests.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim import references as R
from fsarm_sim.errors import ScenarioNotFoundError

Array = npt.NDArray[np.float64]
DEG = math.pi / 180.0


@dataclass(frozen=True)
class Scenario:
    name: str
    description: str
    duration_s: float
    payload_kg: float
    reference: Callable[[Array], Array]  # tick times -> table (n, 9)


REGISTRY: dict[str, Scenario] = {}


def register(
    name: str, description: str, duration_s: float, payload_kg: float = 0.0
) -> Callable[[Callable[[Array], Array]], Callable[[Array], Array]]:
    def wrap(fn: Callable[[Array], Array]) -> Callable[[Array], Array]:
        REGISTRY[name] = Scenario(name, description, duration_s, payload_kg, fn)
        return fn

    return wrap


def get(name: str) -> Scenario:
    try:
        return REGISTRY[name]
    except KeyError:
        raise ScenarioNotFoundError(
            f"unknown scenario '{name}'; registered scenarios: {', '.join(sorted(REGISTRY))}"
        ) from None


FIG14_POSE_Q2 = (
    45.0 * DEG
)  # joint 2 holds 45 deg: the shaft is bent by phi_B = 45 deg (Fig. 7's bend)


@register(
    "fig14-sine",
    "Seed 000 Fig. 14: joint 3 follows 0-90 deg, period 4 s (peak 71 deg/s ~ nominal 75 deg/s); "
    "joints 1, 2 hold a pose that bends the shaft 45 deg",
    duration_s=10.0,
)
def _fig14(t: Array) -> Array:
    return R.stack(
        (R.hold(t, 0.0), R.hold(t, FIG14_POSE_Q2), R.cosine_sweep(t, 0.0, 90.0 * DEG, 4.0))
    )


@register(
    "p2p-payload",
    "Multi-joint point-to-point with the rated 15 kg payload: minimum-jerk moves out and back "
    "(2.5 s each) between a folded and a reaching pose",
    duration_s=7.0,
    payload_kg=15.0,
)
def _p2p(t: Array) -> Array:
    a = (0.0, 15.0 * DEG, 60.0 * DEG)
    b = (60.0 * DEG, 60.0 * DEG, 20.0 * DEG)
    out = []
    for j in range(3):
        go = R.quintic(t, a[j], b[j], 0.5, 2.5)
        back = R.quintic(t, 0.0, a[j] - b[j], 4.0, 2.5)
        out.append((go[0] + back[0], go[1] + back[1], go[2] + back[2]))
    return R.stack((out[0], out[1], out[2]))


@register(
    "step-q3",
    "Joint-3 position step of 10 deg at t = 0.5 s (shaft bent 45 deg): torque and position loop response",
    duration_s=2.0,
)
def _step_q3(t: Array) -> Array:
    return R.stack(
        (R.hold(t, 0.0), R.hold(t, FIG14_POSE_Q2), R.step(t, 30.0 * DEG, 40.0 * DEG, 0.5))
    )


@register(
    "step-q2",
    "Joint-2 position step of 10 deg at t = 0.5 s: bending torque and its hysteresis seen by joint 2",
    duration_s=2.0,
)
def _step_q2(t: Array) -> Array:
    return R.stack((R.hold(t, 0.0), R.step(t, 30.0 * DEG, 40.0 * DEG, 0.5), R.hold(t, 30.0 * DEG)))
