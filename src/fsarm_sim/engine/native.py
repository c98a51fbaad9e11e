"""Native callback backend: the :mod:`fsarm_sim.kernels.physics` kernels compiled with Numba as C callbacks.

The readable reference is :mod:`fsarm_sim.engine.callbacks` (Python callbacks). This module compiles the
*same* kernel functions - no second implementation - into three C functions and hands MuJoCo their
addresses, so no Python runs per physics step and ``mujoco.rollout`` threads run them in parallel:

* ``mjcb_passive(const mjModel*, mjData*)``  -> :func:`physics.passive_forces`
* ``mjcb_act_dyn(const mjModel*, const mjData*, int id)`` -> :func:`physics.state_rate`
  (state address ``m->actuator_actadr[id]``)
* ``mjcb_control(const mjModel*, mjData*)``  -> :func:`physics.control`

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
import ctypes
import hashlib
import importlib
import inspect
import json
import os
import pkgutil
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import mujoco
import numba
from numba import carray, cfunc, njit, types
from numba.core import config as _numba_config
from numba.extending import intrinsic, register_jitable

from fsarm_sim.errors import FsarmError
from fsarm_sim.kernels import dispatch, physics
from fsarm_sim.kernels import layout as L

CACHE_ENV = "FSARM_CACHE_DIR"  # overrides the cache directory (default: $XDG_CACHE_HOME/fsarm-sim)


class NativeBackendError(FsarmError, RuntimeError):
    """The native backend cannot be built here (no C compiler, unknown MuJoCo struct layout)."""


# ------------------------------------------------------------------ struct offsets

MODEL_FIELDS = (
    "nq",
    "nv",
    "nu",
    "na",
    "nC",
    "nnumeric",
    "nuserdata",
    "numeric_adr",
    "numeric_size",
    "numeric_data",
    "name_numericadr",
    "names",
    "actuator_actadr",
)
DATA_FIELDS = ("time", "qpos", "qvel", "act", "qfrc_passive", "qfrc_bias", "M", "userdata", "ctrl")

# Recorded with the offsetof() probe below against the mujoco 3.17.0 wheel's headers on x86-64
# Linux; used only when no C compiler is found, and only after _verify_offsets() has checked every
# entry against the Python bindings of the running MuJoCo (so a different layout is refused).
_RECORDED: dict[str, dict[str, dict[str, list[int]]]] = {
    "3.17.0": {
        "model": {
            "nq": [0, 8],
            "nv": [8, 8],
            "nu": [16, 8],
            "na": [40, 8],
            "nC": [120, 8],
            "nnumeric": [512, 8],
            "nuserdata": [736, 8],
            "numeric_adr": [5216, 8],
            "numeric_size": [5224, 8],
            "numeric_data": [5232, 8],
            "name_numericadr": [5504, 8],
            "names": [5544, 8],
            "actuator_actadr": [4816, 8],
        },
        "data": {
            "time": [160648, 8],
            "qpos": [160688, 8],
            "qvel": [160696, 8],
            "act": [160704, 8],
            "qfrc_passive": [161344, 8],
            "qfrc_bias": [161296, 8],
            "M": [161184, 8],
            "userdata": [160800, 8],
            "ctrl": [160736, 8],
        },
    }
}

_PROBE_C = """
#include <stddef.h>
#include <stdio.h>
#include <mujoco/mujoco.h>
#define F(S, f) printf("%s\\"%s\\": [%zu, %zu]", first ? "" : ", ", #f, \\
                       offsetof(S, f), sizeof(((S*)0)->f)); first = 0;
int main(void) {
  int first = 1;
  printf("{\\"model\\": {");
  MODEL_FIELDS
  first = 1;
  printf("}, \\"data\\": {");
  DATA_FIELDS
  printf("}}\\n");
  return 0;
}
"""


def cache_dir() -> Path:
    """Where compiled artefacts go: $FSARM_CACHE_DIR, else $XDG_CACHE_HOME/fsarm-sim, ~/.cache/..."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "fsarm-sim"


def _include_dir() -> Path:
    return Path(mujoco.__file__).resolve().parent / "include"


def _headers_digest() -> str:
    h = hashlib.sha256(mujoco.__version__.encode())
    inc = _include_dir() / "mujoco"
    for p in sorted(inc.glob("*.h")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def _compiler() -> str | None:
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name and shutil.which(name):
            return name
    return None


def _offsets_from_compiler(cc: str) -> dict[str, dict[str, list[int]]]:
    src = _PROBE_C.replace(
        "MODEL_FIELDS", " ".join(f"F(mjModel, {f})" for f in MODEL_FIELDS)
    ).replace("DATA_FIELDS", " ".join(f"F(mjData, {f})" for f in DATA_FIELDS))
    with tempfile.TemporaryDirectory(prefix="fsarm-offsets-") as tmp:
        c_file, exe = Path(tmp) / "probe.c", Path(tmp) / "probe"
        c_file.write_text(src)
        build = subprocess.run(
            [cc, "-std=c11", "-I", str(_include_dir()), str(c_file), "-o", str(exe)],
            capture_output=True,
            text=True,
            check=False,
        )
        if build.returncode != 0:
            raise NativeBackendError(
                f"compiling the MuJoCo struct-offset probe with '{cc}' failed:\n{build.stderr[-2000:]}"
            )
        out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    parsed: dict[str, dict[str, list[int]]] = json.loads(out)
    return parsed


def struct_offsets() -> dict[str, dict[str, list[int]]]:
    """{"model"|"data": {field: [byte offset, byte size]}} for this MuJoCo, verified.

    Tried in turn: the cached table of these headers, a fresh offsetof() probe (then cached), the
    table recorded for this MuJoCo version. The first that passes :func:`_verify_offsets` wins.
    """
    path = cache_dir() / f"offsets-{mujoco.__version__}-{_headers_digest()}.json"
    problems: list[str] = []
    try:
        cached: Any = json.loads(path.read_text())
    except (OSError, ValueError):
        cached = None
    if cached is not None:
        try:
            _verify_offsets(cached)
            return cached
        except NativeBackendError as exc:
            problems.append(f"cached table {path}: {exc}")
    cc = _compiler()
    if cc is not None:
        try:
            probed = _offsets_from_compiler(cc)
            _verify_offsets(probed)
            with contextlib.suppress(OSError):
                path.parent.mkdir(parents=True, exist_ok=True)
                tmp = path.with_suffix(f".tmp{os.getpid()}")
                tmp.write_text(json.dumps(probed))
                tmp.replace(path)
            return probed
        except (NativeBackendError, OSError, subprocess.SubprocessError, ValueError) as exc:
            problems.append(f"offsetof() probe with '{cc}': {exc}")
    else:
        problems.append("no C compiler found (cc, gcc, clang or $CC)")
    if mujoco.__version__ in _RECORDED:
        try:
            _verify_offsets(_RECORDED[mujoco.__version__])
            return _RECORDED[mujoco.__version__]
        except NativeBackendError as exc:
            problems.append(f"recorded table: {exc}")
    else:
        problems.append(f"no recorded table for mujoco {mujoco.__version__}")
    raise NativeBackendError(
        "cannot find the mjModel/mjData field offsets the native callbacks need ("
        + "; ".join(problems)
        + "). Install a C compiler (it is used once per MuJoCo version) or use backend='python'"
    )


_PROBE_XML = """
<mujoco>
  <worldbody><body><joint name="a" axis="0 0 1"/><geom size=".1" mass="1"/>
    <body pos="0 0 .3"><joint name="b" axis="0 1 0"/><geom size=".1" mass="1"/>
      <body pos="0 0 .3"><joint name="c" axis="1 0 0"/><geom size=".1" mass="1"/></body>
    </body></body></worldbody>
  <actuator><motor joint="a"/><general joint="b" dyntype="user" gainprm="0"/>
    <general joint="c" dyntype="user" gainprm="0"/><motor joint="c"/></actuator>
  <custom><numeric name="first" data="1 2 3"/><numeric name="second" data="4 5"/></custom>
  <size nuserdata="7"/>
</mujoco>
"""


def _read_int(addr: int, size: int) -> int:
    return int((ctypes.c_int64 if size == 8 else ctypes.c_int32).from_address(addr).value)


def _read_ptr(addr: int) -> int:
    return int(ctypes.c_void_p.from_address(addr).value or 0)


def _verify_offsets(offsets: dict[str, dict[str, list[int]]]) -> None:
    """Check every offset against the Python bindings on a probe model; raise if any disagrees."""
    try:
        mo, do = offsets["model"], offsets["data"]
        missing = [f for f in MODEL_FIELDS if f not in mo] + [f for f in DATA_FIELDS if f not in do]
    except (KeyError, TypeError) as exc:
        raise NativeBackendError(f"malformed struct-offset table: {exc!r}") from exc
    if missing:
        raise NativeBackendError(f"struct-offset table lacks {missing}")
    m = mujoco.MjModel.from_xml_string(_PROBE_XML)
    d = mujoco.MjData(m)
    d.time = 0.123456789
    ma, da = int(m._address), int(d._address)
    bad: list[str] = []
    for f in ("nq", "nv", "nu", "na", "nC", "nnumeric", "nuserdata"):
        off, size = mo[f]
        if size not in (4, 8) or _read_int(ma + off, size) != int(getattr(m, f)):
            bad.append(f"mjModel.{f}")
    for f in ("numeric_adr", "numeric_size", "numeric_data", "name_numericadr", "actuator_actadr"):
        off, size = mo[f]
        if size != 8 or _read_ptr(ma + off) != getattr(m, f).ctypes.data:
            bad.append(f"mjModel.{f}")
    off, size = mo["names"]
    names = _read_ptr(ma + off) if size == 8 else 0
    if not names or ctypes.string_at(names + int(m.name_numericadr[1])) != b"second":
        bad.append("mjModel.names")
    for f in DATA_FIELDS:
        off, size = do[f]
        if f == "time":
            if size != 8 or ctypes.c_double.from_address(da + off).value != d.time:
                bad.append("mjData.time")
        elif size != 8 or _read_ptr(da + off) != getattr(d, f).ctypes.data:
            bad.append(f"mjData.{f}")
    if bad:
        raise NativeBackendError(
            f"offsets disagree with mujoco {mujoco.__version__}'s Python bindings for "
            + ", ".join(bad)
        )


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
PARAMS_NAME = tuple(L.PARAMS_NAME.encode() + b"\0")  # compared byte by byte, terminator included
REF_NAME = tuple(L.REF_NAME.encode() + b"\0")


# ------------------------------------------------------------------ make the kernels compilable


def _kernel_modules() -> list[ModuleType]:
    """physics, the generated dispatch, every effects, controllers and transmissions module
    (what the callbacks run)."""
    mods: list[ModuleType] = [physics, L, dispatch]
    for pkg_name in (
        "fsarm_sim.plant.effects",
        "fsarm_sim.controllers",
        "fsarm_sim.plant.transmissions",
    ):
        pkg = importlib.import_module(pkg_name)
        mods.append(pkg)
        for info in pkgutil.iter_modules(pkg.__path__):
            mods.append(importlib.import_module(f"{pkg_name}.{info.name}"))
    return mods


def _register_kernels(mods: list[ModuleType]) -> None:
    for mod in mods:
        for _, fn in inspect.getmembers(mod, inspect.isfunction):
            if fn.__module__ == mod.__name__ and not getattr(fn, "_fsarm_jitable", False):
                register_jitable(error_model="numpy", _nrt=False)(fn)
                fn._fsarm_jitable = True  # type: ignore[attr-defined]


_MODULES = _kernel_modules()
_register_kernels(_MODULES)


def _source_key() -> str:
    h = hashlib.sha256()
    for mod in sorted(_MODULES, key=lambda m: m.__name__):
        h.update(mod.__name__.encode())
        h.update(Path(inspect.getfile(mod)).read_bytes())
    h.update(Path(__file__).read_bytes())
    h.update(json.dumps(OFFSETS, sort_keys=True).encode())
    h.update(f"{numba.__version__} {mujoco.__version__} {sys.version_info[:2]}".encode())
    return h.hexdigest()[:16]


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
    for i in range(n):
        if _name_is(names, name_adr[i], PARAMS_NAME):
            if size[i] == L.N_PARAMS and data[adr[i]] == L.MAGIC:
                p = adr[i]
        elif _name_is(names, name_adr[i], REF_NAME):
            r = adr[i]
            r_size = size[i]
    if p < 0 or r < 0 or _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE) < L.N_USERDATA:
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
        prm = carray(_f64p(_ptr(ma, M_NUMERIC_DATA) + 8 * p), (L.N_PARAMS,))
        userdata = _f64_array(da, D_USERDATA, _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE))
        physics.passive_forces(
            prm,
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_ACT, na),
            _f64_array(da, D_QFRC_PASSIVE, nv),
            userdata[L.U_LOG :],
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
        prm = carray(_f64p(_ptr(ma, M_NUMERIC_DATA) + 8 * p), (L.N_PARAMS,))
        act_adr = _i32p(_ptr(ma, M_ACTUATOR_ACTADR))[actuator_id]
        return physics.state_rate(
            prm,
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_ACT, na),
            int(act_adr),
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
            carray(_f64p(base + 8 * p), (L.N_PARAMS,)),
            carray(_f64p(base + 8 * r), (r_size,)),
            _f64p(da + D_TIME)[0],
            _f64_array(da, D_QPOS, nq),
            _f64_array(da, D_QVEL, nv),
            _f64_array(da, D_QFRC_BIAS, nv),
            _f64_array(da, D_M, _int(ma, M_NC, M_NC_SIZE)),
            _f64_array(da, D_USERDATA, _int(ma, M_NUSERDATA, M_NUSERDATA_SIZE)),
            _f64_array(da, D_CTRL, _int(ma, M_NU, M_NU_SIZE)),
        )


@dataclass(frozen=True)
class CompileInfo:
    seconds: float  # wall time of compiling or loading the three callbacks at import
    cache_hits: int  # 3: all loaded from the cache; 0: all compiled now
    cache_path: str  # "" when the cache directory is not writable (compiled on every import)


COMPILE_INFO = CompileInfo(
    seconds=time.perf_counter() - _t0,
    cache_hits=_passive_cb.cache_hits + _act_dyn_cb.cache_hits + _control_cb.cache_hits,
    cache_path=str(_CACHE_PATH) if _CACHE_PATH is not None else "",
)

# ctypes function pointers (cached on the CFunc objects; module globals keep them alive)
PASSIVE = _passive_cb.ctypes
ACT_DYN = _act_dyn_cb.ctypes
CONTROL = _control_cb.ctypes


def install() -> None:
    """Install the native callbacks process-wide (idempotent). Replaces whatever was installed."""
    mujoco.set_mjcb_passive(PASSIVE)
    mujoco.set_mjcb_act_dyn(ACT_DYN)
    mujoco.set_mjcb_control(CONTROL)


def installed() -> bool:
    """Whether the three MuJoCo callbacks currently are the native ones."""
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
