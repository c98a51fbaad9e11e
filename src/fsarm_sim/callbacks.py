"""Plugin-free injection: the shaft and controllers enter MuJoCo through process-global callbacks.

* ``mjcb_passive``  adds the shaft's generalized forces to ``qfrc_passive``;
* ``mjcb_act_dyn``  gives the rates of the internal states in ``data.act``;
* ``mjcb_control``  runs the controllers on their clock ticks and writes ``data.ctrl``.

The callbacks are shared by every model in the process, so they carry no parameters themselves:
each call finds its parameters in the model it receives (``fsarm_params``) and its states in the
data (``userdata``, ``act``). Models that are not fsarm models are passed to whatever callback was
installed before (or left alone). This module is the readable Python reference path; the native
path installs compiled versions of the same :mod:`fsarm_sim.physics` kernels.
"""

from __future__ import annotations

import contextlib
import importlib
import weakref
from collections.abc import Iterator
from typing import Any

import mujoco

from fsarm_sim import layout as L
from fsarm_sim import physics
from fsarm_sim.errors import InvalidParameterError

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
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, L.PARAMS_NAME)
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, L.REF_NAME)
    if (
        i >= 0
        and j >= 0
        and m.numeric_size[i] == L.N_PARAMS
        and m.numeric_data[m.numeric_adr[i]] == L.MAGIC
    ):
        a, b = int(m.numeric_adr[i]), int(m.numeric_adr[j])
        out = (a, a + L.N_PARAMS, b, b + int(m.numeric_size[j]))
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
        m.numeric_data[s[0] : s[1]], d.qpos, d.qvel, d.act, d.qfrc_passive, d.userdata[L.U_LOG :]
    )


def _act_dyn(m: mujoco.MjModel, d: mujoco.MjData, actuator_id: int) -> float:
    s = _slices(m)
    if s is None:
        prev = _previous.get("act_dyn")
        return float(prev(m, d, actuator_id)) if prev is not None else 0.0
    return physics.state_rate(
        m.numeric_data[s[0] : s[1]], d.qpos, d.qvel, d.act, int(m.actuator_actadr[actuator_id])
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
        d.qfrc_bias,
        d.M,
        d.userdata,
        d.ctrl,
    )


@contextlib.contextmanager
def suspended() -> Iterator[None]:
    """No callbacks at all inside the block (MuJoCo's compiler runs mj_forward on models that are
    not finished yet)."""
    saved = (mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn(), mujoco.get_mjcb_control())
    mujoco.set_mjcb_passive(None)
    mujoco.set_mjcb_act_dyn(None)
    mujoco.set_mjcb_control(None)
    try:
        yield
    finally:
        mujoco.set_mjcb_passive(saved[0])
        mujoco.set_mjcb_act_dyn(saved[1])
        mujoco.set_mjcb_control(saved[2])


def _set_python() -> None:
    mujoco.set_mjcb_passive(_passive)
    mujoco.set_mjcb_act_dyn(_act_dyn)
    mujoco.set_mjcb_control(_control)


def install_python() -> None:
    """Install the Python reference callbacks process-wide (idempotent).

    Caveat (mujoco 3.17 Python bindings): while *any* Python callback is installed, compiling a
    model in the same process fails with "engine error: Python exception raised", because the
    compiler runs the callbacks on a model that has no Python object yet. Prefer :func:`active`,
    which installs them only while stepping, or compile inside :func:`suspended`.
    """
    global _installed
    if not _installed:
        _previous["passive"] = mujoco.get_mjcb_passive()
        _previous["act_dyn"] = mujoco.get_mjcb_act_dyn()
        _previous["control"] = mujoco.get_mjcb_control()
    _set_python()
    _installed = True


def uninstall() -> None:
    """Restore the callbacks that were installed before fsarm-sim's."""
    global _installed
    mujoco.set_mjcb_passive(_previous.get("passive"))
    mujoco.set_mjcb_act_dyn(_previous.get("act_dyn"))
    mujoco.set_mjcb_control(_previous.get("control"))
    _previous.clear()
    _installed = False


@contextlib.contextmanager
def active(backend: str = "python") -> Iterator[None]:
    """fsarm's callbacks inside the block (``python`` or ``native``), the previous ones after it.

    Other models stepped inside the block are passed on untouched (see module docstring).
    """
    saved = (mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn(), mujoco.get_mjcb_control())
    if backend == "python":
        _set_python()
    elif backend == "native":
        importlib.import_module("fsarm_sim.native").install()
    else:
        raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
    try:
        yield
    finally:
        mujoco.set_mjcb_passive(saved[0])
        mujoco.set_mjcb_act_dyn(saved[1])
        mujoco.set_mjcb_control(saved[2])
