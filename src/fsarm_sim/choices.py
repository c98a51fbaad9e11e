"""The fixed sets of choices the ``fsarm`` command offers, as string enums (``str(Integrator.RK4) == "RK4"``), so that ``--help`` lists
them and the command accepts them in any case (``--integrator rk4``).

The library itself takes plain strings (``SimConfig(integrator="RK4")``); an enum's values are
exactly the strings its library function accepts. They are written out here, not read from the
modules that own them, because those import MuJoCo, Numba or the transmission kernels, which the
command must not load before it needs them (start-up time); ``tests/test_choices.py`` checks that
each enum equals its owner's set.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from enum import Enum, StrEnum
from typing import Any


class Integrator(StrEnum):
    """MuJoCo's integrators (``fsarm_sim.engine.model.INTEGRATORS``)."""

    EULER = "Euler"
    RK4 = "RK4"
    IMPLICIT = "implicit"
    IMPLICITFAST = "implicitfast"


class Backend(StrEnum):
    """The callback path: compiled kernels or the pure-Python reference."""

    NATIVE = "native"
    PYTHON = "python"


class TimeseriesFormat(StrEnum):
    """A run's time-series file (``fsarm_sim.records.timeseries.FORMATS``)."""

    CSV = "csv"
    PARQUET = "parquet"


class FigureFormat(StrEnum):
    """Static figure files (matplotlib's writers used by ``fsarm figures``)."""

    PNG = "png"
    SVG = "svg"
    PDF = "pdf"


class Transmission(StrEnum):
    """Joint 3's transmissions (``fsarm_sim.plant.transmissions.names()``)."""

    FLEXIBLE_SHAFT = "flexible-shaft"
    RTCA = "rtca"
    QA_JOINT = "qa-joint"
    MAGNETIC_SPRING = "magnetic-spring"
    TENDON_SHEATH = "tendon-sheath"


class Executor(StrEnum):
    """Where a sweep's points run: ``auto`` or one of ``fsarm_sim.executors.EXECUTORS``."""

    AUTO = "auto"
    LOCAL = "local"
    THREADS = "threads"
    DASK = "dask"


class Pool(StrEnum):
    """Where a campaign's runs go (``fsarm_sim.executors.EXECUTORS``)."""

    LOCAL = "local"
    THREADS = "threads"
    DASK = "dask"


class ShaftKind(StrEnum):
    """Which stiffness a shaft is selected for: series (eq. 3) or parallel (eq. 4)."""

    SERIES = "series"
    PARALLEL = "parallel"


class Setup(StrEnum):
    """A measured record's setup (``fsarm_sim.records.sidecar.SETUPS``)."""

    SERIES_BENCH = "series_bench"
    PARALLEL_BENCH = "parallel_bench"
    ARM = "arm"


class BenchLoad(StrEnum):
    """The series bench's load: blocked output or a free inertia."""

    BLOCKED = "blocked"
    INERTIA = "inertia"


class BenchTrajectory(StrEnum):
    """A synthetic bench's input (``fsarm_sim.discrepancy.synth.TRAJECTORIES``)."""

    CHIRP = "chirp"
    MULTISINE = "multisine"
    TRIANGLE = "triangle"
    RANDOM = "random"
    STEPS = "steps"
    BIASED_SINE = "biased_sine"


class StiffnessAdjust(StrEnum):
    """Seed 002's stiffness adjustment of a throw, eq. 20
    (``fsarm_sim.studies.qa_joint_experiments.ADJUST_MODES``)."""

    NONE = "none"
    DRIVE = "drive"
    IDEAL = "ideal"


class Controller(StrEnum):
    """Joint 3's controller structures (``fsarm_sim.engine.model.CONTROLLERS``)."""

    DEFAULT = "default"
    HYSTERESIS_COMP = "hysteresis-comp"
    DOB = "dob"
    PAPER_PID = "paper-pid"


class Scenario(StrEnum):
    """The registered scenarios (``fsarm_sim.sim.scenarios.REGISTRY``; importing it costs ~0.7 s
    of a command's start, so they are listed here and a test keeps the two equal)."""

    FIG14_SINE = "fig14-sine"
    P2P_PAYLOAD = "p2p-payload"
    STEP_Q3 = "step-q3"
    STEP_Q2 = "step-q2"
    COLLISION_HIT = "collision-hit"
    HAND_GUIDE = "hand-guide"


class UncertaintyController(StrEnum):
    """What the controller knows of a sampled shaft
    (``fsarm_sim.studies.uncertainty.CONTROLLER_MODES``)."""

    NOMINAL = "nominal"
    MATCHED = "matched"


def values(choice: type[Enum]) -> tuple[str, ...]:
    """An enum's values, in order (what ``--help`` lists)."""
    return tuple(str(c.value) for c in choice)


def plain_options(options: Mapping[str, Any], names: Iterable[str]) -> dict[str, Any]:
    """The command's option values the library takes (``names``): a choice as its plain
    string, a repeated option as a tuple; None (not given) and other names left out."""
    wanted = set(names)
    values: dict[str, Any] = {}
    for name, value in options.items():
        if name not in wanted or value is None:
            continue
        if isinstance(value, list | tuple):
            value = tuple(value)
        elif isinstance(value, str):
            value = str(value)  # a StrEnum as its plain value
        values[name] = value
    return values
