"""What the native callbacks need to know about MuJoCo and the kernels, without Numba.

The compiled callbacks (:mod:`fsarm_sim.engine.native`, and the prebuilt library of
:mod:`fsarm_sim.engine.native_lib`) read ``mjModel``/``mjData`` fields through raw pointers, so
they need each field's byte offset and width: :func:`struct_offsets` finds them (a tiny C probe
compiled with ``offsetof()`` against the headers in the ``mujoco`` wheel, cached per header set;
without a C compiler, a table recorded for the pinned MuJoCo version) and checks every entry
against the Python bindings on a probe model. :func:`source_key` names a build of the kernels:
a hash of every kernel source file, the callback module, the offsets and the versions of Numba,
MuJoCo and Python, so a cache is never stale after an edit. Nothing here imports Numba.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import importlib
import importlib.metadata
import inspect
import json
import os
import pkgutil
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Any

import mujoco

from fsarm_sim.errors import FsarmError
from fsarm_sim.kernels import dispatch, layout, physics

CACHE_ENV = "FSARM_CACHE_DIR"  # overrides the cache directory (default: $XDG_CACHE_HOME/fsarm-sim)


class NativeBackendError(FsarmError, RuntimeError):
    """The native backend cannot be built here (no C compiler, unknown MuJoCo struct layout)."""


def run_compiler(command: list[str], what: str) -> None:
    """Run the C compiler's ``command``; :class:`NativeBackendError` "``what`` failed" with the
    end of its output when it fails."""
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise NativeBackendError(f"{what} failed:\n{done.stderr[-2000:]}")


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


def compiler() -> str | None:
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
        run_compiler(
            [cc, "-std=c11", "-I", str(_include_dir()), str(c_file), "-o", str(exe)],
            f"compiling the MuJoCo struct-offset probe with '{cc}'",
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
    cc = compiler()
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


def kernel_modules() -> list[ModuleType]:
    """physics, the generated dispatch, every effects, controllers and transmissions module
    (what the callbacks run)."""
    mods: list[ModuleType] = [physics, layout, dispatch]
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


def source_key(offsets: dict[str, dict[str, list[int]]]) -> str:
    """Names one build of the kernels (see the module docstring)."""
    h = hashlib.sha256()
    for mod in sorted(kernel_modules(), key=lambda m: m.__name__):
        h.update(mod.__name__.encode())
        h.update(Path(inspect.getfile(mod)).read_bytes())
    h.update(Path(__file__).with_name("native.py").read_bytes())
    h.update(json.dumps(offsets, sort_keys=True).encode())
    numba_version = importlib.metadata.version("numba")
    h.update(f"{numba_version} {mujoco.__version__} {sys.version_info[:2]}".encode())
    return h.hexdigest()[:16]
