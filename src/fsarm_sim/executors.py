"""Run many independent tasks (sweep points, bench runs) on one machine or on a Dask cluster.

``run_tasks(fn, tasks, executor=..., workers=..., on_done=...)`` calls the picklable, module-level
``fn(task) -> dict`` for every task and hands each :class:`Outcome` to ``on_done`` *in the calling
process* as soon as it finishes (the sweep runner stores it there, so only one process writes the
results store).

* ``local`` with ``workers == 1``: in this process, one task after the other.
* ``local`` with ``workers > 1`` (default: every core this process may use): a
  ``concurrent.futures.ProcessPoolExecutor``. Its workers are forked from this process when that
  is safe - Linux, and this process runs no other thread at that moment (so no lock another
  thread holds is copied locked) - after ``prepare()`` ran here once: they start in milliseconds
  with its imports and loaded native kernels, where a spawned worker pays a whole interpreter
  start, the imports and the kernel load (about 0.5 s each, as long as a 12-point sweep of 10 s
  runs). Otherwise (another thread is running, a progress bar say, or ``FSARM_START_METHOD=spawn``)
  they are spawned. A forked worker never touches what it inherited (the results store stays
  with this process; workers leave through ``os._exit``, so nothing inherited is closed or
  flushed twice). At most ``2 * workers`` tasks are in flight, so Ctrl-C stops quickly and huge
  sweeps do not queue everything at once.
* ``threads``: ``workers`` threads of this process, tasks in parallel. No interpreter is started
  and nothing is imported twice, so a small sweep of short runs is not eaten by worker start-up;
  the native callbacks step with the GIL released (``mujoco.mj_step``), so the runs' stepping goes
  in parallel while their Python parts (building a model, metrics) take turns.
* ``dask``: Dask distributed. ``scheduler=None`` starts a ``LocalCluster`` of ``workers``
  single-threaded worker processes on this machine; ``scheduler="tcp://host:8786"`` uses a running
  cluster (its workers must have fsarm-sim installed, the same version for the store to mean
  anything). ``processes=False`` runs the workers as threads of this process (tests).

MuJoCo's callbacks are process-global; :func:`fsarm_sim.engine.callbacks.active` installs them
for every thread that steps, counted under a lock, so runs in threads of one process
are safe together. Tasks of the ``local`` pool and of Dask's thread workers still run under
:data:`PROCESS_LOCK` (one at a time per process); the ``threads`` executor does not.
"""

from __future__ import annotations

import contextlib
import os
import socket
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import (
    FIRST_COMPLETED,
    Future,
    ProcessPoolExecutor,
    ThreadPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from multiprocessing import get_all_start_methods, get_context
from multiprocessing.context import BaseContext
from typing import Any

from fsarm_sim.errors import FsarmError, whole_number

EXECUTORS: tuple[str, ...] = ("local", "threads", "dask")
PROCESS_LOCK = threading.Lock()
TaskFn = Callable[[Any], dict[str, Any]]
# most workers (processes or threads) one run may start: each costs memory (a forked process holds
# a simulator, ~100 MB) while the machines fsarm runs on have tens of cores, not hundreds
MAX_WORKERS = 256
START_METHOD_ENV = "FSARM_START_METHOD"  # "spawn": never fork the local pool's workers


class ExecutorError(FsarmError, RuntimeError):
    """Bad executor settings, or the executor could not be started or reached."""


@dataclass(frozen=True)
class Outcome:
    """One finished task: its result, or the error that stopped it."""

    index: int
    task: Any
    result: dict[str, Any] | None
    error: str | None
    wall_s: float
    host: str


def available_cores() -> int:
    """Cores this process may run on (CPU affinity where the OS has it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def call_task(fn: TaskFn, index: int, task: Any, serial: bool = True) -> Outcome:
    """Run one task (``serial``: one at a time per process), catching its exception into the
    outcome."""
    start = time.perf_counter()
    with PROCESS_LOCK if serial else contextlib.nullcontext():
        try:
            result = fn(task)
            error = None
        except FsarmError as exc:
            result, error = None, f"{type(exc).__name__}: {exc}"
        except Exception as exc:
            result = None
            error = f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=6)}"
    return Outcome(index, task, result, error, time.perf_counter() - start, socket.gethostname())


def check_workers(workers: int | None, what: str = "workers") -> int | None:
    """``workers`` (None: every core) within 1 .. :data:`MAX_WORKERS`, else ExecutorError."""
    if workers is None:
        return None
    return whole_number(workers, what, 1, MAX_WORKERS, ExecutorError)


def _check(executor: str, workers: int | None, scheduler: str | None) -> int:
    if executor not in EXECUTORS:
        raise ExecutorError(f"executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    workers = check_workers(workers)
    if scheduler is not None and executor != "dask":
        raise ExecutorError("a scheduler address only makes sense with executor 'dask'")
    return workers if workers is not None else available_cores()


def run_tasks(
    fn: TaskFn,
    tasks: Sequence[Any],
    *,
    executor: str = "local",
    workers: int | None = None,
    scheduler: str | None = None,
    processes: bool = True,
    on_done: Callable[[Outcome], None] | None = None,
    prepare: Callable[[], None] | None = None,
    on_start: Callable[[], None] | None = None,
) -> list[Outcome]:
    """Run ``fn`` on every task; return the outcomes in completion order.

    ``on_done`` is called for each outcome as it arrives (in this process). An interrupt
    (Ctrl-C) cancels what has not started and re-raises; finished outcomes were already handed
    to ``on_done``. ``prepare`` (imports, library loads the tasks need) runs here once before
    the local pool forks its workers, so that they inherit it (not called when the workers are
    spawned or no pool is used). ``on_start`` is called once the workers run (a progress bar
    started there runs no thread while the pool forks).
    """
    n_workers = _check(executor, workers, scheduler)
    out: list[Outcome] = []

    def deliver(o: Outcome) -> None:
        out.append(o)
        if on_done is not None:
            on_done(o)

    if not tasks:
        if on_start is not None:
            on_start()
        return out
    if executor == "local" and n_workers > 1:
        for o in _run_pool(fn, tasks, n_workers, prepare, on_start):
            deliver(o)
        return out
    if on_start is not None:
        on_start()
    if executor == "dask":
        for o in _run_dask(fn, tasks, n_workers, scheduler, processes):
            deliver(o)
    elif executor == "threads":
        for o in _run_threads(fn, tasks, n_workers):
            deliver(o)
    else:
        for i, task in enumerate(tasks):
            deliver(call_task(fn, i, task))
    return out


PARENT_POLL_S = 0.5  # how often a pool worker checks that the sweep that started it still runs


def _exit_with_parent(parent_pid: int) -> None:
    """Pool-worker initializer: end this worker when the process that started it is gone
    (``kill -9`` of a sweep must not leave orphaned workers computing on): a daemon thread checks
    the parent id every PARENT_POLL_S (an orphan is re-parented, so the id changes)."""

    def watch() -> None:
        while True:
            if os.getppid() != parent_pid:
                os._exit(1)
            time.sleep(PARENT_POLL_S)

    threading.Thread(target=watch, name="fsarm-parent-watch", daemon=True).start()


def start_method() -> str:
    """How the local pool starts its workers now: "fork" where that is safe (see the module
    docstring), else "spawn"."""
    if os.environ.get(START_METHOD_ENV, "") == "spawn":
        return "spawn"
    if not sys.platform.startswith("linux") or "fork" not in get_all_start_methods():
        return "spawn"  # fork only on Linux (macOS: fork is unsafe with system frameworks)
    return "fork" if threading.active_count() == 1 else "spawn"


def _pool_context(prepare: Callable[[], None] | None) -> BaseContext:
    if start_method() == "fork" and prepare is not None:
        prepare()  # may start a thread (it should not): check again
    return get_context(start_method())


def _run_pool(
    fn: TaskFn,
    tasks: Sequence[Any],
    n_workers: int,
    prepare: Callable[[], None] | None = None,
    on_start: Callable[[], None] | None = None,
) -> Iterator[Outcome]:
    pool = ProcessPoolExecutor(
        max_workers=n_workers,
        mp_context=_pool_context(prepare),
        initializer=_exit_with_parent,
        initargs=(os.getpid(),),
    )
    pending: set[Future[Outcome]] = set()
    next_i = 0
    started = on_start is None
    try:
        while next_i < len(tasks) or pending:
            while next_i < len(tasks) and len(pending) < 2 * n_workers:
                # (forked workers all start at the first submit, before the pool's thread)
                pending.add(pool.submit(call_task, fn, next_i, tasks[next_i]))
                next_i += 1
            if not started and on_start is not None:
                started = True
                on_start()
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                try:
                    yield fut.result()
                except BrokenProcessPool as exc:
                    raise ExecutorError(
                        "a worker process died abruptly (killed, out of memory, or started from "
                        "a script without an `if __name__ == '__main__':` guard, which the "
                        f"'spawn' start method needs): {exc}"
                    ) from exc
    finally:
        pool.shutdown(wait=not pending, cancel_futures=True)


def _run_threads(fn: TaskFn, tasks: Sequence[Any], n_workers: int) -> Iterator[Outcome]:
    """``n_workers`` threads, at most ``2 * n_workers`` tasks in flight (Ctrl-C stops quickly:
    queued tasks are cancelled, running ones finish)."""
    pool = ThreadPoolExecutor(max_workers=n_workers, thread_name_prefix="fsarm-task")
    pending: set[Future[Outcome]] = set()
    next_i = 0
    try:
        while next_i < len(tasks) or pending:
            while next_i < len(tasks) and len(pending) < 2 * n_workers:
                pending.add(pool.submit(call_task, fn, next_i, tasks[next_i], False))
                next_i += 1
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                yield fut.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _run_dask(
    fn: TaskFn,
    tasks: Sequence[Any],
    n_workers: int,
    scheduler: str | None,
    processes: bool,
) -> Iterator[Outcome]:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as exc:  # pragma: no cover - dask is a dependency
        raise ExecutorError(
            f"executor 'dask' needs dask[distributed] installed ({exc}); "
            "pip install 'dask[distributed]' or use --executor local"
        ) from exc
    cluster = None
    try:
        if scheduler is None:
            cluster = LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=processes,
                dashboard_address=None,
            )
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout="20s")
    except (OSError, TimeoutError) as exc:
        if cluster is not None:
            cluster.close()
        where = scheduler or "a local cluster"
        raise ExecutorError(f"cannot start or reach the Dask scheduler at {where}: {exc}") from exc
    futures = []
    try:
        futures = client.map(
            call_task,
            [fn] * len(tasks),
            list(range(len(tasks))),
            list(tasks),
            pure=False,
        )
        for fut in as_completed(futures):
            try:
                outcome = fut.result()
            except Exception as exc:  # task errors are caught in call_task: this is the cluster
                raise ExecutorError(
                    f"the Dask cluster lost a task ({type(exc).__name__}: {exc}); finished points "
                    "are kept, rerun to continue"
                ) from exc
            yield outcome
    finally:
        if futures:
            client.cancel(futures)
        client.close()
        if cluster is not None:
            cluster.close()
