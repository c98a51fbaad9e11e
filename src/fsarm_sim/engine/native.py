"""Native callback backend: the :mod:`fsarm_sim.kernels.physics` kernels compiled with Numba as C callbacks.

The readable reference is :mod:`fsarm_sim.engine.callbacks` (Python callbacks). This module compiles the
*same* kernel functions - no second implementation - into three C functions and hands MuJoCo their
addresses, so no Python runs per physics step and ``mujoco.rollout`` threads run them in parallel:

* ``mjcb_passive(const mjModel*, mjData*)``  -> :func:`physics.passive_forces`
* ``mjcb_act_dyn(const mjModel*, const mjData*, int id)`` -> :func:`physics.state_rate`
  (state address ``m->actuator_actadr[id]``)
* ``mjcb_control(const mjModel*, mjData*)``  -> :func:`physics.control`
* ``mjcb_time(void)`` -> 0: MuJoCo's profiling clock, stopped while fsarm steps (see below)

MuJoCo (3.17) times every stage of every step into ``data.timer`` with its own clock when no
``mjcb_time`` is installed: two ``clock_gettime`` calls for each of about a dozen timed stages
of a step, 0.5 us of the arm's 2.5 us raw step on the development machine (``fsarm bench-speed`` shows raw MuJoCo with and without
them). fsarm reads no timer, so :func:`install` points ``mjcb_time`` at a function returning 0
(``data.timer`` then counts calls with zero durations; like every ``mjcb_*`` this is process-wide
while the callbacks are installed, so other models stepped meanwhile report zero durations too) -
unless a clock of your own is installed, which stays, as does its profiling. Timers never enter
the dynamics (``tests/test_native_clock.py``).

How the pure-Python kernels become compilable without editing them: every function defined in
``fsarm_sim.kernels.physics``, ``fsarm_sim.plant.effects.*`` and ``fsarm_sim.controllers.*`` is registered with
``numba.extending.register_jitable`` at import of this module. Called from Python they stay plain
Python; called from compiled code, Numba compiles their source. They are compiled without Numba's
reference counting (``_nrt=False``): they only ever get views of MuJoCo's own arrays, and the
refcount calls on every array argument made the kernels 3-30 times slower.

How the C callbacks read MuJoCo's structs: they receive raw ``mjModel*``/``mjData*`` pointers, so
they need the byte offset (and width) of each field they read. A tiny C file is compiled with
``offsetof()`` against the headers shipped in the ``mujoco`` wheel (``mujoco/include``), once per
header set, cached as JSON under the user cache directory. Without a C compiler, a table recorded
for the pinned MuJoCo version is used. Either way the offsets are checked against the Python
bindings (pointer values, sizes, ``time``) on a probe model before anything is installed.

Per-model parameters are found through the model pointer on every call, as in the Python path:
numeric ``fsarm_params`` (size ``layout.N_PARAMS``, ``layout.MAGIC`` at index 0) and numeric
``fsarm_ref``, looked up by name; a model without them, or with fewer than ``layout.N_USERDATA``
user data, is left alone (no forces, ``act_dyn`` returns 0). Differently configured models
therefore step correctly in one process and in ``mujoco.rollout`` threads.

Compiled code is cached (``numba`` ``cache=True``) in a directory whose name hashes the kernel
sources, the struct offsets and the Numba/MuJoCo versions, because Numba's own cache checks only
this file's time stamp and would keep stale code after an edit of ``physics.py``.
:data:`COMPILE_INFO` says how long the import took and whether the cache was hit.

Differences from the Python path, by design: callbacks installed before are not chained for
foreign models (native code cannot call Python callbacks without the GIL); a division by zero
yields inf/nan as in C instead of raising (``error_model="numpy"``).
"""

from __future__ import annotations

import contextlib
import inspect
import os
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import mujoco
from numba import carray, cfunc, njit, types
from numba.core import config as _numba_config
from numba.extending import intrinsic, register_jitable

from fsarm_sim.engine.native_abi import (
    cache_dir,
    kernel_modules,
    source_key,
    struct_offsets,
)
from fsarm_sim.kernels import layout, physics

OFFSETS = struct_offsets()

# module-level int constants: Numba freezes them into the compiled callbacks
M_NQ, M_NQ_SIZE = OFFSETS["model"]["nq"]
M_NV, M_NV_SIZE = OFFSETS["model"]["nv"]
M_NU, M_NU_SIZE = OFFSETS["model"]["nu"]
M_NA, M_NA_SIZE = OFFSETS["model"]["na"]
M_NC, M_NC_SIZE = OFFSETS["model"]["nC"]
M_NNUMERIC, M_NNUMERIC_SIZE = OFFSETS["model"]["nnumeric"]
M_NUSERDATA, M_NUSERDATA_SIZE = OFFSETS["model"]["nuserdata"]
M_NUMERIC_ADR = OFFSETS["model"]["numeric_adr"][0]
M_NUMERIC_SIZE = OFFSETS["model"]["numeric_size"][0]
M_NUMERIC_DATA = OFFSETS["model"]["numeric_data"][0]
M_NAME_NUMERICADR = OFFSETS["model"]["name_numericadr"][0]
M_NAMES = OFFSETS["model"]["names"][0]
M_ACTUATOR_ACTADR = OFFSETS["model"]["actuator_actadr"][0]
D_TIME = OFFSETS["data"]["time"][0]
D_QPOS = OFFSETS["data"]["qpos"][0]
D_QVEL = OFFSETS["data"]["qvel"][0]
D_ACT = OFFSETS["data"]["act"][0]
D_QFRC_PASSIVE = OFFSETS["data"]["qfrc_passive"][0]
D_QFRC_BIAS = OFFSETS["data"]["qfrc_bias"][0]
D_M = OFFSETS["data"]["M"][0]
D_USERDATA = OFFSETS["data"]["userdata"][0]
D_CTRL = OFFSETS["data"]["ctrl"][0]
PARAMS_NAME = tuple(
    layout.PARAMS_NAME.encode() + b"\0"
)  # compared byte by byte, terminator included
REF_NAME = tuple(layout.REF_NAME.encode() + b"\0")


# ------------------------------------------------------------------ make the kernels compilable


def _register_kernels(mods: list[ModuleType]) -> None:
    for mod in mods:
        for _, fn in inspect.getmembers(mod, inspect.isfunction):
            if fn.__module__ == mod.__name__ and not getattr(fn, "_fsarm_jitable", False):
                register_jitable(error_model="numpy", _nrt=False)(fn)
                fn._fsarm_jitable = True  # type: ignore[attr-defined]


_MODULES = kernel_modules()
_register_kernels(_MODULES)


def _source_key() -> str:
    return source_key(OFFSETS)


@contextlib.contextmanager
def _numba_cache_in(path: Path) -> Iterator[None]:
    """Numba reads CACHE_DIR when a cached function is created: point it at ``path`` meanwhile."""
    config: Any = _numba_config
    old = config.CACHE_DIR
    config.CACHE_DIR = str(path)
    try:
        yield
    finally:
        config.CACHE_DIR = old


# ------------------------------------------------------------------ raw memory access


def _addr_typing(typingctx: Any, ptr: Any) -> Any:
    """void* -> intp."""

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.ptrtoint(args[0], context.get_value_type(types.intp))

    return types.intp(ptr), codegen


_addr: Any = intrinsic(_addr_typing)


def _pointer_intrinsic(dtype: Any) -> Any:
    """intp -> dtype* (an address read from a struct becomes a typed pointer)."""

    def as_pointer(typingctx: Any, addr: Any) -> Any:
        if not isinstance(addr, types.Integer):
            return None
        rtype = types.CPointer(dtype)

        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            return builder.inttoptr(args[0], context.get_value_type(rtype))

        return rtype(addr), codegen

    return intrinsic(as_pointer)


_f64p = _pointer_intrinsic(types.float64)
_i64p = _pointer_intrinsic(types.int64)
_i32p = _pointer_intrinsic(types.int32)
_u8p = _pointer_intrinsic(types.uint8)


@njit(inline="always", error_model="numpy")
def _ptr(base: int, off: int) -> int:
    """The pointer field at byte offset ``off`` of a struct, as an address."""
    return _i64p(base + off)[0]


@njit(inline="always", error_model="numpy")
def _int(base: int, off: int, size: int) -> int:
    """An int (4 bytes) or mjtSize (8 bytes) field."""
    if size == 8:
        return int(_i64p(base + off)[0])
    return int(_i32p(base + off)[0])


@njit(inline="always", error_model="numpy")
def _f64_array(base: int, off: int, n: int) -> Any:
    """The mjtNum* field at ``off`` as an array of ``n`` values (no copy)."""
    return carray(_f64p(_ptr(base, off)), (n,))


@njit(inline="always", error_model="numpy")
def _name_is(names: Any, adr: int, name: Any) -> bool:
    for j in range(len(name)):  # noqa: SIM110  (a plain loop compiles in Numba)
        if names[adr + j] != name[j]:
            return False
    return True


@njit(inline="always", error_model="numpy")
def _find(ma: int) -> tuple[int, int, int]:
    """(fsarm_params address, fsarm_ref address, fsarm_ref size) in numeric_data; -1: not fsarm."""
    n = _int(ma, M_NNUMERIC, M_NNUMERIC_SIZE)
    adr = _i32p(_ptr(ma, M_NUMERIC_ADR))
    size = _i32p(_ptr(ma, M_NUMERIC_SIZE))
    name_adr = _i32p(_ptr(ma, M_NAME_NUMERICADR))
    names = _u8p(_ptr(ma, M_NAMES))
    data = _f64p(_ptr(ma, M_NUMERIC_DATA))
    p = -1
    r = -1
    r_size = 0
    # Names are unique per object type in a compiled model, so each is found once: the cheap size
    # and MAGIC tests go before the name comparison, and the scan stops once both are found (a
    # third of this lookup's time, which runs on every callback call, 7 a step).
    for i in range(n):
        if (
            p < 0
            and size[i] == layout.N_PARAMS
            and data[adr[i]] == layout.MAGIC
            and _name_is(names, name_adr[i], PARAMS_NAME)
        ):
            p = adr[i]
        elif r < 0 and _name_is(names, name_adr[i], REF_NAME):
            r = adr[i]
            r_size = size[i]
        if p >= 0 and r >= 0:
            break
    if p < 0 or r < 0 or _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE) < layout.N_USERDATA:
        return -1, -1, 0
    return p, r, r_size


# ------------------------------------------------------------------ the callbacks


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / f".write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError:
        return False
    return True


# Only ever cache into the source-keyed directory: if it cannot be written, Numba would fall back
# to __pycache__ next to this file, where an edit of physics.py would not invalidate the code.
_KEYED_DIR = cache_dir() / f"numba-{_source_key()}"
_CACHE_PATH: Path | None = _KEYED_DIR if _writable(_KEYED_DIR) else None
_OPTIONS: dict[str, Any] = {"cache": _CACHE_PATH is not None, "error_model": "numpy"}
_t0 = time.perf_counter()

with _numba_cache_in(_CACHE_PATH or Path(tempfile.gettempdir())):

    @cfunc(types.void(types.voidptr, types.voidptr), **_OPTIONS)
    def _passive_cb(m: Any, d: Any) -> None:
        ma = _addr(m)
        da = _addr(d)
        p, _, _ = _find(ma)
        if p < 0:
            return
        nq = _int(ma, M_NQ, M_NQ_SIZE)
        nv = _int(ma, M_NV, M_NV_SIZE)
        na = _int(ma, M_NA, M_NA_SIZE)
        prm = carray(_f64p(_ptr(ma, M_NUMERIC_DATA) + 8 * p), (layout.N_PARAMS,))
        userdata = _f64_array(da, D_USERDATA, _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE))
        physics.passive_forces(
            prm,
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_ACT, na),
            _f64_array(da, D_QFRC_PASSIVE, nv),
            userdata,
        )

    @cfunc(types.float64(types.voidptr, types.voidptr, types.int32), **_OPTIONS)
    def _act_dyn_cb(m: Any, d: Any, actuator_id: int) -> float:
        ma = _addr(m)
        da = _addr(d)
        p, _, _ = _find(ma)
        if p < 0:
            return 0.0
        nq = _int(ma, M_NQ, M_NQ_SIZE)
        nv = _int(ma, M_NV, M_NV_SIZE)
        na = _int(ma, M_NA, M_NA_SIZE)
        prm = carray(_f64p(_ptr(ma, M_NUMERIC_DATA) + 8 * p), (layout.N_PARAMS,))
        act_adr = _i32p(_ptr(ma, M_ACTUATOR_ACTADR))[actuator_id]
        return physics.state_rate(
            prm,
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_ACT, na),
            int(act_adr),
            _f64_array(da, D_USERDATA, _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE)),
        )

    @cfunc(types.void(types.voidptr, types.voidptr), **_OPTIONS)
    def _control_cb(m: Any, d: Any) -> None:
        ma = _addr(m)
        da = _addr(d)
        p, r, r_size = _find(ma)
        if p < 0:
            return
        nq = _int(ma, M_NQ, M_NQ_SIZE)
        nv = _int(ma, M_NV, M_NV_SIZE)
        base = _ptr(ma, M_NUMERIC_DATA)
        physics.control(
            carray(_f64p(base + 8 * p), (layout.N_PARAMS,)),
            carray(_f64p(base + 8 * r), (r_size,)),
            _f64p(da + D_TIME)[0],
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_ACT, _int(ma, M_NA, M_NA_SIZE)),
            _f64_array(da, D_QFRC_BIAS, nv),
            _f64_array(da, D_M, _int(ma, M_NC, M_NC_SIZE)),
            _f64_array(da, D_USERDATA, _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE)),
            _f64_array(da, D_CTRL, _int(ma, M_NU, M_NU_SIZE)),
        )

    @cfunc(types.float64(), **_OPTIONS)
    def _time_cb() -> float:
        """mjcb_time: the stopped clock (MuJoCo's stage timers cost ~20 % of a raw step)."""
        return 0.0


@dataclass(frozen=True)
class CompileInfo:
    seconds: float  # wall time of compiling or loading the callbacks (CFUNCS) at import
    cache_hits: int  # len(CFUNCS): all loaded from the cache; 0: all compiled now
    cache_path: str  # "" when the cache directory is not writable (compiled on every import)


COMPILE_INFO = CompileInfo(
    seconds=time.perf_counter() - _t0,
    cache_hits=(
        _passive_cb.cache_hits
        + _act_dyn_cb.cache_hits
        + _control_cb.cache_hits
        + _time_cb.cache_hits
    ),
    cache_path=str(_CACHE_PATH) if _CACHE_PATH is not None else "",
)

# the compiled callbacks (engine.native_lib rebuilds these very functions into its library)
CFUNCS = (_passive_cb, _act_dyn_cb, _control_cb, _time_cb)
# ctypes function pointers (cached on the CFunc objects; module globals keep them alive)
PASSIVE = _passive_cb.ctypes
ACT_DYN = _act_dyn_cb.ctypes
CONTROL = _control_cb.ctypes
TIME = _time_cb.ctypes


def install_clock(stopped: Any) -> None:
    """Point ``mjcb_time`` at ``stopped`` (a clock returning 0) unless a clock of the user's is
    installed (theirs stays, with MuJoCo's profiling). (native_lib.Library does the same.)"""
    if mujoco.get_mjcb_time() is None:
        mujoco.set_mjcb_time(stopped)


def uninstall_clock(stopped: Any) -> None:
    """Remove ``stopped`` from ``mjcb_time`` (MuJoCo's own timers come back), if it is there."""
    if mujoco.get_mjcb_time() is stopped:
        mujoco.set_mjcb_time(None)


def install() -> None:
    """Install the native callbacks process-wide (idempotent). Replaces whatever was installed,
    except a clock of the user's in ``mjcb_time`` (see the module docstring)."""
    mujoco.set_mjcb_passive(PASSIVE)
    mujoco.set_mjcb_act_dyn(ACT_DYN)
    mujoco.set_mjcb_control(CONTROL)
    install_clock(TIME)


def installed() -> bool:
    """Whether the three MuJoCo callbacks currently are the native ones (the clock aside)."""
    return (
        mujoco.get_mjcb_passive() is PASSIVE
        and mujoco.get_mjcb_act_dyn() is ACT_DYN
        and mujoco.get_mjcb_control() is CONTROL
    )


def uninstall() -> None:
    """Remove the native callbacks (only if they are the ones installed)."""
    if mujoco.get_mjcb_passive() is PASSIVE:
        mujoco.set_mjcb_passive(None)
    if mujoco.get_mjcb_act_dyn() is ACT_DYN:
        mujoco.set_mjcb_act_dyn(None)
    if mujoco.get_mjcb_control() is CONTROL:
        mujoco.set_mjcb_control(None)
    uninstall_clock(TIME)
