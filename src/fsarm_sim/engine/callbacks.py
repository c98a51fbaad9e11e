"""Plugin-free injection: the shaft and controllers enter MuJoCo through process-global callbacks.

* ``mjcb_passive``  adds the shaft's generalized forces to ``qfrc_passive``;
* ``mjcb_act_dyn``  gives the rates of the internal states in ``data.act``;
* ``mjcb_control``  runs the controllers on their clock ticks and writes ``data.ctrl``.

The callbacks are shared by every model in the process, so they carry no parameters themselves:
each call finds its parameters in the model it receives (``fsarm_params``) and its states in the
data (``userdata``, ``act``). Models that are not fsarm models are passed to whatever callback was
installed before (or left alone). This module is the readable Python reference path; the native
path installs compiled versions of the same :mod:`fsarm_sim.kernels.physics` kernels.
"""

from __future__ import annotations

import contextlib
import importlib
import sys
import threading
import weakref
from collections.abc import Iterator
from types import ModuleType
from typing import Any, Literal

import mujoco

from fsarm_sim.errors import CallbackConflictError, InvalidParameterError
from fsarm_sim.kernels import layout, physics

Backend = Literal["python", "native"]
# The compiled callbacks are the default everywhere (about 13x the Python path's speed, bit for bit
# the same physics); the Python callbacks stay the readable reference (`backend="python"`,
# `--backend python`). Where the native ones cannot be compiled, `active` says so once and runs
# the Python path.
DEFAULT_BACKEND: Backend = "native"

_Cache = tuple[int, int, int, int] | None  # params start/end, ref start/end
_cache: weakref.WeakKeyDictionary[Any, _Cache] = weakref.WeakKeyDictionary()
_previous: dict[str, Any] = {}
_installed = False


def _slices(m: mujoco.MjModel) -> _Cache:
    try:
        return _cache[m]
    except KeyError:
        pass
    out: _Cache = None
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, layout.PARAMS_NAME)
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, layout.REF_NAME)
    if (
        i >= 0
        and j >= 0
        and m.numeric_size[i] == layout.N_PARAMS
        and m.numeric_data[m.numeric_adr[i]] == layout.MAGIC
    ):
        a, b = int(m.numeric_adr[i]), int(m.numeric_adr[j])
        out = (a, a + layout.N_PARAMS, b, b + int(m.numeric_size[j]))
    if out is not None:  # never cache a miss: a model's parameters may be written after compiling
        _cache[m] = out
    return out


def _passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    s = _slices(m)
    if s is None:
        prev = _previous.get("passive")
        if prev is not None:
            prev(m, d)
        return
    physics.passive_forces(
        m.numeric_data[s[0] : s[1]], d.qpos, d.qvel, d.act, d.qfrc_passive, d.userdata
    )


def _act_dyn(m: mujoco.MjModel, d: mujoco.MjData, actuator_id: int) -> float:
    s = _slices(m)
    if s is None:
        prev = _previous.get("act_dyn")
        return float(prev(m, d, actuator_id)) if prev is not None else 0.0
    return physics.state_rate(
        m.numeric_data[s[0] : s[1]],
        d.qpos,
        d.qvel,
        d.act,
        int(m.actuator_actadr[actuator_id]),
        d.userdata,
    )


def _control(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    s = _slices(m)
    if s is None:
        prev = _previous.get("control")
        if prev is not None:
            prev(m, d)
        return
    physics.control(
        m.numeric_data[s[0] : s[1]],
        m.numeric_data[s[2] : s[3]],
        d.time,
        d.qpos,
        d.qvel,
        d.act,
        d.qfrc_bias,
        d.M,
        d.userdata,
        d.ctrl,
    )


# --- installation: one process-wide owner at a time, counted -------------------------------
# MuJoCo's callbacks are process globals. Several runs (threads) may step at once: the first to
# enter ``active`` installs fsarm's callbacks and saves what was there, the others only count
# themselves in, and the last to leave restores what was saved. A thread asking for the other
# backend meanwhile gets CallbackConflictError (both paths compute the same physics, but a silent
# swap would make "python" a lie). ``suspended`` (compiling) waits until no other thread steps
# with the Python callbacks, so it never switches a running run's callbacks off.
_lock = threading.RLock()
_free = threading.Condition(_lock)
_holders: dict[int, int] = {}  # thread id -> nesting depth inside active()
_backend: str | None = None
_saved: tuple[Any, Any, Any, Any] | None = None


def _current() -> tuple[Any, Any, Any, Any]:
    """passive, act_dyn, control and the clock (``mjcb_time``: the native path stops MuJoCo's
    stage timers while it steps, see :mod:`fsarm_sim.engine.native`)."""
    return (
        mujoco.get_mjcb_passive(),
        mujoco.get_mjcb_act_dyn(),
        mujoco.get_mjcb_control(),
        mujoco.get_mjcb_time(),
    )


def _restore(cbs: tuple[Any, Any, Any, Any] | None) -> None:
    cbs = cbs or (None, None, None, None)
    mujoco.set_mjcb_passive(cbs[0])
    mujoco.set_mjcb_act_dyn(cbs[1])
    mujoco.set_mjcb_control(cbs[2])
    mujoco.set_mjcb_time(cbs[3])


def _ours(cb: Any) -> bool:
    if cb is None or cb in (_passive, _act_dyn, _control):
        return True
    sources = [sys.modules.get("fsarm_sim.engine.native"), *_native]
    return any(
        src is not None and cb is getattr(src, n, None)
        for src in sources
        for n in ("PASSIVE", "ACT_DYN", "CONTROL", "TIME")
    )


@contextlib.contextmanager
def suspended() -> Iterator[None]:
    """No fsarm callbacks inside the block, for compiling models (MuJoCo's compiler runs
    mj_forward on models that are not finished yet, and mujoco 3.17's bindings fail on any Python
    callback then). Waits while another thread steps with the Python callbacks; with the native
    ones installed (safe on unfinished models) it leaves them in place."""
    me = threading.get_ident()
    with _free:
        while _backend == "python" and any(t != me for t in _holders):
            _free.wait()
        if _backend == "native":
            yield
            return
        saved = _current()
        _restore(None)
        try:
            yield
        finally:
            _restore(saved)


def _set_python() -> None:
    mujoco.set_mjcb_passive(_passive)
    mujoco.set_mjcb_act_dyn(_act_dyn)
    mujoco.set_mjcb_control(_control)


def install_python() -> None:
    """Install the Python reference callbacks process-wide (idempotent), chaining the callbacks
    installed before them for models that are not fsarm's. Undo with :func:`uninstall`.

    Caveat (mujoco 3.17 Python bindings): while *any* Python callback is installed, compiling a
    model in the same process fails with "engine error: Python exception raised", because the
    compiler runs the callbacks on a model that has no Python object yet. Prefer :func:`active`,
    which installs them only while stepping, or compile inside :func:`suspended`.
    """
    global _installed
    with _lock:
        if _holders:
            raise CallbackConflictError(
                "fsarm's callbacks are in use by a running simulation (callbacks.active); "
                "install_python() can be called only when none runs"
            )
        if not _installed:
            cbs = _current()
            for key, cb in zip(("passive", "act_dyn", "control"), cbs[:3], strict=True):
                _previous[key] = None if _ours(cb) else cb
        _set_python()
        _installed = True


def uninstall() -> None:
    """Restore the callbacks that were installed before :func:`install_python`."""
    global _installed
    with _lock:
        if _holders:
            raise CallbackConflictError(
                "fsarm's callbacks are in use by a running simulation (callbacks.active); "
                "uninstall() can be called only when none runs"
            )
        _restore(
            (
                _previous.get("passive"),
                _previous.get("act_dyn"),
                _previous.get("control"),
                mujoco.get_mjcb_time(),  # the Python path never touches the clock
            )
        )
        _previous.clear()
        _installed = False


_native_failure: list[str] = []
_native: list[Any] = []  # the native callbacks in use in this process (one source, never mixed)


def load_native() -> Any:
    """The native callbacks: the prebuilt library of the current kernels if there is one
    (:mod:`fsarm_sim.engine.native_lib`, no Numba import), else fsarm_sim.engine.native (Numba,
    which then builds the library for later processes in the background), or None (said once on
    stderr) where they cannot be compiled here."""
    if _native:
        return _native[0]
    if _native_failure:
        return None
    try:
        from fsarm_sim.engine import native_lib

        lib = native_lib.load()
        if lib is not None:
            _native.append(lib)
            return lib
        mod = importlib.import_module("fsarm_sim.engine.native")
        if native_lib.enabled():
            native_lib.build_in_background()
        _native.append(mod)
        return mod
    except Exception as exc:  # numba missing or broken, no compiler, unknown struct layout
        _native_failure.append(f"{type(exc).__name__}: {exc}")
        sys.stderr.write(
            "fsarm: the native (compiled) callbacks are not available here "
            f"({_native_failure[0]}); running on the Python reference path "
            "(same physics, slower; --backend python says so explicitly)\n"
        )
        return None


def native_source() -> str:
    """Where this process's native callbacks come from: "prebuilt library", "numba" or
    "unavailable" (loads them if not loaded yet)."""
    src = load_native()
    if src is None:
        return "unavailable"
    return "numba" if isinstance(src, ModuleType) else "prebuilt library"


@contextlib.contextmanager
def active(backend: str = DEFAULT_BACKEND) -> Iterator[None]:
    """fsarm's callbacks inside the block (``python`` or ``native``), the previous ones after it.

    Thread-safe: runs in several threads share one installation (counted); the callbacks that
    were installed before the first of them come back when the last one leaves. A callback of
    your own that was installed before is chained on the Python path: models that are not fsarm's
    are passed to it (see the module docstring). The native path cannot call Python callbacks, so
    with one of yours installed the block runs the Python path (said on stderr); where the native
    callbacks cannot be compiled, likewise.
    """
    global _backend, _saved
    if backend not in ("python", "native"):
        raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
    me = threading.get_ident()
    with _lock:
        if not _holders:
            saved = _current()
            foreign = [
                n
                for n, cb in zip(("passive", "act_dyn", "control"), saved[:3], strict=True)
                if not _ours(cb)
            ]
            if backend == "native" and foreign:
                # the compiled callbacks cannot call a Python one: the Python path chains it
                sys.stderr.write(
                    f"fsarm: a callback of your own is installed (mjcb_{', mjcb_'.join(foreign)}); "
                    "the native callbacks cannot pass other models on to it, so this run uses the "
                    "Python reference path, which does\n"
                )
                backend = "python"
            if backend == "native":
                native = load_native()
                if native is not None:
                    native.install()
                else:
                    backend = "python"
            if backend == "python":
                if not _installed:
                    for key, cb in zip(("passive", "act_dyn", "control"), saved[:3], strict=True):
                        _previous[key] = None if _ours(cb) else cb
                _set_python()
            _saved = saved
            _backend = backend
        elif backend == "native" and _native_failure:
            backend = "python"  # said once already: the native callbacks cannot run here
        if _holders and backend != _backend:
            raise CallbackConflictError(
                f"another simulation in this process is stepping with the {_backend} callbacks; "
                f"backend={backend!r} cannot run at the same time: use backend={_backend!r} "
                "(same physics) or wait for it to finish"
            )
        _holders[me] = _holders.get(me, 0) + 1
    try:
        yield
    finally:
        with _free:
            _holders[me] -= 1
            if not _holders[me]:
                del _holders[me]
            if not _holders:
                _restore(_saved)
                if not _installed:
                    _previous.clear()
                _saved = None
                _backend = None
                _free.notify_all()
