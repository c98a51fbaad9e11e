"""The arm in 3-D for a recording: its geoms, body poses from recorded joint angles, and the
shaft's route.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import mujoco
import numpy as np

from fsarm_sim.engine.model import read_structure
from fsarm_sim.review.panels import (
    SHAFT_BLUE,
    SHAFT_POINTS,
    SHAFT_RADIUS_M,
    Array,
    Columns,
    sim_time_column,
)

if TYPE_CHECKING:
    import rerun as rr


# --------------------------------------------------------------------------- 3-D arm


@dataclass(frozen=True)
class GeomShape:
    """A drawable geom: body name, geom name, MuJoCo type, size and pose in its body's frame."""

    body: str
    name: str
    kind: int
    size: tuple[float, float, float]
    pos: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]


def arm_geoms(model: mujoco.MjModel) -> list[GeomShape]:
    """The visible geoms of a compiled model (read from the MJCF, never typed twice)."""
    out = []
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        out.append(
            GeomShape(
                body=mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}",
                name=mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or f"geom{g}",
                kind=int(model.geom_type[g]),
                size=tuple(float(v) for v in model.geom_size[g]),  # type: ignore[arg-type]
                pos=tuple(float(v) for v in model.geom_pos[g]),  # type: ignore[arg-type]
                quat_wxyz=tuple(float(v) for v in model.geom_quat[g]),  # type: ignore[arg-type]
                rgba=tuple(float(v) for v in model.geom_rgba[g]),  # type: ignore[arg-type]
            )
        )
    return out


def _xyzw(q_wxyz: Any) -> list[float]:
    return [float(q_wxyz[1]), float(q_wxyz[2]), float(q_wxyz[3]), float(q_wxyz[0])]


def _color(rgba: Sequence[float]) -> tuple[int, int, int, int]:
    return tuple(round(255 * float(c)) for c in rgba)  # type: ignore[return-value]


def log_geoms(
    rec: rr.RecordingStream, geoms: Sequence[GeomShape], skip: Sequence[str] = ()
) -> list[str]:
    """Log the geoms statically under ``world/arm/<body>/<geom>``; return their paths."""
    import rerun as rr

    G = mujoco.mjtGeom
    paths = []
    for g in geoms:
        if g.name in skip or g.rgba[3] <= 0.0:
            continue
        path = f"world/arm/{g.body}/{g.name}"
        rec.log(
            path,
            rr.Transform3D(translation=g.pos, quaternion=rr.Quaternion(xyzw=_xyzw(g.quat_wxyz))),
            static=True,
        )
        color = [_color(g.rgba)]
        shape: Any
        if g.kind == G.mjGEOM_CAPSULE:
            # MuJoCo: centred, half-length size[1] along z; Rerun: one cap centre at the origin
            shape = rr.Capsules3D(
                lengths=[2 * g.size[1]],
                radii=[g.size[0]],
                translations=[[0.0, 0.0, -g.size[1]]],
                colors=color,
            )
        elif g.kind == G.mjGEOM_CYLINDER:
            shape = rr.Cylinders3D(lengths=[2 * g.size[1]], radii=[g.size[0]], colors=color)
        elif g.kind == G.mjGEOM_BOX:
            shape = rr.Boxes3D(half_sizes=[g.size], colors=color, fill_mode="solid")
        elif g.kind == G.mjGEOM_SPHERE:
            shape = rr.Ellipsoids3D(half_sizes=[[g.size[0]] * 3], colors=color, fill_mode="solid")
        else:
            continue  # planes, meshes, ...: the arm has none
        rec.log(path, shape, static=True)
        paths.append(path)
    return paths


def joint_qpos(cols: Columns, model: mujoco.MjModel) -> Array:
    """Full qpos rows (q1, q2, q3, rotor) from the recorded columns: rotor = theta_m / coef_m."""
    st = read_structure(model)
    n = len(cols["q1"])
    qpos = np.tile(model.qpos0, (n, 1))
    for j in range(3):
        qpos[:, st.qadr[j]] = cols[f"q{j + 1}"]
    if "theta_m" in cols:
        qpos[:, st.qadr[3]] = np.asarray(cols["theta_m"]) / st.coef_m
    return qpos


def body_poses(model: mujoco.MjModel, qpos: Array) -> tuple[Array, Array, Array, Array]:
    """World poses from ``mj_kinematics`` on a private MjData (no callbacks run):
    body positions (n, nbody, 3), body quaternions wxyz (n, nbody, 4), site positions
    (n, nsite, 3) and site rotation matrices (n, nsite, 3, 3)."""
    d = mujoco.MjData(model)
    n = len(qpos)
    xpos = np.empty((n, model.nbody, 3))
    xquat = np.empty((n, model.nbody, 4))
    spos = np.empty((n, model.nsite, 3))
    smat = np.empty((n, model.nsite, 3, 3))
    for i in range(n):
        d.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, d)
        xpos[i], xquat[i] = d.xpos, d.xquat
        spos[i], smat[i] = d.site_xpos, d.site_xmat.reshape(-1, 3, 3)
    return xpos, xquat, spos, smat


def shaft_route(
    p_in: Array, z_in: Array, p_out: Array, z_out: Array, n_points: int = SHAFT_POINTS
) -> Array:
    """Cubic Bezier of the shaft from ``p_in`` (leaving along ``z_in``) to ``p_out`` (arriving
    along ``z_out``); shapes (n, 3) -> (n, n_points, 3). Visual only: it bends with joint 2 because
    the end tangent turns with link 2."""
    gap = np.linalg.norm(p_out - p_in, axis=-1, keepdims=True)
    a = 0.45 * gap
    c1 = p_in + a * z_in
    c2 = p_out - a * z_out
    s = np.linspace(0.0, 1.0, n_points)[None, :, None]
    b0, b1, b2, b3 = (1 - s) ** 3, 3 * (1 - s) ** 2 * s, 3 * (1 - s) * s**2, s**3
    return b0 * p_in[:, None] + b1 * c1[:, None] + b2 * c2[:, None] + b3 * p_out[:, None]


def log_arm_motion(
    rec: rr.RecordingStream,
    model: mujoco.MjModel,
    qpos: Array,
    t: Array,
) -> list[str]:
    """Log each body's world transform over time and the shaft route; return entity paths."""
    import rerun as rr

    xpos, xquat, spos, smat = body_poses(model, qpos)
    idx = [sim_time_column(t)]
    paths = []
    for b in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}"
        path = f"world/arm/{name}"
        quat_xyzw = xquat[:, b][:, [1, 2, 3, 0]]
        rec.send_columns(
            path,
            indexes=idx,
            columns=rr.Transform3D.columns(translation=xpos[:, b], quaternion=quat_xyzw),
        )
        paths.append(path)
    sites = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, s): s for s in range(model.nsite)}
    if {"shaft_in", "shaft_out"} <= set(sites):
        i, o = sites["shaft_in"], sites["shaft_out"]
        route = shaft_route(spos[:, i], smat[:, i, :, 2], spos[:, o], smat[:, o, :, 2])
        rec.log(
            "world/shaft",
            rr.LineStrips3D.from_fields(colors=[SHAFT_BLUE], radii=[SHAFT_RADIUS_M]),
            static=True,
        )
        rec.send_columns(
            "world/shaft",
            indexes=idx,
            columns=rr.LineStrips3D.columns(strips=cast(Any, route)).partition(
                np.ones(len(t), dtype=int)
            ),
        )
        paths.append("world/shaft")
    return paths
