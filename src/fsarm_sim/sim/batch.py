"""Batches of differently configured runs on every core: ``mujoco.rollout`` in worker threads.

``mujoco.rollout`` steps with the GIL released; with the native callbacks
(:mod:`fsarm_sim.engine.native`) no Python runs per step, so runs in different threads go in parallel
(the Python callbacks also work here, but they take the GIL and serialise).

Why each run keeps its *own* ``MjData``, and one ``rollout`` call per run: rollout restores only
``mjSTATE_FULLPHYSICS`` at the start of a rollout, not ``userdata``, where the controllers keep
their memory (integrators, held outputs, tick counter). Several rollouts sharing one ``MjData`` -
a list of models with fewer datas, or the rollout thread pool, which hands a worker's data to
whatever chunk it picks up - would start the second run with the first run's controller memory.
Giving every run its own data (the :class:`~fsarm_sim.sim.simulation.Simulation`'s) makes a batch
run bit-for-bit the same as stepping that simulation alone, whatever the number of workers.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
from mujoco import rollout

from fsarm_sim.engine import callbacks
from fsarm_sim.errors import InvalidParameterError, whole_number
from fsarm_sim.executors import MAX_WORKERS
from fsarm_sim.sim.simulation import (
    MAX_STEPS,
    MEMORY_SHARE,
    Simulation,
    available_memory_bytes,
    raise_on_warning,
)

Array = npt.NDArray[np.float64]
FULLPHYSICS = mujoco.mjtState.mjSTATE_FULLPHYSICS
# Every user-input bit: with no control array rollout then leaves ctrl, applied forces, mocap and
# equality activations as the data holds them (it resets the ones not named here).
KEEP_INPUTS = int(mujoco.mjtState.mjSTATE_USER)


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@dataclass(frozen=True)
class BatchResult:
    wall_s: float  # wall time of the whole batch
    n_runs: int
    n_steps: int  # physics steps per run
    workers: int  # runs stepped at the same time
    states: list[Array] | None  # per run, (n_steps, nstate) mjSTATE_FULLPHYSICS after each step

    @property
    def steps_per_s(self) -> float:
        """Physics steps of all runs together per wall-clock second."""
        return self.n_runs * self.n_steps / self.wall_s if self.wall_s > 0 else float("inf")


def _roll(sim: Simulation, n_steps: int, record: bool) -> Array | None:
    m, d = sim.model, sim.data
    state0 = np.empty((1, mujoco.mj_stateSize(m, FULLPHYSICS)))
    mujoco.mj_getState(m, d, state0[0], FULLPHYSICS)
    warmstart0 = d.qacc_warmstart.copy()[None, :]  # continue exactly as mj_step would
    out = np.empty((1, n_steps, state0.shape[1])) if record else None
    rollout.rollout(
        [m],  # skip_checks: lists, contiguous float64 arrays of the final shapes
        [d],
        state0,
        None,
        control_spec=KEEP_INPUTS,
        skip_checks=True,
        nstep=n_steps,
        initial_warmstart=warmstart0,
        state=out,
        sensordata=None,
        chunk_size=None,
    )
    return out[0] if out is not None else None


def run_batch(
    sims: Sequence[Simulation], n_steps: int, workers: int | None = None, record: bool = False
) -> BatchResult:
    """Advance every simulation by ``n_steps`` physics steps, ``workers`` runs at a time.

    Each simulation continues from its current state and keeps its controller memory, exactly as
    ``Simulation.run`` would; afterwards its ``data`` holds the final state. All simulations must
    use the same callback backend (callbacks are process-global). ``record=True`` returns every
    run's FULLPHYSICS state after each step. Raises SimulationWarningError if any run warned.
    """
    if not sims:
        raise InvalidParameterError("a batch needs at least one simulation")
    whole_number(n_steps, "n_steps", 1, MAX_STEPS)  # the cap of one run's steps
    if len({id(s) for s in sims}) != len(sims):
        raise InvalidParameterError("a simulation appears twice in the batch; each needs its own")
    backends = {s.backend for s in sims}
    if len(backends) != 1:
        raise InvalidParameterError(
            f"all simulations of a batch must use one callback backend, got {sorted(backends)}"
        )
    n_workers = available_cores() if workers is None else workers
    whole_number(n_workers, "workers", 1, MAX_WORKERS)
    if record:  # every run's state after every step, allocated up front
        need = 8.0 * len(sims) * n_steps * mujoco.mj_stateSize(sims[0].model, FULLPHYSICS)
        have = MEMORY_SHARE * available_memory_bytes()
        if need > have:
            raise InvalidParameterError(
                f"recording {len(sims)} run(s) of {n_steps} steps needs about "
                f"{need / 2**30:.1f} GiB but only {have / 2**30:.1f} GiB may be used here: "
                "fewer steps or runs, or record=False"
            )
    n_workers = min(n_workers, len(sims))
    with callbacks.active(backends.pop()), ThreadPoolExecutor(max_workers=n_workers) as pool:
        start = time.perf_counter()
        states = list(pool.map(lambda s: _roll(s, n_steps, record), sims))
        wall = time.perf_counter() - start
    for s in sims:
        raise_on_warning(s.data)
    return BatchResult(
        wall_s=wall,
        n_runs=len(sims),
        n_steps=n_steps,
        workers=n_workers,
        states=[x for x in states if x is not None] if record else None,
    )
