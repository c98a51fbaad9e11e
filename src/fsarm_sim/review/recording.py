"""Rerun recordings of runs: the arm in 3-D, the shaft route, time series, 2-D loops, metadata.

Everything is logged *after* the run from the recorded columns (``RunResult.columns``), so a
recording can never change a simulation's results. The logging functions are generic over plain
column dicts (``{"t": ..., "q3": ..., ...}``): a bench run or a sweep can reuse
:func:`log_scalar_panels`, :func:`log_loops` and :func:`blueprint` with its own
:class:`Panel` / :class:`Loop` lists.

Entity layout of an arm recording (timeline ``sim_time``, simulation clock):

* ``run/metadata``                 - TextDocument (markdown): shaft, payload, gains, version, metrics
* ``world/arm/<body>``             - Transform3D of each body (world frame, from ``mj_kinematics``)
* ``world/arm/<body>/<geom>``      - static Capsules3D / Cylinders3D / Boxes3D from the MJCF geoms
* ``world/shaft``                  - LineStrips3D: the shaft route shaft_in -> (bend) -> shaft_out
* ``signals/<panel>/<series>``     - Scalars (one TimeSeriesView per panel)
* ``loops/<loop>/<curve>``         - LineStrips2D segments (the loop grows with the time cursor);
  ``.../<curve>/full`` the whole loop (static, faint), ``loops/<loop>/axes`` the zero lines.
  Rerun's 2-D views point y down, so y values are logged negated (positive torque shows upwards).

A blueprint (:func:`blueprint`) lays this out: 3-D view, the loops and the metadata on the left, one
time-series view per panel on the right. Open a file with ``rerun FILE.rrd``.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim import __version__
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import build_spec, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout as L

if TYPE_CHECKING:
    import rerun as rr
    import rerun.blueprint as rrb

    from fsarm_sim.sim.simulation import RunResult

Array = npt.NDArray[np.float64]
Columns = Mapping[str, Array]

APPLICATION_ID = "fsarm_sim"
TIMELINE = "sim_time"
DEFAULT_RATE_HZ = 100.0  # logged rows per simulated second: smooth playback, small files
RAD2DEG = 180.0 / math.pi
SHAFT_POINTS = 24  # points of the drawn shaft curve (visual only)
SHAFT_RADIUS_M = 0.006  # drawn radius of the shaft line (visual only, not the shaft's D)

# colors (visual only)
BLUE = (31, 119, 180)
ORANGE = (255, 127, 14)
GREEN = (44, 160, 44)
RED = (214, 39, 40)
PURPLE = (148, 103, 189)
GREY = (127, 127, 127)
SHAFT_BLUE = (26, 153, 230)


# --------------------------------------------------------------------------- panels and loops


@dataclass(frozen=True)
class Series:
    """One scalar series: ``column`` of the column dict, times ``scale``, shown as ``label``."""

    column: str
    label: str
    scale: float = 1.0
    color: tuple[int, int, int] = BLUE


@dataclass(frozen=True)
class Panel:
    """A time-series plot: its series are logged under ``signals/<name>/<column>``."""

    name: str
    title: str
    series: tuple[Series, ...]

    @property
    def entity(self) -> str:
        return f"signals/{self.name}"


@dataclass(frozen=True)
class Loop:
    """A 2-D x-y plot traced over time (e.g. torque vs twist). ``curves``: (y column, label, color);
    all curves share ``x``. Rerun's 2-D view has y pointing down, so y is logged negated
    (``-y * y_scale``) to show positive values upwards."""

    name: str
    title: str
    x: str
    x_label: str
    x_scale: float
    curves: tuple[tuple[str, str, tuple[int, int, int]], ...]
    y_label: str
    y_scale: float = 1.0

    @property
    def entity(self) -> str:
        return f"loops/{self.name}"


def _ui(points: float) -> float:
    """A radius in UI points (Rerun's convention: negative radii are screen-space points)."""
    return -abs(points)


def _deg(column: str, label: str, color: tuple[int, int, int]) -> Series:
    return Series(column, label, RAD2DEG, color)


ARM_PANELS: tuple[Panel, ...] = (
    Panel(
        "joint1",
        "joint 1 [deg]",
        (_deg("q1_ref", "q1 ref", GREY), _deg("q1", "q1", BLUE)),
    ),
    Panel(
        "joint2",
        "joint 2 [deg]",
        (_deg("q2_ref", "q2 ref", GREY), _deg("q2", "q2", BLUE)),
    ),
    Panel(
        "joint3",
        "joint 3 [deg]",
        (_deg("q3_ref", "q3 ref", GREY), _deg("q3", "q3", BLUE)),
    ),
    Panel(
        "errors",
        "tracking error q - q_ref [deg]",
        (_deg("e1", "e1", BLUE), _deg("e2", "e2", ORANGE), _deg("e3", "e3", GREEN)),
    ),
    Panel(
        "shaft_angles",
        "shaft input θ_m / output θ_s [rad]",
        (Series("theta_m", "θ_m", 1.0, BLUE), Series("theta_s", "θ_s", 1.0, ORANGE)),
    ),
    Panel(
        "twist_bend",
        "twist Δθ and bend φ_B [deg]",
        (_deg("twist", "twist Δθ", BLUE), _deg("phi_b", "bend φ_B", ORANGE)),
    ),
    Panel(
        "shaft_torque",
        "shaft torque [N·m]",
        (
            Series("tau_shaft", "true τ", 1.0, BLUE),
            Series("tau_model", "modeled τ_m", 1.0, ORANGE),
            Series("tau_d_shaft", "desired τ_d", 1.0, GREY),
        ),
    ),
    Panel(
        "bending",
        "bending torque on joint 2 [N·m]",
        (
            Series("tau_bend", "total", 1.0, BLUE),
            Series("tau_conduit", "conduit part", 1.0, ORANGE),
        ),
    ),
    Panel(
        "pid",
        "torque PID terms [rad/s]",
        (
            Series("pid_p", "P", 1.0, BLUE),
            Series("pid_i", "I", 1.0, ORANGE),
            Series("pid_d", "D", 1.0, GREEN),
        ),
    ),
    Panel(
        "speed",
        "shaft-input speed [rad/s]",
        (Series("omega_d", "ω_d", 1.0, GREY), Series("omega_m", "ω_m", 1.0, BLUE)),
    ),
    Panel(
        "motor_torque",
        "joint-3 motor torque [N·m]",
        (
            Series("tau_motor", "τ_motor", 1.0, BLUE),
            Series("tau_motor_limit_pos", "+limit", 1.0, RED),
            Series("tau_motor_limit_neg", "-limit", 1.0, RED),
        ),
    ),
    Panel(
        "joint_torques",
        "joint 1 / 2 torque commands [N·m]",
        (Series("tau1", "τ1", 1.0, BLUE), Series("tau2", "τ2", 1.0, ORANGE)),
    ),
)

ARM_LOOPS: tuple[Loop, ...] = (
    Loop(
        "torque_twist",
        "shaft torque vs twist (Fig. 6/7)",
        x="twist",
        x_label="twist Δθ [deg]",
        x_scale=RAD2DEG,
        curves=(("tau_shaft", "true", BLUE), ("tau_model", "model τ_m", ORANGE)),
        y_label="τ [N·m]",
    ),
    Loop(
        "bending",
        "bending moment vs bend (Fig. 9)",
        x="phi_b",
        x_label="bend φ_B [deg]",
        x_scale=RAD2DEG,
        curves=(("moment_bend", "M = -τ_bend", BLUE),),
        y_label="M [N·m]",
    ),
)


def with_derived(cols: Columns, tau_motor_limit_nm: float | None = None) -> dict[str, Array]:
    """The columns plus derived ones where their inputs exist: tracking errors ``e1..e3``
    (rad), bending moment ``moment_bend = -tau_bend`` (the moment that resists the bend, Fig. 9's
    sign) and the motor-torque limit lines ``tau_motor_limit_pos/neg``."""
    out = {k: np.asarray(v, dtype=np.float64) for k, v in cols.items()}
    for j in (1, 2, 3):
        if f"q{j}" in out and f"q{j}_ref" in out:
            out[f"e{j}"] = out[f"q{j}"] - out[f"q{j}_ref"]
    if "tau_bend" in out:
        out["moment_bend"] = -out["tau_bend"]
    if tau_motor_limit_nm is not None and "t" in out:
        out["tau_motor_limit_pos"] = np.full_like(out["t"], tau_motor_limit_nm)
        out["tau_motor_limit_neg"] = np.full_like(out["t"], -tau_motor_limit_nm)
    return out


# --------------------------------------------------------------------------- generic logging


def decimate(t: Array, rate_hz: float | None) -> npt.NDArray[np.intp]:
    """Row indices that log at about ``rate_hz`` rows per simulated second (None: every row).
    The last row is always kept so the recording spans the whole run."""
    n = len(t)
    if rate_hz is None or n < 2:
        return np.arange(n)
    if not math.isfinite(rate_hz) or rate_hz <= 0.0:
        raise InvalidParameterError(
            f"recording rate must be a finite number of Hz > 0, got {rate_hz!r}"
        )
    dt = float(np.median(np.diff(t)))
    stride = max(1, round(1.0 / (rate_hz * dt))) if dt > 0.0 else 1
    rows = np.arange(0, n, stride)
    if rows[-1] != n - 1:
        rows = np.append(rows, n - 1)
    return rows


def _time_column(t: Array) -> rr.TimeColumn:
    import rerun as rr

    return rr.TimeColumn(TIMELINE, duration=np.asarray(t, dtype=np.float64))


def log_scalar_panels(
    rec: rr.RecordingStream,
    cols: Columns,
    panels: Sequence[Panel],
    rows: npt.NDArray[np.intp],
    time_column: str = "t",
) -> list[str]:
    """Log each panel's series (columns that exist) as Scalars; return the entity paths."""
    import rerun as rr

    t = np.asarray(cols[time_column])[rows]
    logged: list[str] = []
    for panel in panels:
        for s in panel.series:
            if s.column not in cols:
                continue
            path = f"{panel.entity}/{s.column}"
            rec.log(
                path, rr.SeriesLines(colors=[s.color], names=[s.label], widths=[1.5]), static=True
            )
            values = np.asarray(cols[s.column], dtype=np.float64)[rows] * s.scale
            rec.send_columns(
                path, indexes=[_time_column(t)], columns=rr.Scalars.columns(scalars=values)
            )
            logged.append(path)
    return logged


def log_loops(
    rec: rr.RecordingStream,
    cols: Columns,
    loops: Sequence[Loop],
    rows: npt.NDArray[np.intp],
    time_column: str = "t",
) -> list[str]:
    """Log each loop as a static full curve (faint) plus one segment per logged row, so that the
    view (time range: start .. cursor) draws the loop up to the current time."""
    import rerun as rr

    t = np.asarray(cols[time_column])[rows]
    logged: list[str] = []
    for loop in loops:
        if loop.x not in cols:
            continue
        x = np.asarray(cols[loop.x], dtype=np.float64)[rows] * loop.x_scale
        for column, label, color in loop.curves:
            if column not in cols or len(rows) < 2:
                continue
            y = -np.asarray(cols[column], dtype=np.float64)[rows] * loop.y_scale
            pts = np.stack([x, y], axis=1)
            path = f"{loop.entity}/{column}"
            faint = (*color, 70)
            rec.log(
                f"{path}/full",
                rr.LineStrips2D([pts], colors=[faint], radii=[_ui(1.0)], labels=[label]),
                static=True,
            )
            # segment i joins row i-1 to row i and appears at row i's time
            seg = np.stack([pts[:-1], pts[1:]], axis=1)
            rec.send_columns(
                path,
                indexes=[_time_column(t[1:])],
                columns=rr.LineStrips2D.columns(strips=cast(Any, seg)).partition(
                    np.ones(len(seg), dtype=int)
                ),
            )
            rec.log(
                path,
                rr.LineStrips2D.from_fields(colors=[color], radii=[_ui(2.0)]),
                static=True,
            )
            logged.append(path)
        _log_loop_axes(rec, loop, x, cols, rows)
    return logged


def _log_loop_axes(
    rec: rr.RecordingStream, loop: Loop, x: Array, cols: Columns, rows: npt.NDArray[np.intp]
) -> None:
    import rerun as rr

    ys = [
        -np.asarray(cols[c], dtype=np.float64)[rows] * loop.y_scale
        for c, _, _ in loop.curves
        if c in cols
    ]
    if not ys or len(x) == 0:
        return
    y = np.concatenate(ys)
    x0, x1 = float(min(x.min(), 0.0)), float(max(x.max(), 0.0))
    y0, y1 = float(min(y.min(), 0.0)), float(max(y.max(), 0.0))
    rec.log(
        f"{loop.entity}/axes",
        rr.LineStrips2D(
            [[[x0, 0.0], [x1, 0.0]], [[0.0, y0], [0.0, y1]]],
            colors=[GREY],
            labels=[loop.x_label, f"{loop.y_label} (up)"],
            radii=[_ui(0.5)],
        ),
        static=True,
    )


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
    idx = [_time_column(t)]
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


# --------------------------------------------------------------------------- blueprint, metadata


def blueprint(
    panels: Sequence[Panel],
    loops: Sequence[Loop],
    *,
    with_3d: bool = True,
    loop_bounds: Mapping[str, tuple[tuple[float, float], tuple[float, float]]] | None = None,
) -> rrb.Blueprint:
    """The default layout: 3-D arm, loops and metadata on the left, time series on the right."""
    import rerun as rr
    import rerun.blueprint as rrb

    grow = rr.VisibleTimeRange(
        TIMELINE,
        start=rr.TimeRangeBoundary.infinite(),
        end=rr.TimeRangeBoundary.cursor_relative(),
    )
    loop_views = []
    for lp in loops:
        bounds = (loop_bounds or {}).get(lp.name)
        loop_views.append(
            rrb.Spatial2DView(
                origin=lp.entity,
                name=lp.title,
                time_ranges=[grow],
                visual_bounds=rrb.VisualBounds2D(x_range=bounds[0], y_range=bounds[1])
                if bounds
                else None,
            )
        )
    left: list[Any] = []
    if with_3d:
        left.append(rrb.Spatial3DView(origin="world", name="arm (3-D)"))
    if loop_views:
        left.append(rrb.Horizontal(*loop_views))
    left.append(rrb.TextDocumentView(origin="run/metadata", name="run"))
    series_views = [rrb.TimeSeriesView(origin=p.entity, name=p.title) for p in panels]
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(*left, row_shares=[3, 2, 1][: len(left)]),
            rrb.Grid(*series_views, grid_columns=2),
            column_shares=[2, 3],
        ),
        collapse_panels=False,
    )


def metadata_markdown(meta: Mapping[str, Any], metrics: Mapping[str, Any] | None = None) -> str:
    """A readable markdown page of the run metadata (and metrics), with the full JSON below."""
    lines = [f"# {meta.get('scenario', 'run')}", ""]
    shaft = meta.get("shaft") or {}
    rows = [
        ("setup", meta.get("setup")),
        ("shaft D / L [mm]", f"{shaft.get('diameter_mm')} / {shaft.get('length_mm')}"),
        ("payload [kg]", meta.get("payload_kg")),
        ("duration [s]", meta.get("duration_s")),
        ("fsarm-sim", meta.get("fsarm_sim_version", __version__)),
    ]
    lines += ["| item | value |", "|---|---|", *(f"| {k} | {v} |" for k, v in rows), ""]
    if metrics:
        rmse = metrics.get("rmse_deg")
        if isinstance(rmse, Mapping):
            lines.append(
                "tracking RMSE [deg]: " + ", ".join(f"{k} {float(v):.4f}" for k, v in rmse.items())
            )
            lines.append("")
    payload = {"metadata": meta, "metrics": metrics or {}}
    lines += ["```json", json.dumps(payload, indent=2, default=str), "```"]
    return "\n".join(lines)


def _loop_bounds(
    cols: Columns, loops: Sequence[Loop]
) -> dict[str, tuple[tuple[float, float], tuple[float, float]]]:
    out = {}
    for lp in loops:
        if lp.x not in cols:
            continue
        x = np.asarray(cols[lp.x]) * lp.x_scale
        ys = [-np.asarray(cols[c]) * lp.y_scale for c, _, _ in lp.curves if c in cols]
        if not ys:
            continue
        y = np.concatenate(ys)
        x0, x1, y0, y1 = (
            float(min(x.min(), 0.0)),
            float(max(x.max(), 0.0)),
            float(min(y.min(), 0.0)),
            float(max(y.max(), 0.0)),
        )
        mx, my = 0.08 * (x1 - x0) + 1e-6, 0.08 * (y1 - y0) + 1e-6
        out[lp.name] = ((x0 - mx, x1 + mx), (y0 - my, y1 + my))
    return out


# --------------------------------------------------------------------------- an arm run


def log_arm_run(
    rec: rr.RecordingStream, result: RunResult, rate_hz: float | None = DEFAULT_RATE_HZ
) -> rrb.Blueprint:
    """Log a finished arm run into ``rec``; return the blueprint that lays it out."""
    import rerun as rr

    from fsarm_sim.records.timeseries import run_metadata

    with callbacks.suspended():  # a private copy for kinematics only; it is never stepped
        model = build_spec(result.config, np.zeros((1, L.REF_COLS))).compile()
    st = read_structure(model)
    cols = with_derived(result.columns, tau_motor_limit_nm=st.tau_max[2])
    rows = decimate(cols["t"], rate_hz)
    t = cols["t"][rows]

    rec.log(
        "run/metadata",
        rr.TextDocument(
            metadata_markdown(run_metadata(result), result.metrics), media_type="text/markdown"
        ),
        static=True,
    )
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    skip = () if result.config.payload_kg > 0.0 else ("payload_geom",)
    log_geoms(rec, arm_geoms(model), skip=skip)
    if result.config.payload_kg > 0.0:
        pid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "payload")
        rec.log(
            "world/arm/payload/label",
            rr.Points3D(
                [model.body_ipos[pid]],
                labels=[f"payload {result.config.payload_kg:g} kg"],
                radii=[0.004],
                colors=[GREEN],
            ),
            static=True,
        )
    qpos = joint_qpos({k: v[rows] for k, v in cols.items()}, model)
    log_arm_motion(rec, model, qpos, t)
    log_scalar_panels(rec, cols, ARM_PANELS, rows)
    log_loops(rec, cols, ARM_LOOPS, rows)
    return blueprint(ARM_PANELS, ARM_LOOPS, loop_bounds=_loop_bounds(cols, ARM_LOOPS))


def new_stream(result: RunResult) -> rr.RecordingStream:
    """A dedicated recording stream (no global state), named after the run."""
    import rerun as rr

    return rr.RecordingStream(APPLICATION_ID, recording_id=f"{result.scenario}")


def record_run(result: RunResult, path: Path, rate_hz: float | None = DEFAULT_RATE_HZ) -> Path:
    """Write ``result`` as a Rerun recording (``.rrd``) with its blueprint; return the path."""
    rec = new_stream(result)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    rec.save(path)
    try:
        bp = log_arm_run(rec, result, rate_hz)
        rec.send_blueprint(bp, make_active=True, make_default=True)
        rec.flush()
    finally:
        rec.disconnect()
    return path


def spawn_viewer(path: Path) -> str:
    """Open ``path`` in the Rerun viewer if one can run here; return a one-line status message.

    Never raises: a missing display or executable, or a viewer that exits at once, is reported
    in the message (the recording file stays valid either way)."""
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        return (
            f"no viewer opened: no display here (DISPLAY/WAYLAND_DISPLAY unset); "
            f"open the recording elsewhere with `rerun {path}`"
        )
    exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    if not Path(exe).exists():
        return (
            f"no viewer opened: the `rerun` executable was not found; open `{path}` with it later"
        )
    try:
        proc = subprocess.Popen(
            [exe, str(path)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            start_new_session=True,
        )
    except OSError as exc:
        return f"no viewer opened: could not start {exe}: {exc}"
    try:
        rc = proc.wait(timeout=3.0)
    except subprocess.TimeoutExpired:
        return f"viewer started (pid {proc.pid}) on {path}"
    err = (proc.stderr.read().decode(errors="replace") if proc.stderr else "").strip()
    tail = err.splitlines()[-1] if err else "no message"
    return f"no viewer opened: `rerun` exited with code {rc} ({tail}); open `{path}` elsewhere"
