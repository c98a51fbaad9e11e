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

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.model import build_spec, read_structure
from fsarm_sim.kernels import layout
from fsarm_sim.review.arm_scene import arm_geoms, joint_qpos, log_arm_motion, log_geoms
from fsarm_sim.review.blueprint import PANELS_PER_TAB as PANELS_PER_TAB
from fsarm_sim.review.blueprint import Curve as Curve
from fsarm_sim.review.blueprint import LoopView as LoopView
from fsarm_sim.review.blueprint import SeriesLayout as SeriesLayout
from fsarm_sim.review.blueprint import blueprint as blueprint
from fsarm_sim.review.blueprint import informative_panels as informative_panels
from fsarm_sim.review.blueprint import metadata_markdown as metadata_markdown
from fsarm_sim.review.blueprint import panel_curves as panel_curves
from fsarm_sim.review.blueprint import panel_tabs as panel_tabs
from fsarm_sim.review.blueprint import series_layout as series_layout
from fsarm_sim.review.blueprint import shown_panels as shown_panels
from fsarm_sim.review.loop_panels import (
    ARM_LOOPS,
    Loop,
    Trace,
    log_loop_panel,
    loop_image,
    loop_is_informative,
    shaft_model_curves,
)
from fsarm_sim.review.panels import APPLICATION_ID as APPLICATION_ID
from fsarm_sim.review.panels import ARM_PANELS as ARM_PANELS
from fsarm_sim.review.panels import BLUE as BLUE
from fsarm_sim.review.panels import DEFAULT_RATE_HZ as DEFAULT_RATE_HZ
from fsarm_sim.review.panels import GREEN as GREEN
from fsarm_sim.review.panels import GREY as GREY
from fsarm_sim.review.panels import ORANGE as ORANGE
from fsarm_sim.review.panels import PURPLE as PURPLE
from fsarm_sim.review.panels import RED as RED
from fsarm_sim.review.panels import Array, Columns
from fsarm_sim.review.panels import Panel as Panel
from fsarm_sim.review.panels import Series as Series
from fsarm_sim.review.panels import decimate as decimate
from fsarm_sim.review.panels import log_scalar_panels as log_scalar_panels
from fsarm_sim.review.panels import state_panels as state_panels
from fsarm_sim.review.panels import with_derived as with_derived

if TYPE_CHECKING:
    import rerun as rr
    import rerun.blueprint as rrb

    from fsarm_sim.sim.simulation import RunResult

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


def save_recording(
    rec: rr.RecordingStream, path: Path, log: Callable[[rr.RecordingStream], rrb.Blueprint]
) -> Path:
    """Stream ``rec`` into the file ``path`` (its folder made), log into it with ``log`` and send
    the blueprint ``log`` returns; the stream is closed even when logging fails. Returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    rec.save(path)
    try:
        rec.send_blueprint(log(rec), make_active=True, make_default=True)
        rec.flush()
    finally:
        rec.disconnect()
    return path


def record_run(result: RunResult, path: Path, rate_hz: float | None = DEFAULT_RATE_HZ) -> Path:
    """Write ``result`` as a Rerun recording (``.rrd``) with its blueprint; return the path."""
    return save_recording(new_stream(result), path, lambda rec: log_arm_run(rec, result, rate_hz))


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
