"""The native callbacks as a prebuilt shared library: no Numba at run time.

Importing Numba and loading its cached code is most of the start-up of a short run (about 0.5 s of
a 1 s ``fsarm run``). So the three callbacks are also built once as a shared library - the very
functions :mod:`fsarm_sim.engine.native` compiles, taken through Numba's LLVM pipeline and
emitted as position-independent machine code for this CPU, linked by the C compiler into
``<cache>/lib-<key>/libfsarm_callbacks.so`` - and later processes load that library with
``ctypes`` and hand its three functions to MuJoCo without importing Numba (with the stopped
clock for ``mjcb_time``, written in C there). ``<key>`` is
:func:`fsarm_sim.engine.native_abi.source_key` plus the CPU and this module's own source, so an
edit of any kernel or of the build, another MuJoCo struct layout or another machine builds a new
library.

The build needs Numba, llvmlite and a C compiler; it runs once per key, from
:func:`fsarm_sim.engine.callbacks.active` after the first native run (``FSARM_PREBUILT=0``
switches the library off) or from ``python -m fsarm_sim.engine.native_lib``
(``scripts/setup_env.sh`` does this). The code paths that would raise a Python exception from a
compiled kernel (there are none by construction: ``error_model="numpy"``, no reference counting)
call Numba's runtime helpers; the library links stubs for them that abort with a message instead
of continuing silently. ``tests/test_native_lib.py`` checks that the library steps the arm bit for
bit as the Numba-compiled callbacks do.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco

from fsarm_sim.engine.native_abi import (
    NativeBackendError,
    cache_dir,
    run_compiler,
    source_key,
    struct_offsets,
)

ENV = "FSARM_PREBUILT"  # "0": never load or build the library (the Numba path then runs)
LIB_NAME = "libfsarm_callbacks.so"
NAMES = ("passive", "act_dyn", "control", "time")

# Numba runtime helpers referenced only from the exception paths of the compiled wrappers
_STUBS_C = r"""
#include <stdio.h>
#include <stdlib.h>
static void fsarm_fail(const char *what) {
  fprintf(stderr, "fsarm: a compiled kernel reached %s (an exception path that the kernels never"
                  " take by design); aborting rather than continuing with a wrong state\n", what);
  abort();
}
#define STUB(name) void name(void) { fsarm_fail(#name); }
STUB(NRT_Free)
STUB(NRT_MemInfo_call_dtor)
STUB(numba_do_raise)
STUB(numba_gil_ensure)
STUB(numba_gil_release)
STUB(numba_runtime_build_excinfo_struct)
STUB(numba_unpickle)

/* mjcb_time: the stopped clock (engine.native's _time_cb, returning 0), here in plain C. MuJoCo
   calls it twice for each of about a dozen timed stages of every step; Numba's cfunc wrapper
   around its own version costs a call and a status check more each time (1.5 % of a lean
   native step, measured in interleaved blocks of 2000 steps on the 2-core development VM). */
double fsarm_stopped_clock(void) { return 0.0; }
"""
STOPPED_CLOCK = "fsarm_stopped_clock"  # the symbol of the clock above


def enabled() -> bool:
    return os.environ.get(ENV, "1") != "0"


def _cpu() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith(("model name", "flags")):
                    return line.strip()
    except OSError:
        pass
    return "unknown-cpu"


@functools.lru_cache(maxsize=1)
def library_dir() -> Path:
    """Where this build of the kernels lives (see the module docstring; computed once: it hashes
    every kernel source and checks the struct offsets)."""
    key = source_key(struct_offsets())
    # the CPU, and this module: how the library is built (its C code, the link) names it too
    build = hashlib.sha256(_cpu().encode() + Path(__file__).read_bytes()).hexdigest()[:8]
    return cache_dir() / f"lib-{key}-{build}"


@dataclass(frozen=True)
class Library:
    """The loaded library: the callbacks as ctypes function pointers MuJoCo accepts, with the
    same ``install``/``installed``/``uninstall`` and ``PASSIVE``/``ACT_DYN``/``CONTROL``/``TIME``
    as :mod:`fsarm_sim.engine.native` (the callbacks module uses either; ``TIME`` is the stopped
    clock, installed in ``mjcb_time`` unless a clock of the user's is there)."""

    path: Path
    handle: Any
    PASSIVE: Any
    ACT_DYN: Any
    CONTROL: Any
    TIME: Any

    def install(self) -> None:
        mujoco.set_mjcb_passive(self.PASSIVE)
        mujoco.set_mjcb_act_dyn(self.ACT_DYN)
        mujoco.set_mjcb_control(self.CONTROL)
        if mujoco.get_mjcb_time() is None:
            mujoco.set_mjcb_time(self.TIME)

    def installed(self) -> bool:
        return (
            mujoco.get_mjcb_passive() is self.PASSIVE
            and mujoco.get_mjcb_act_dyn() is self.ACT_DYN
            and mujoco.get_mjcb_control() is self.CONTROL
        )

    def uninstall(self) -> None:
        if mujoco.get_mjcb_passive() is self.PASSIVE:
            mujoco.set_mjcb_passive(None)
        if mujoco.get_mjcb_act_dyn() is self.ACT_DYN:
            mujoco.set_mjcb_act_dyn(None)
        if mujoco.get_mjcb_control() is self.CONTROL:
            mujoco.set_mjcb_control(None)
        if mujoco.get_mjcb_time() is self.TIME:
            mujoco.set_mjcb_time(None)


_PASSIVE_T = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)
_ACT_DYN_T = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int)
_CONTROL_T = _PASSIVE_T
_TIME_T = ctypes.CFUNCTYPE(ctypes.c_double)


def load() -> Library | None:
    """The prebuilt library of the current kernels, or None (not built yet, switched off, or it
    cannot be loaded here)."""
    if not enabled():
        return None
    d = library_dir()
    path, meta = d / LIB_NAME, d / "symbols.json"
    if not path.exists() or not meta.exists():
        return None
    try:
        symbols = json.loads(meta.read_text())
        handle = ctypes.CDLL(str(path))
        fns = [
            t(int(ctypes.cast(getattr(handle, symbols[n]), ctypes.c_void_p).value or 0))
            for n, t in zip(NAMES, (_PASSIVE_T, _ACT_DYN_T, _CONTROL_T, _TIME_T), strict=True)
        ]
    except (OSError, ValueError, KeyError, AttributeError):
        return None
    return Library(path, handle, *fns)


def build() -> Path:
    """Compile the callbacks with Numba (uncached), emit them as PIC machine code and link the
    library; returns its path. Raises NativeBackendError where that cannot be done here."""
    from fsarm_sim.engine.native_abi import compiler

    cc = compiler()
    if cc is None:
        raise NativeBackendError("no C compiler to link the prebuilt callbacks library")
    import llvmlite.binding as llvm
    from numba import cfunc

    from fsarm_sim.engine import native

    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    target = llvm.Target.from_default_triple()
    tm = target.create_target_machine(
        cpu=llvm.get_host_cpu_name(),
        features=llvm.get_host_cpu_features().flatten(),
        opt=3,
        reloc="pic",
        codemodel="default",
    )
    d = library_dir()
    d.mkdir(parents=True, exist_ok=True)
    symbols: dict[str, str] = {}
    with tempfile.TemporaryDirectory(prefix="fsarm-lib-", dir=d) as tmp:
        objects = []
        cfuncs: tuple[Any, ...] = native.CFUNCS
        for name, cb in zip(NAMES, cfuncs, strict=True):
            if name == "time":  # the C clock of the stubs file (the same function: returns 0)
                symbols[name] = STOPPED_CLOCK
                continue
            fresh: Any = cfunc(cb._sig, cache=False, error_model="numpy")(cb._pyfunc)
            obj = Path(tmp) / f"{name}.o"
            obj.write_bytes(tm.emit_object(fresh._library._final_module))
            objects.append(str(obj))
            symbols[name] = fresh.native_name
        stubs = Path(tmp) / "stubs.c"
        stubs.write_text(_STUBS_C)
        out = Path(tmp) / LIB_NAME
        run_compiler(
            [cc, "-shared", "-fPIC", "-O2", "-o", str(out), *objects, str(stubs), "-lm"],
            "linking the callbacks library",
        )
        meta = Path(tmp) / "symbols.json"
        meta.write_text(json.dumps(symbols))
        os.replace(out, d / LIB_NAME)
        os.replace(meta, d / "symbols.json")
    return d / LIB_NAME


LOCK_NAME = "building.lock"
LOCK_STALE_S = 900.0  # a lock older than this is a build that died: another may start


def _claim_build() -> bool:
    """Take the build lock of this key; False if a live build holds it. (Two processes racing
    here may both build: each replaces the files atomically, so the result is the same.)"""
    lock = library_dir() / LOCK_NAME
    try:
        if lock.exists() and time.time() - lock.stat().st_mtime < LOCK_STALE_S:
            return False
        lock.parent.mkdir(parents=True, exist_ok=True)
        lock.write_text(str(os.getpid()))
    except OSError:
        return False
    return True


def build_in_background() -> None:
    """Start ``python -m fsarm_sim.engine.native_lib`` detached (it outlives this process), so
    that the next processes load the library - unless a build of this key is already running
    (one build at a time per key: a lock file in its folder, removed when the build ends)."""
    if not _claim_build():
        return
    with contextlib.suppress(OSError):
        subprocess.Popen(
            [sys.executable, "-m", "fsarm_sim.engine.native_lib", "--locked"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )


def main(argv: list[str]) -> None:
    """``python -m fsarm_sim.engine.native_lib``: build the library unless it is built.
    ``--locked``: started by :func:`build_in_background`, which holds the lock for it."""
    locked = "--locked" in argv
    if not locked and not _claim_build():
        print("a build of this library is already running")
        return
    try:
        found = load()
        print(found.path if found is not None else build())
    finally:
        with contextlib.suppress(OSError):
            (library_dir() / LOCK_NAME).unlink()


if __name__ == "__main__":
    with contextlib.suppress(KeyboardInterrupt):
        main(sys.argv[1:])
