"""The lean twin of a run's model: the same dynamics without what only a viewer needs.

``mj_step`` spends part of every step on elements that do not change the arm's motion here: the
visual geoms (no geom of the arm collides: ``contype``/``conaffinity`` 0, see
``models/fsarm/fsarm.xml``) have their poses computed every step, and the sensors are evaluated
every step although fsarm reads its channels from the state. :func:`strip` removes them from a
run's MjSpec before it is compiled (``engine.model.build_model(..., lean=True)``):

* a non-colliding geom is deleted only where its body states its inertia explicitly, so no body
  loses mass or inertia (a body whose inertia comes from its geoms keeps them);
* every sensor is deleted.

:func:`idle_off` then switches off, in the compiled twin, MuJoCo's passive *spring* stage when
no element has a spring (every joint and tendon stiffness 0, polynomial terms included; no flex,
no plugin): MuJoCo adds exactly nothing there, yet walks every joint and tendon each step (about
1.5 % of a lean native step). fsarm's springs are its own (the shaft, the bending moment:
``mjcb_passive``). Damping, limits and everything else stay on.

Bodies, joints, sites, tendons and actuators are kept, so every address the kernels read
(``fsarm_params``' structure block) is the same as in the full model, and the dynamics are the
same to the last bit (``tests/test_lean.py`` steps the twin beside the full model for 10 s of
every scenario with every transmission). ``fsarm bench-speed`` reports what it saves. Review
(the 3-D view) and anything that needs the geoms or sensors use the full model.
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.errors import ModelStructureError


def strip(spec: mujoco.MjSpec) -> tuple[int, int]:
    """Delete the non-colliding geoms of bodies with explicit inertia, and every sensor, from
    ``spec`` (in place); returns (geoms deleted, sensors deleted)."""
    geoms = [
        g for g in spec.geoms if g.contype == 0 and g.conaffinity == 0 and g.parent.explicitinertial
    ]
    sensors = list(spec.sensors)
    for g in geoms:
        spec.delete(g)
    for s in sensors:
        spec.delete(s)
    return len(geoms), len(sensors)


_SPRING_OFF = int(mujoco.mjtDisableBit.mjDSBL_SPRING)


def has_springs(model: mujoco.MjModel) -> bool:
    """Whether MuJoCo's passive spring stage can add any force to ``model``: a joint or tendon
    stiffness (or polynomial stiffness term) other than 0, a flex, or a plugin (which may read the
    spring flag)."""
    return bool(
        model.nflex > 0 or model.nplugin > 0 or any(np.any(a) for a in stiffness_views(model))
    )


def idle_off(model: mujoco.MjModel) -> bool:
    """Disable MuJoCo's spring stage (``mjDSBL_SPRING``) in a compiled twin without springs
    (:func:`has_springs`); True if it was disabled. Call it once the model's numbers are
    written: a stiffness written later would then not act."""
    if has_springs(model):
        return False
    model.opt.disableflags |= _SPRING_OFF
    return True


def stiffness_views(model: mujoco.MjModel) -> tuple[npt.NDArray[np.float64], ...]:
    """Views of ``model``'s joint and tendon stiffness arrays (polynomial terms included): what a
    caller can write into a compiled model to add a spring (a flex or plugin cannot be added)."""
    return (
        model.jnt_stiffness,
        model.jnt_stiffnesspoly,
        model.tendon_stiffness,
        model.tendon_stiffnesspoly,
    )


def check_springs_off(
    model: mujoco.MjModel, views: tuple[npt.NDArray[np.float64], ...] | None = None
) -> None:
    """Raise :class:`ModelStructureError` if MuJoCo's spring stage is off in ``model`` although a
    spring was written into it since (a joint or tendon stiffness set on the lean twin after it
    was built, which :func:`idle_off` made inert: it would be ignored without a word).
    ``views``: :func:`stiffness_views` of ``model`` kept by the caller (a per-step check then
    takes ~1 us: ``np.count_nonzero`` on these few numbers is ~5x quicker than ``.any()``)."""
    arrays = stiffness_views(model) if views is None else views
    if any(np.count_nonzero(a) for a in arrays) and model.opt.disableflags & _SPRING_OFF:
        raise ModelStructureError(
            "a joint or tendon stiffness was written into the lean twin after it was built, where "
            "MuJoCo's spring stage is off (engine.lean.idle_off), so it would not act: put the "
            "spring in the MJCF, or build the model with lean=False (Simulation(..., lean=False))"
        )
