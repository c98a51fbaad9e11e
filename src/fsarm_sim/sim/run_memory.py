"""A run's memory, checked before it starts (it cannot fail half-way for memory) and mapped in
before the kernels write it.
"""

from __future__ import annotations

import ctypes
import functools
import mmap
import os
import sys
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import (
    InvalidParameterError,
)
from fsarm_sim.kernels import layout

Array = npt.NDArray[np.float64]

# One hour at a 10 us timestep: the most physics steps one run may take (about 15 min native).
MAX_STEPS = 360_000_000
# A run may use at most this share of the memory available when it starts (reference table,
# recorded rows and the columns made from them), so that it cannot fail half-way for memory.
MEMORY_SHARE = 0.5
SMALL_RUN_BYTES = 64 << 20  # a run this small is not checked against the free memory


def available_memory_bytes() -> int:
    """Memory the kernel says is available now (MemAvailable), else the physical memory."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (OSError, ValueError, AttributeError):
        return 8 << 30


# madvise(2) advice that faults a range in as writable in one call (Linux >= 5.14; <linux/mman.h>)
MADV_POPULATE_WRITE = 23
PAGE_BYTES = mmap.PAGESIZE  # this machine's page size (4 KiB on x86-64)


@functools.lru_cache(maxsize=1)
def _madvise() -> Callable[[int, int, int], int] | None:
    """libc's ``madvise``, or None where there is none to call (not Linux)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        fn = ctypes.CDLL(None, use_errno=True).madvise
    except (OSError, AttributeError):
        return None
    fn.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int)
    fn.restype = ctypes.c_int
    return fn


def resident_empty(shape: tuple[int, int]) -> Array:
    """``np.empty(shape)`` whose pages are already in memory (contents as undefined).

    A run's record array is fresh memory: left lazy, the kernel zeroes and maps each 4 KiB page
    at its first write, which happens while the loop drains rows into it - about 2.2 us a page
    on the 2-core development VM (1.5-1.9 ms of a 10 s run's 2.9 MB record: 6-8 % of its
    stepping time, more of a shorter run). One ``madvise(MADV_POPULATE_WRITE)`` over the array's
    whole pages maps them in a single call before stepping (about 1 us a page there; pages
    already resident, e.g. memory malloc reuses, cost next to nothing), so the process spends
    less time in all and the stepping wall time measures stepping. Where the call is not
    available (not Linux, a kernel older than 5.14) the array is returned as is: nothing changes
    but the time. The values written later are the same either way.
    """
    out = np.empty(shape)
    madvise = _madvise()
    if madvise is not None and out.nbytes >= 2 * PAGE_BYTES:
        addr = int(out.ctypes.data)
        start = -(-addr // PAGE_BYTES) * PAGE_BYTES  # whole pages inside the array only
        end = (addr + out.nbytes) // PAGE_BYTES * PAGE_BYTES
        if end > start:
            madvise(start, end - start, MADV_POPULATE_WRITE)  # a failure leaves the pages lazy
    return out


def check_run_size(
    duration_s: float, timestep_s: float, ctrl_dt_s: float, log_every_ticks: int, n_cols: int
) -> None:
    """Refuse, before anything is allocated, a run that takes too many steps or will not fit.

    Names the options to change. ``n_cols`` is the number of floats recorded per row.
    """
    n_steps = duration_s / timestep_s
    if n_steps > MAX_STEPS:
        raise InvalidParameterError(
            f"{duration_s:g} s at a timestep of {timestep_s:g} s is {n_steps:.3g} physics steps; "
            f"at most {MAX_STEPS:.3g} are allowed per run: raise --timestep or shorten --duration"
        )
    if duration_s < ctrl_dt_s * (1.0 - 1e-9):
        raise InvalidParameterError(
            f"duration {duration_s:g} s is shorter than one control period ({ctrl_dt_s:g} s): "
            "a run must span at least one control tick (lower --ctrl-dt or raise --duration)"
        )
    n_ticks = duration_s / ctrl_dt_s + 1.0
    rows = n_ticks / max(log_every_ticks, 1) if log_every_ticks > 0 else 0.0
    # reference table (the model holds it twice while compiling) + recorded rows + columns
    need = 8.0 * (3.0 * n_ticks * layout.REF_COLS + rows * (n_cols + 40))
    if need <= SMALL_RUN_BYTES:
        return  # fits anywhere: no need to ask the kernel (a sweep point asks ~0.15 ms)
    have = MEMORY_SHARE * available_memory_bytes()
    if need > have:
        raise InvalidParameterError(
            f"this run needs about {need / 2**30:.1f} GiB ({n_ticks:.3g} control ticks, "
            f"{rows:.3g} recorded rows) but only {have / 2**30:.1f} GiB may be used here: "
            "raise --log-every, raise --ctrl-dt or shorten --duration"
        )
