"""Bounded linear least squares on tall problems (one row per sample), reduced to k x k first.

``|A x - y|^2 = |R x - Q^T y|^2 + |y|^2 - |Q^T y|^2`` with ``A = Q R``: the bounded solve (BVLS)
runs on the triangle, the same minimiser at a fraction of the cost (BVLS on 30 000 rows took
~10 ms a call, most of a diagnosis). ``R`` is the Cholesky factor of ``A^T A`` and
``Q^T y = R^-T A^T y`` where that is well conditioned (``cond(R)`` below :data:`CHOLESKY_COND`:
the normal equations' error in x, ~cond(R)^2 eps, stays below 1e-8), a thin QR of ``A``
otherwise (nearly dependent columns, e.g. look-alike candidates).

:func:`full_problem` switches the reduction off for a block (BVLS on the full problem, as 0.4.0
did; ``scripts/bench_diagnose.py`` times both paths). It is scoped, not a module global: it
holds in the thread (and asyncio task) that entered it and in contexts copied from it
(``contextvars.copy_context``), never in other threads. Threads started inside it do not see it
unless they run in a copied context: ``ThreadPoolExecutor`` workers do not (Python 3.11), so
their ``bounded`` calls solve the reduced problem. The diagnosis calls :func:`bounded` only in the
calling thread (``arm_fit``'s worker threads run simulations only), and the benchmark's 0.4.0
path runs its simulations one after the other (``arm_fit.simulation_threads(1)``) anyway.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

import numpy as np
import numpy.typing as npt
from scipy.linalg import solve_triangular
from scipy.optimize import lsq_linear

FloatArray = npt.NDArray[np.float64]

CHOLESKY_COND = 1e4  # cond(R) above which the triangle comes from a QR of A
# True inside full_problem(): BVLS on the full problem, as 0.4.0 did
_FULL_PROBLEM: ContextVar[bool] = ContextVar("fsarm_lsq_full_problem", default=False)


@contextmanager
def full_problem() -> Iterator[None]:
    """For the block, :func:`bounded` solves the full tall problem instead of its triangle
    (0.4.0's path, for benchmarks; module docstring for which threads see it). Nests; the
    previous setting comes back on exit, also on an exception."""
    token = _FULL_PROBLEM.set(True)
    try:
        yield
    finally:
        _FULL_PROBLEM.reset(token)


def reduces() -> bool:
    """Whether :func:`bounded` reduces tall problems here (False inside :func:`full_problem`)."""
    return not _FULL_PROBLEM.get()


def triangle(a: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(R, Q^T y) of the least-squares problem ``a x ~ y`` (module docstring)."""
    try:
        r = np.asarray(np.linalg.cholesky(a.T @ a).T, dtype=np.float64)  # upper
        if np.linalg.cond(r) < CHOLESKY_COND:
            return r, np.asarray(solve_triangular(r.T, a.T @ y, lower=True), dtype=np.float64)
    except np.linalg.LinAlgError:
        pass
    q, r = np.linalg.qr(a, mode="reduced")
    return np.asarray(r, dtype=np.float64), np.asarray(q.T @ y, dtype=np.float64)


def bounded(a: FloatArray, y: FloatArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """``argmin |a x - y|`` with ``lower <= x <= upper`` (BVLS on the reduced problem; on the
    full one inside :func:`full_problem`)."""
    if not reduces() or a.shape[0] <= a.shape[1]:  # not tall: nothing to reduce
        r, qty = a, y
    else:
        r, qty = triangle(a, y)
    res = lsq_linear(r, qty, bounds=(lower, upper), method="bvls")
    return np.asarray(res.x, dtype=np.float64)
