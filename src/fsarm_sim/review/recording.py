"""Rerun recordings of runs: the arm in 3-D, the shaft route, time series, 2-D loops, metadata.

Everything is logged *after* the run from the recorded columns (``RunResult.columns``), so a
recording can never change a simulation's results. The logging functions are generic over plain
column dicts (``{"t": ..., "q3": ..., ...}``): a bench run or a sweep can reuse
:func:`log_scalar_panels`, :func:`.loop_panels.log_loop_panel` and :func:`blueprint` with its own
:class:`Panel` / :class:`.loop_panels.Loop` lists.

Entity layout of an arm recording (timeline ``sim_time``, simulation clock):

* ``run/metadata``                 - TextDocument (markdown): shaft, payload, gains, version, metrics
* ``world/arm/<body>``             - Transform3D of each body (world frame, from ``mj_kinematics``)
* ``world/arm/<body>/<geom>``      - static Capsules3D / Cylinders3D / Boxes3D from the MJCF geoms
* ``world/shaft``                  - LineStrips3D: the shaft route shaft_in -> (bend) -> shaft_out
* ``signals/<panel>/<series>``     - Scalars (one TimeSeriesView per panel)
* ``loops/<loop>/...``             - the loop panels (Fig. 6/7, Fig. 9): a plot image with axes,
  ticks, numbers and the catalogue's model curve, the loop up to the time cursor and the current
  point drawn over it (:mod:`.loop_panels`).

A blueprint (:func:`blueprint`) lays this out: 3-D view and metadata, the loops, one time-series
view per panel. It is chosen per run: panels that carry no information for the run (a held
joint's angle, the bending loop when joint 2 holds the bend, constant signals) are left out
(:func:`informative_panels`, :func:`.loop_panels.loop_is_informative`); their data stay in the
recording. Open a file with ``rerun FILE.rrd``.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim._version import __version__
from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import build_spec, read_structure
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout
from fsarm_sim.review.figures import moving_joints
from fsarm_sim.review.loop_panels import (
    ARM_LOOPS,
    Loop,
    Trace,
    bending_shown,
    log_loop_panel,
    loop_image,
    loop_is_informative,
    shaft_model_curves,
    varies,
)

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
CAMERA_EYE_M = (1.05, -1.35, 0.95)  # default 3-D viewpoint (visual only)
CAMERA_TARGET_M = (0.25, 0.0, 0.45)

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
    width: float = 1.5  # line width, UI points


@dataclass(frozen=True)
class Panel:
    """A time-series plot: its series are logged under ``signals/<name>/<column>``.
    ``informative``: does a run's column dict carry information for it? (None: whenever one of
    its series varies.)"""

    name: str
    title: str
    series: tuple[Series, ...]
    informative: Callable[[Columns], bool] | None = None
    group: str = "signals"  # the blueprint's tab (consecutive panels of a group share one)

    @property
    def entity(self) -> str:
        return f"signals/{self.name}"


def _deg(column: str, label: str, color: tuple[int, int, int]) -> Series:
    return Series(column, label, RAD2DEG, color)


ARM_PANELS: tuple[Panel, ...] = (
    Panel(
        "joint1",
        "joint 1 [deg]",
        (_deg("q1_ref", "q1 ref", GREY), _deg("q1", "q1", BLUE)),
        informative=lambda c: 1 in moving_joints(c),
        group="tracking",
    ),
    Panel(
        "joint2",
        "joint 2 [deg]",
        (_deg("q2_ref", "q2 ref", GREY), _deg("q2", "q2", BLUE)),
        informative=lambda c: 2 in moving_joints(c),
        group="tracking",
    ),
    Panel(
        "joint3",
        "joint 3 [deg]",
        (_deg("q3_ref", "q3 ref", GREY), _deg("q3", "q3", BLUE)),
        informative=lambda c: 3 in moving_joints(c),
        group="tracking",
    ),
    Panel(
        "errors",
        "tracking error q - q_ref [deg]",
        (_deg("e1", "e1", BLUE), _deg("e2", "e2", ORANGE), _deg("e3", "e3", GREEN)),
        group="tracking",
    ),
    Panel(
        "shaft_angles",
        "shaft input θ_m / output θ_s [rad]",
        (Series("theta_m", "θ_m", 1.0, BLUE), Series("theta_s", "θ_s", 1.0, ORANGE)),
        group="shaft",
    ),
    Panel(
        "twist_bend",
        "twist Δθ and bend φ_B [deg]",
        (_deg("twist", "twist Δθ", BLUE), _deg("phi_b", "bend φ_B", ORANGE)),
        group="shaft",
    ),
    Panel(
        "shaft_torque",
        "shaft torque [N·m]",
        (
            Series("tau_shaft", "true τ", 1.0, BLUE),
            Series("tau_model", "modeled τ_m", 1.0, ORANGE),
            Series("tau_d_shaft", "desired τ_d", 1.0, GREY),
        ),
        group="shaft",
    ),
    Panel(
        "bending",
        "bending torque on joint 2 [N·m]",
        (
            Series("tau_bend", "total", 1.0, BLUE),
            Series("tau_conduit", "conduit part", 1.0, ORANGE),
        ),
        informative=bending_shown,
        group="shaft",
    ),
    Panel(
        "pid",
        "torque PID terms [rad/s]",
        (
            Series("pid_p", "P", 1.0, BLUE),
            Series("pid_i", "I", 1.0, ORANGE),
            Series("pid_d", "D", 1.0, GREEN),
        ),
        group="control",
    ),
    Panel(
        "speed",
        "shaft-input speed [rad/s]",
        (Series("omega_d", "ω_d", 1.0, GREY), Series("omega_m", "ω_m", 1.0, BLUE)),
        group="control",
    ),
    Panel(
        "motor_torque",
        "joint-3 motor torque [N·m]",
        (
            Series("tau_motor", "τ_motor", 1.0, BLUE),
            Series("tau_motor_limit_pos", "+limit", 1.0, RED),
            Series("tau_motor_limit_neg", "-limit", 1.0, RED),
        ),
        group="control",
    ),
    Panel(
        "joint_torques",
        "joint 1 / 2 torque commands [N·m]",
        (Series("tau1", "τ1", 1.0, BLUE), Series("tau2", "τ2", 1.0, ORANGE)),
        group="control",
    ),
)


def state_panels(result: RunResult) -> tuple[Panel, ...]:
    """Panels of a run's internal states (``RunResult.states``, logged as ``state_<name>``):
    the transmission's own (the shaft's slip elements, QA-Joint's sigma and friction, the
    tendon-sheath's capstan friction...) and the conduit branches (shown when the bend moves)."""
    colors = (BLUE, ORANGE, GREEN, GREY)
    own = [n for n in result.states if not n.startswith("conduit_branch")]
    branches = [n for n in result.states if n.startswith("conduit_branch")]
    out = []
    if own:
        out.append(
            Panel(
                "transmission_states",
                f"{result.config.transmission} states (data.act)",
                tuple(Series(f"state_{n}", n, 1.0, colors[i % 4]) for i, n in enumerate(own)),
                group="states",
            )
        )
    if branches:
        out.append(
            Panel(
                "conduit_states",
                "conduit branch states (bending hysteresis, data.act)",
                tuple(Series(f"state_{n}", n, 1.0, colors[i % 4]) for i, n in enumerate(branches)),
                informative=bending_shown,
                group="states",
            )
        )
    return tuple(out)


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
                path,
                rr.SeriesLines(colors=[s.color], names=[s.label], widths=[s.width]),
                static=True,
            )
            values = np.asarray(cols[s.column], dtype=np.float64)[rows] * s.scale
            rec.send_columns(
                path, indexes=[_time_column(t)], columns=rr.Scalars.columns(scalars=values)
            )
            logged.append(path)
    return logged


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


def informative_panels(cols: Columns, panels: Sequence[Panel]) -> list[Panel]:
    """The panels that carry information for this run: their own test when they have one, else
    at least one series that exists and varies."""
    out = []
    for p in panels:
        present = [s for s in p.series if s.column in cols]
        if not present:
            continue
        ok = (
            p.informative(cols)
            if p.informative is not None
            else any(varies(cols[s.column]) for s in present)
        )
        if ok:
            out.append(p)
    return out


@dataclass(frozen=True)
class LoopView:
    """A loop panel in the blueprint: its entity, title and image size (its visual bounds)."""

    entity: str
    title: str
    width: int
    height: int


# --- time-series views: what each panel needs to be read at a glance. Rerun draws a plot's
# legend over the data and labels the time axis only where ticks have room (its time ticks step
# 1 s, 10 s, ...: a 7 s run in a quarter-width panel got "+0s" alone). So the panels stand in
# one full-width column, at most PANELS_PER_TAB per tab, each with a y range of its data and a
# legend in the corner the data leave free (room is made above or below the data where none is).
PANELS_PER_TAB = 4
COLUMN_PX = (560.0, 800.0)  # the panels' column in a 1600 x 1000 window (below its tabs)
PANEL_CHROME_PX = 50.0  # a panel's title bar and time axis; visual only
LEGEND_ROW_PX = 19.0  # one legend entry's height (Rerun's default font), visual only
LEGEND_CHAR_PX = 7.0  # one character's width in a legend entry, visual only
LEGEND_PAD_PX = 30.0  # a legend entry's colour mark and margins, visual only
Y_MARGIN = 0.06  # share of the data's span left free above and below it

Curve = tuple[Array, Array, str]  # (t, y as shown, legend name) of one series in a panel


def panel_curves(panel: Panel, cols: Columns, time_column: str = "t") -> list[Curve]:
    """The series of ``panel`` that ``cols`` holds, as shown (scaled), with their names."""
    t = np.asarray(cols[time_column], dtype=np.float64)
    return [
        (t, np.asarray(cols[s.column], dtype=np.float64) * s.scale, s.label)
        for s in panel.series
        if s.column in cols
    ]


@dataclass(frozen=True)
class SeriesLayout:
    """How a time-series view shows its curves: the y range, the legend's corner (``None``: no
    legend, one curve names itself by the title) and the share of the plot the legend covers."""

    y_range: tuple[float, float]
    corner: str | None
    legend_share: tuple[float, float]


CORNERS = ("RightTop", "LeftTop", "RightBottom", "LeftBottom")


def plot_px(panels_in_tab: int) -> tuple[float, float]:
    """The nominal plot area of one of ``panels_in_tab`` panels stacked in the column."""
    return COLUMN_PX[0], COLUMN_PX[1] / max(1, panels_in_tab) - PANEL_CHROME_PX


def series_layout(
    curves: Sequence[Curve], plot_px: tuple[float, float] = plot_px(PANELS_PER_TAB)
) -> SeriesLayout:
    """The y range and legend corner of a panel showing ``curves``: the corner whose legend box
    covers the fewest data points; where every corner covers some, the range grows on that side
    by the legend's height, so that the legend stands beside the data, never on it."""
    finite = [(t[m], y[m]) for t, y, _ in curves if (m := np.isfinite(y) & np.isfinite(t)).any()]
    if not finite:
        return SeriesLayout((-1.0, 1.0), None, (0.0, 0.0))
    ts = np.concatenate([t for t, _ in finite])
    ys = np.concatenate([y for _, y in finite])
    lo, hi = float(ys.min()), float(ys.max())
    span = hi - lo if hi > lo else max(abs(hi), 1.0) * 0.1
    lo, hi = lo - Y_MARGIN * span, hi + Y_MARGIN * span
    if len(curves) < 2:
        return SeriesLayout((lo, hi), None, (0.0, 0.0))
    longest = max(len(name) for _, _, name in curves)
    w = min(0.9, (LEGEND_PAD_PX + LEGEND_CHAR_PX * longest) / plot_px[0])
    h = min(0.6, (LEGEND_ROW_PX * len(curves) + 8.0) / plot_px[1])
    t0, t1 = float(ts.min()), float(ts.max())
    u = (ts - t0) / (t1 - t0) if t1 > t0 else np.zeros_like(ts)
    v = (ys - lo) / (hi - lo)

    def covered(corner: str) -> int:
        in_x = u >= 1.0 - w if corner.startswith("Right") else u <= w
        in_y = v >= 1.0 - h if corner.endswith("Top") else v <= h
        return int(np.count_nonzero(in_x & in_y))

    corner = min(CORNERS, key=covered)  # ties: the first (top right, where Rerun puts it)
    if covered(corner):
        grow = (hi - lo) * h / (1.0 - h)  # the legend's rows beyond the data
        lo, hi = (lo, hi + grow) if corner.endswith("Top") else (lo - grow, hi)
    return SeriesLayout((lo, hi), corner, (w, h))


def series_view(panel: Panel, curves: Sequence[Curve], panels_in_tab: int) -> rrb.TimeSeriesView:
    """The panel's TimeSeriesView laid out by :func:`series_layout`."""
    import rerun.blueprint as rrb

    lay = series_layout(curves, plot_px(panels_in_tab))
    legend = (
        rrb.PlotLegend(visible=False)
        if lay.corner is None
        else rrb.PlotLegend(corner=getattr(rrb.Corner2D, lay.corner), visible=True)
    )
    return rrb.TimeSeriesView(
        origin=panel.entity,
        name=panel.title,
        axis_y=rrb.ScalarAxis(range=lay.y_range, zoom_lock=False),
        plot_legend=legend,
    )


def panel_tabs(panels: Sequence[Panel]) -> list[tuple[str, list[Panel]]]:
    """The panels as tabs: consecutive panels of a group share one, at most
    :data:`PANELS_PER_TAB` each (a larger group is split: ``control 1``, ``control 2``)."""
    groups: list[tuple[str, list[Panel]]] = []
    for p in panels:
        if groups and groups[-1][0] == p.group:
            groups[-1][1].append(p)
        else:
            groups.append((p.group, [p]))
    tabs = []
    for name, members in groups:
        chunks = [members[i : i + PANELS_PER_TAB] for i in range(0, len(members), PANELS_PER_TAB)]
        for k, chunk in enumerate(chunks):
            tabs.append((f"{name} {k + 1}" if len(chunks) > 1 else name, chunk))
    return tabs


def shown_panels(panels: Sequence[Panel]) -> list[Panel]:
    """The panels a reader sees on opening the recording (the first tab's)."""
    tabs = panel_tabs(panels)
    return tabs[0][1] if tabs else []


def blueprint(
    panels: Sequence[Panel],
    loops: Sequence[LoopView],
    *,
    with_3d: bool = True,
    metadata: str | None = "run/metadata",
    curves: Mapping[str, Sequence[Curve]] | None = None,
) -> rrb.Blueprint:
    """The layout: 3-D arm and metadata, the loop panels (framed to their plot), the time-series
    panels in tabs of one column (:func:`panel_tabs`), each laid out from its ``curves`` (panel
    name -> curves; :func:`series_layout`); Rerun's side panels start collapsed (the views get
    the room)."""
    import rerun.blueprint as rrb

    loop_views = [
        rrb.Spatial2DView(
            origin=lp.entity,
            name=lp.title,
            visual_bounds=rrb.VisualBounds2D(x_range=(0.0, lp.width), y_range=(0.0, lp.height)),
            background=(255, 255, 255),
        )
        for lp in loops
    ]
    meta = [rrb.TextDocumentView(origin=metadata, name="run")] if metadata is not None else []
    arm = (
        [
            rrb.Spatial3DView(
                origin="world",
                name="arm (3-D)",
                # the whole arm in view at any pose (reach ~0.85 m from the base; visual only)
                eye_controls=rrb.EyeControls3D(
                    kind=rrb.Eye3DKind.Orbital,
                    position=CAMERA_EYE_M,
                    look_target=CAMERA_TARGET_M,
                    eye_up=(0.0, 0.0, 1.0),
                ),
            )
        ]
        if with_3d
        else []
    )
    # one loop: it shares its column with the metadata and the arm gets a full column
    left: list[Any] = arm + (meta if len(loop_views) != 1 else [])
    middle: list[Any] = loop_views + (meta if len(loop_views) == 1 else [])
    columns: list[Any] = []
    shares: list[float] = []
    for views, share in ((left, 2.0), (middle, 2.2)):
        if views:
            rows = [
                3.0 if isinstance(v, rrb.Spatial3DView | rrb.Spatial2DView) else 1.0 for v in views
            ]
            columns.append(rrb.Vertical(*views, row_shares=rows))
            shares.append(share)
    tabs = [
        rrb.Vertical(
            *(series_view(p, (curves or {}).get(p.name, ()), len(members)) for p in members),
            name=name,
        )
        for name, members in panel_tabs(panels)
    ]
    if tabs:
        columns.append(tabs[0] if len(tabs) == 1 else rrb.Tabs(*tabs, active_tab=0))
        shares.append(3.0)
    return rrb.Blueprint(
        rrb.Horizontal(*columns, column_shares=shares),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
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


# --------------------------------------------------------------------------- an arm run


def log_arm_run(
    rec: rr.RecordingStream, result: RunResult, rate_hz: float | None = DEFAULT_RATE_HZ
) -> rrb.Blueprint:
    """Log a finished arm run into ``rec``; return the blueprint that lays it out."""
    import rerun as rr

    from fsarm_sim.records.timeseries import run_metadata

    cols, rows = log_arm_world(rec, result, rate_hz)
    rec.log(
        "run/metadata",
        rr.TextDocument(
            metadata_markdown(run_metadata(result), result.metrics), media_type="text/markdown"
        ),
        static=True,
    )
    panels = ARM_PANELS + state_panels(result)
    cols.update(state_columns(result))
    log_scalar_panels(rec, cols, panels, rows)
    views = log_arm_loops(rec, result, cols, rows)
    shown = informative_panels(cols, panels)
    return blueprint(shown, views, curves={p.name: panel_curves(p, cols) for p in shown})


def state_columns(result: RunResult) -> dict[str, Array]:
    """``state_<name>`` columns of the run's internal states (those recorded at its rows)."""
    n = len(result.columns["t"])
    return {f"state_{k}": v for k, v in result.states.items() if len(v) == n}


def run_panels(result: RunResult) -> list[Panel]:
    """The time-series panels a run's recording shows (informative ones, states included)."""
    cols = {**with_derived(result.columns), **state_columns(result)}
    return informative_panels(cols, ARM_PANELS + state_panels(result))


def log_arm_world(
    rec: rr.RecordingStream, result: RunResult, rate_hz: float | None = DEFAULT_RATE_HZ
) -> tuple[dict[str, Array], npt.NDArray[np.intp]]:
    """Log the 3-D arm of a run (geoms, body motion, shaft route); return the run's columns with
    the derived ones (:func:`with_derived`) and the logged row indices."""
    import rerun as rr

    with callbacks.suspended():  # a private copy for kinematics only; it is never stepped
        model = build_spec(result.config, np.zeros((1, layout.REF_COLS))).compile()
    st = read_structure(model)
    cols = with_derived(result.columns, tau_motor_limit_nm=st.tau_max[2])
    rows = decimate(cols["t"], rate_hz)
    t = cols["t"][rows]
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
    return cols, rows


def log_arm_loops(
    rec: rr.RecordingStream,
    result: RunResult,
    cols: Columns,
    rows: npt.NDArray[np.intp],
    loops: Sequence[Loop] = ARM_LOOPS,
) -> list[LoopView]:
    """Log the run's informative loop panels, with the catalogue's model curves when joint 3 is
    driven by the flexible shaft; return their views for the blueprint."""
    sh = result.config.shaft
    flexible = result.config.transmission == "flexible-shaft"
    subtitle = (
        f"{result.scenario}: D = {sh.diameter_mm:g} mm, L = {sh.length_mm:g} mm"
        if flexible
        else f"{result.scenario}: {result.config.transmission}"
    )
    views = []
    for lp in loops:
        if not loop_is_informative(lp, cols):
            continue
        trace = Trace("run", "plant", BLUE, lp.y)
        model = shaft_model_curves(lp, cols, sh) if flexible else []
        image = loop_image(lp, [(trace, cols)], model, subtitle=subtitle)
        log_loop_panel(rec, lp, [(trace, cols, rows)], image)
        views.append(LoopView(lp.entity, lp.title, image.width, image.height))
    return views


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
