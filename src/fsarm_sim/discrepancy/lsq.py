"""Bounded linear least squares on tall problems (one row per sample), reduced to k x k first.

``|A x - y|^2 = |R x - Q^T y|^2 + |y|^2 - |Q^T y|^2`` with ``A = Q R``: the bounded solve (BVLS)
runs on the triangle, the same minimiser at a fraction of the cost (BVLS on 30 000 rows took
~10 ms a call, most of a diagnosis). ``R`` is the Cholesky factor of ``A^T A`` and
``Q^T y = R^-T A^T y`` where that is well conditioned (``cond(R)`` below :data:`CHOLESKY_COND`:
the normal equations' error in x, ~cond(R)^2 eps, stays below 1e-8), a thin QR of ``A``
otherwise (nearly dependent columns, e.g. look-alike candidates).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.linalg import solve_triangular
from scipy.optimize import lsq_linear

FloatArray = npt.NDArray[np.float64]

CHOLESKY_COND = 1e4  # cond(R) above which the triangle comes from a QR of A


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
    """``argmin |a x - y|`` with ``lower <= x <= upper`` (BVLS on the reduced problem)."""
    if a.shape[0] <= a.shape[1]:  # not tall: nothing to reduce
        r, qty = a, y
    else:
        r, qty = triangle(a, y)
    res = lsq_linear(r, qty, bounds=(lower, upper), method="bvls")
    return np.asarray(res.x, dtype=np.float64)
