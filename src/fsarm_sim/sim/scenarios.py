"""Scenario registry: name -> reference trajectory, duration, payload.

Add a scenario with ``@register``; every registered scenario is run by the generic tests.

A scenario may also script the outside world and an outer control loop (both used only by
:func:`fsarm_sim.sim.simulation.run_scenario`, once per control tick, and only when set):

* ``disturbance`` - an external force on the arm (a hit, a hand on the flange), see
  :class:`Disturbance`;
* ``outer_loop`` - a factory ``Simulation -> (tick k -> None)`` that may rewrite the reference
  rows from tick ``k`` on before the controller reads them (hand guiding, collision reaction;
  :mod:`fsarm_sim.sim.outer_loops`, which, like this module, sits below the runner).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import ScenarioNotFoundError
from fsarm_sim.sim import references
from fsarm_sim.sim.outer_loops import OuterLoop as OuterLoop
from fsarm_sim.sim.outer_loops import TickHook as TickHook
from fsarm_sim.sim.outer_loops import hand_guiding_loop, reaction_loop

Array = npt.NDArray[np.float64]
DEG = math.pi / 180.0


@dataclass(frozen=True)
class Disturbance:
    """A scripted external force on the arm, applied at a site (e.g. ``flange``).

    ``force_n(t)`` is the force (N) at time ``t`` expressed in the site's frame, applied at the
    site's origin through ``data.qfrc_applied`` (``mj_applyFT``) and held over each control
    period. ``window_s`` is the (start, end) of the contact, for detection statistics.
    """

    site: str
    force_n: Callable[[float], tuple[float, float, float]]
    window_s: tuple[float, float]


@dataclass(frozen=True)
class Scenario:
    name: str
    description: str
    duration_s: float
    payload_kg: float
    reference: Callable[[Array], Array]  # tick times -> table (n, 9)
    disturbance: Disturbance | None = None
    outer_loop: OuterLoop | None = None
    # the reference is a pure function of time (same times, same table), as every built-in one
    # is (fsarm_sim.sim.references): its table may be kept and reused. False for one that draws
    # new random numbers per call, say: its table is computed at every run.
    pure_reference: bool = True
    # per-joint tracking RMSE (deg, q1..q3) beyond which a run is far from what the scenario is
    # built for: run_scenario then adds a named warning (RunResult.warnings); None: no check
    rmse_warn_deg: tuple[float, float, float] | None = None

    def tracking_warnings(self, rmse_deg: Mapping[str, float]) -> tuple[str, ...]:
        """Named warnings for joints whose RMSE exceeds :attr:`rmse_warn_deg`."""
        if self.rmse_warn_deg is None:
            return ()
        out = []
        for j, limit in enumerate(self.rmse_warn_deg, start=1):
            got = rmse_deg.get(f"q{j}", math.nan)
            if math.isfinite(got) and got > limit:
                out.append(
                    f"TrackingWarning: joint {j} tracks {self.name} with {got:.3g}° RMSE, "
                    f"beyond the {limit:g}° this scenario is built for: check the gains and the "
                    "transmission's parameters"
                )
        return tuple(out)

    def table(self, n_ticks: int, ctrl_dt_s: float) -> Array:
        """The reference table of ticks ``0, ctrl_dt_s, ..., (n_ticks - 1) ctrl_dt_s``: the
        caller's own copy of ``reference`` at those times, computed once per process for each
        (function, n_ticks, ctrl_dt_s) when ``pure_reference`` - a sweep asks for the same one
        at every point."""
        if not self.pure_reference or n_ticks * 9 > TABLE_CACHE_MAX_NUMBERS:
            return _compute_table(self.reference, n_ticks, ctrl_dt_s)
        return _cached_table(self.reference, n_ticks, ctrl_dt_s).copy()


# Tables kept (Scenario.table): a few, and only short ones - 2^21 numbers = 16 MiB, ~230 s at
# 1 kHz (estimate: a sweep point runs seconds; longer runs compute theirs each time).
TABLE_CACHE_ENTRIES = 8
TABLE_CACHE_MAX_NUMBERS = 1 << 21


def _compute_table(reference: Callable[[Array], Array], n_ticks: int, ctrl_dt_s: float) -> Array:
    return reference(np.arange(n_ticks, dtype=np.float64) * ctrl_dt_s)


@functools.lru_cache(maxsize=TABLE_CACHE_ENTRIES)
def _cached_table(reference: Callable[[Array], Array], n_ticks: int, ctrl_dt_s: float) -> Array:
    """Kept read-only: the cache hands out copies only."""
    table = _compute_table(reference, n_ticks, ctrl_dt_s)
    table.flags.writeable = False
    return table


REGISTRY: dict[str, Scenario] = {}


def register(
    name: str,
    description: str,
    duration_s: float,
    payload_kg: float = 0.0,
    *,
    disturbance: Disturbance | None = None,
    outer_loop: OuterLoop | None = None,
    pure_reference: bool = True,
    rmse_warn_deg: tuple[float, float, float] | None = None,
) -> Callable[[Callable[[Array], Array]], Callable[[Array], Array]]:
    def wrap(fn: Callable[[Array], Array]) -> Callable[[Array], Array]:
        REGISTRY[name] = Scenario(
            name,
            description,
            duration_s,
            payload_kg,
            fn,
            disturbance,
            outer_loop,
            pure_reference,
            rmse_warn_deg,
        )
        return fn

    return wrap


# Scenarios outside REGISTRY, by name prefix: a layer above adds the reader of its names
# (fsarm_sim.studies.trajectory_file: "file:..." - a user's trajectory file).
RESOLVERS: dict[str, Callable[[str], Scenario]] = {}


def known(name: str) -> bool:
    """A registered name, or one a resolver reads (which may still refuse it)."""
    return name in REGISTRY or any(name.startswith(p) for p in RESOLVERS)


def get(name: str) -> Scenario:
    sc = REGISTRY.get(name)
    if sc is not None:
        return sc
    for prefix, resolve in RESOLVERS.items():
        if name.startswith(prefix):
            return resolve(name)
    raise ScenarioNotFoundError(
        f"unknown scenario '{name}'; registered scenarios: {', '.join(sorted(REGISTRY))}"
    )


# rmse_warn_deg of the built-in scenarios (estimates): about 5x what the default configuration
# gives on each joint (fig14-sine q3 0.41°, p2p-payload 0.065°, step-q3 1.55°, step-q2 q2 1.77°,
# collision-hit 1.24°, hand-guide 2.66°), at least 0.5°: far beyond what any catalogue shaft or
# transmission gives with the default gains (fig14-sine q3 0.001-0.49°), so a warning means a
# configuration that does not do what the scenario is for (e.g. a QA-Joint at sigma_cmd = 0.1:
# 8.0°).

FIG14_POSE_Q2 = (
    45.0 * DEG
)  # joint 2 holds 45 deg: the shaft is bent by phi_B = 45 deg (Fig. 7's bend)


@register(
    "fig14-sine",
    "Seed 000 Fig. 14: joint 3 follows 0-90 deg, period 4 s (peak 71 deg/s ~ nominal 75 deg/s); "
    "joints 1, 2 hold a pose that bends the shaft 45 deg",
    duration_s=10.0,
    rmse_warn_deg=(0.5, 0.5, 2.0),
)
def _fig14(t: Array) -> Array:
    return references.stack(
        (
            references.hold(t, 0.0),
            references.hold(t, FIG14_POSE_Q2),
            references.cosine_sweep(t, 0.0, 90.0 * DEG, 4.0),
        )
    )


@register(
    "p2p-payload",
    "Multi-joint point-to-point with the rated 15 kg payload: minimum-jerk moves out and back "
    "(2.5 s each) between a folded and a reaching pose",
    duration_s=7.0,
    payload_kg=15.0,
    rmse_warn_deg=(0.5, 0.5, 1.0),
)
def _p2p(t: Array) -> Array:
    a = (0.0, 15.0 * DEG, 60.0 * DEG)
    b = (60.0 * DEG, 60.0 * DEG, 20.0 * DEG)
    out = []
    for j in range(3):
        go = references.quintic(t, a[j], b[j], 0.5, 2.5)
        back = references.quintic(t, 0.0, a[j] - b[j], 4.0, 2.5)
        out.append((go[0] + back[0], go[1] + back[1], go[2] + back[2]))
    return references.stack((out[0], out[1], out[2]))


@register(
    "step-q3",
    "Joint-3 position step of 10 deg at t = 0.5 s (shaft bent 45 deg): torque and position loop response",
    duration_s=2.0,
    rmse_warn_deg=(0.5, 0.5, 6.0),
)
def _step_q3(t: Array) -> Array:
    return references.stack(
        (
            references.hold(t, 0.0),
            references.hold(t, FIG14_POSE_Q2),
            references.step(t, 30.0 * DEG, 40.0 * DEG, 0.5),
        )
    )


@register(
    "step-q2",
    "Joint-2 position step of 10 deg at t = 0.5 s: bending torque and its hysteresis seen by joint 2",
    duration_s=2.0,
    rmse_warn_deg=(0.5, 6.0, 2.0),
)
def _step_q2(t: Array) -> Array:
    return references.stack(
        (
            references.hold(t, 0.0),
            references.step(t, 30.0 * DEG, 40.0 * DEG, 0.5),
            references.hold(t, 30.0 * DEG),
        )
    )


# --- contact scenarios: scripted external forces on the flange (seed 004 Sec. V, Fig. 12) ---


def _raised_cosine_pulse(t: float, start: float, end: float, ramp: float, peak: float) -> float:
    """``peak`` between start and end, with raised-cosine ramps of ``ramp`` s at both ends."""
    if t <= start or t >= end:
        return 0.0
    edge = min(t - start, end - t)
    return peak if edge >= ramp else peak * 0.5 * (1.0 - math.cos(math.pi * edge / ramp))


# A hit: a raised-cosine (Hann) force pulse on the flange, against the motion (seed 004 Fig. 12a: a wooden
# stick hits the load plate). Estimate (the seed gives no force): 100 N peak over 50 ms, i.e.
# 40 N*m on joint 3 at the 0.4 m flange lever, well above a light touch and inside the joint's
# 160 N*m drive limit.
HIT_START_S = 1.2
HIT_DURATION_S = 0.05
HIT_PEAK_N = 100.0


def _hit_force(t: float) -> tuple[float, float, float]:
    """Flange frame: -x pushes joint 3 negative, against the upward sweep at t = 1.2 s."""
    f = _raised_cosine_pulse(
        t, HIT_START_S, HIT_START_S + HIT_DURATION_S, 0.5 * HIT_DURATION_S, 1.0
    )
    return (-HIT_PEAK_N * f, 0.0, 0.0)


@register(
    "collision-hit",
    "Joint 3 sweeps 0-90 deg as in fig14-sine and is hit on the flange at t = 1.2 s (100 N, "
    "50 ms); sensorless detection from the two encoders stops it (seed 004 Algorithm 1)",
    duration_s=3.0,
    disturbance=Disturbance("flange", _hit_force, (HIT_START_S, HIT_START_S + HIT_DURATION_S)),
    outer_loop=reaction_loop,
    rmse_warn_deg=(0.5, 0.5, 5.0),
)
def _collision_hit(t: Array) -> Array:
    return _fig14(t)


# Hand guiding: a hand pushes the flange perpendicular to link 3, lets go, pushes back, lets go,
# three times (seed 004 Sec. V-B: "the joint is dragged for three cycles. Every cycle includes both
# upward and downward actions"). Estimate (the seed gives no force or timing): 25 N, a light
# one-hand push (10 N*m on joint 3), 1 s each with 1 s between, 0.1 s raised-cosine onsets.
HAND_CYCLES = 3
HAND_PUSHES = tuple(
    (0.5 + 2.0 * i, 1.5 + 2.0 * i, 25.0 if i % 2 == 0 else -25.0) for i in range(2 * HAND_CYCLES)
)  # (start s, end s, force N along flange x)
HAND_RAMP_S = 0.1


def _hand_force(t: float) -> tuple[float, float, float]:
    f = sum(_raised_cosine_pulse(t, a, b, HAND_RAMP_S, p) for a, b, p in HAND_PUSHES)
    return (f, 0.0, 0.0)


@register(
    "hand-guide",
    "Hand guiding of joint 3 (seed 004 Algorithm 2): the arm holds a pose, a hand pushes the "
    "flange with 25 N for 1 s, lets go, pushes back, lets go, three cycles; joint 3 yields and "
    "then holds",
    duration_s=12.5,
    disturbance=Disturbance("flange", _hand_force, (HAND_PUSHES[0][0], HAND_PUSHES[-1][1])),
    outer_loop=hand_guiding_loop,
    rmse_warn_deg=(0.5, 2.0, 10.0),
)
def _hand_guide(t: Array) -> Array:
    return references.stack(
        (references.hold(t, 0.0), references.hold(t, FIG14_POSE_Q2), references.hold(t, 30.0 * DEG))
    )
