"""Scenario runner: owns the loop and the clocks, records time series, fails on MuJoCo warnings."""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks
from fsarm_sim.engine.lean import check_springs_off, stiffness_views
from fsarm_sim.engine.model import (
    SimConfig,
    build_model,
    law_state_names,
    read_structure,
)
from fsarm_sim.errors import (
    InvalidParameterError,
    ModelStructureError,
    RunFailedError,
    RunHealthError,
    real_number,
    whole_number,
)
from fsarm_sim.kernels import layout
from fsarm_sim.sim import scenarios
from fsarm_sim.sim.run_memory import MADV_POPULATE_WRITE as MADV_POPULATE_WRITE
from fsarm_sim.sim.run_memory import MAX_STEPS as MAX_STEPS
from fsarm_sim.sim.run_memory import MEMORY_SHARE as MEMORY_SHARE
from fsarm_sim.sim.run_memory import PAGE_BYTES as PAGE_BYTES
from fsarm_sim.sim.run_memory import available_memory_bytes as available_memory_bytes
from fsarm_sim.sim.run_memory import check_run_size
from fsarm_sim.sim.run_memory import resident_empty as resident_empty
from fsarm_sim.sim.run_metrics import compute_metrics as compute_metrics
from fsarm_sim.sim.run_metrics import kernel_metrics
from fsarm_sim.sim.run_start import check_clock as check_clock
from fsarm_sim.sim.run_start import clock_gap_steps as clock_gap_steps
from fsarm_sim.sim.run_start import initial_state as initial_state
from fsarm_sim.sim.run_start import raise_on_warning as raise_on_warning
from fsarm_sim.sim.run_start import static_twist as static_twist

Array = npt.NDArray[np.float64]
Backend = callbacks.Backend
DEFAULT_BACKEND = callbacks.DEFAULT_BACKEND
MAX_DURATION_S = 3600.0
DEFAULT_TIMESTEP_S = 0.001  # models/fsarm/fsarm.xml <option timestep>, used before a model exists
# log one row every N control ticks: N above the most steps a run may take records the first row
# only, like any N longer than the run; beyond it N is refused (it would overflow the kernels' ints)
MAX_LOG_EVERY = MAX_STEPS
# steps: MuJoCo warnings and the run's health are checked this often (2 s at the default 1 ms
# step, ~5 ms of a native run's wall time). Every check hands the GIL back and forth, which
# threads stepping side by side (a sweep's default executor) pay for (`fsarm bench-speed`).
WARNING_CHECK_EVERY = 2000
# A joint whose tracking error exceeds this has left any controlled motion (the worst seed
# transmission, tendon-sheath hunting, stays below 15 deg): the run is reported as diverged.
DIVERGENCE_LIMIT_RAD = math.radians(45.0)


@dataclass
class RunResult:
    scenario: str
    config: SimConfig
    duration_s: float
    columns: dict[str, Array]
    metrics: dict[str, float | dict[str, float]] = field(default_factory=dict)
    interrupted: bool = False  # Ctrl-C ended the run early; columns hold what was finished
    # internal states at the recorded rows (data.act): the transmission's own (its STATES, e.g.
    # the shaft's slip elements) and the conduit branches; for review, not written to the table
    states: dict[str, Array] = field(default_factory=dict)
    # named warnings about the run (e.g. tracking far from what the scenario is built for)
    warnings: tuple[str, ...] = ()


def check_duration(duration_s: float) -> float:
    if (
        isinstance(duration_s, bool)  # True is not 1 s
        or not isinstance(duration_s, int | float)
        or not math.isfinite(duration_s)
        or duration_s <= 0.0
    ):
        raise InvalidParameterError(
            f"duration must be a finite number of seconds > 0, got {duration_s!r}"
        )
    if duration_s > MAX_DURATION_S:
        raise InvalidParameterError(
            f"duration must be at most {MAX_DURATION_S:g} s per run, got {duration_s!r}"
        )
    return float(duration_s)


class Simulation:
    """One configured model and data, stepped with fsarm's callbacks.

    ``lean`` (default): step the lean twin (:mod:`fsarm_sim.engine.lean`: no visual geoms or
    sensors, the same dynamics to the last bit); ``lean=False`` keeps them in ``self.model``.
    """

    def __init__(
        self,
        config: SimConfig,
        ref_table: Array,
        backend: Backend = DEFAULT_BACKEND,
        lean: bool = True,
    ) -> None:
        self.config = config
        self.model = build_model(config, ref_table, lean=lean)
        self.data = mujoco.MjData(self.model)
        self.structure = read_structure(self.model)
        if backend not in ("python", "native"):
            raise InvalidParameterError(f"backend must be 'python' or 'native', got {backend!r}")
        self.backend: Backend = backend
        self.interrupted = False
        self._rows = 0
        self._step0 = 0
        self._stride = 1
        # per-control-tick Python hooks (scripted disturbances, outer loops); none: the loop is
        # exactly the hook-free one
        self.hooks: list[scenarios.TickHook] = []
        self.states: dict[str, Array] = {}  # internal states at the rows of the last run()
        self._views_of: mujoco.MjModel | None = None
        self._prm: Array = np.empty(0)
        self._ref: Array = np.empty((0, layout.REF_COLS))
        self._stiffness: tuple[Array, ...] = ()
        initial_state(self.model, self.data, self.structure)

    def _views(self) -> tuple[Array, Array]:
        """(``fsarm_params``, reference table as rows) of ``self.model``: views into the model,
        so they see every write; looked up again only if ``self.model`` was replaced (a lookup by
        name took a few us of every health check). The stiffness views of
        :func:`.lean.check_springs_off` are kept with them."""
        m = self.model
        if self._views_of is not m:
            self._prm = m.numeric(layout.PARAMS_NAME).data
            self._ref = m.numeric(layout.REF_NAME).data.reshape(-1, layout.REF_COLS)
            self._stiffness = stiffness_views(m)
            self._views_of = m
        return self._prm, self._ref

    def _check_springs(self) -> None:
        """:func:`.lean.check_springs_off` on the kept views (it runs on every ``step``)."""
        self._views()
        check_springs_off(self.model, self._stiffness)

    @property
    def params(self) -> Array:
        return self._views()[0]

    def step(self, n: int = 1) -> None:
        """``n`` physics steps with fsarm's callbacks active."""
        check_clock(self.model, self.data)
        self._check_springs()
        with callbacks.active(self.backend):
            mujoco.mj_step(self.model, self.data, nstep=n)

    def start_at(self, time_s: float) -> None:
        """Start the run's clock at ``time_s`` instead of 0 (the first control tick is then the
        reference row of that time); only before the first step."""
        if self.data.userdata[layout.U_STEP] > 0.0:
            raise InvalidParameterError("start_at() is only allowed before the first step")
        if not math.isfinite(time_s) or time_s < 0.0:
            raise InvalidParameterError(
                f"start time must be a finite number >= 0 s, got {time_s!r}"
            )
        self.data.time = float(time_s)
        self.data.userdata[layout.U_STEP_T] = float(time_s)

    def step_index(self) -> int:
        """Index of the physics step that starts at the current state, by the control clock's
        own count (``data.time`` alone drifts by rounding over long runs)."""
        d = self.data
        ud = d.userdata
        h = float(self._views()[0][layout.P_TIMESTEP])
        if ud[layout.U_STEP] < 1.0:
            return round(float(d.time) / h)
        return int(ud[layout.U_STEP]) - 1 + round((float(d.time) - float(ud[layout.U_STEP_T])) / h)

    def metrics(self) -> dict[str, float | dict[str, float]]:
        """Tracking and effort metrics accumulated by the control kernel on every physics step
        since the start (independent of logging): see ``layout.A_*``."""
        return kernel_metrics(self.data.userdata[layout.U_ACC : layout.U_ACC + layout.N_ACC])

    def health(self) -> None:
        """Raise :class:`RunHealthError` if the state is not finite, the control clock stopped,
        or a joint left its reference by more than ``DIVERGENCE_LIMIT_RAD``.

        Called between chunks of every run: Python scalars on views kept per model (a few us).
        """
        m, d, st = self.model, self.data, self.structure
        prm, ref = self._views()
        t = float(d.time)
        qpos = d.qpos.tolist()
        if not (all(map(math.isfinite, qpos)) and all(map(math.isfinite, d.qvel.tolist()))):
            bad = [f"q{j + 1}" for j in range(3) if not math.isfinite(qpos[st.qadr[j]])]
            raise RunHealthError(
                f"run diverged at t = {t:.4f} s: the state is not finite ({', '.join(bad) or 'rotor'})"
            )
        steps = clock_gap_steps(m, d, prm)
        if steps is None:
            return
        ud = d.userdata
        h = float(m.opt.timestep)
        tick = float(ud[layout.U_TICK])
        if ud[layout.U_STEP] < 1.0 or steps > 1.5:
            raise RunHealthError(
                f"control clock stopped at t = {t:.6f} s: it last saw a step at "
                f"t = {ud[layout.U_STEP_T]:.6f} s (timestep {h:g} s), so the controllers' "
                "outputs are frozen"
            )
        ctrl_dt = self.config.gains.ctrl_dt_s
        per_tick = round(ctrl_dt / h)
        due = self.step_index() // per_tick  # the tick the controllers should be at
        ticked = int(tick) - 1
        if ticked < due - 1:
            raise RunHealthError(
                f"controllers stopped at t = {t:.6f} s: their last tick was #{ticked} "
                f"(t = {ticked * ctrl_dt:.6f} s) but #{due} is due, so their "
                "outputs are frozen"
            )
        k = min(int(tick) - 1, ref.shape[0] - 1)
        row = ref[k, :3].tolist()
        for j in range(3):
            q = qpos[st.qadr[j]]
            e = q - row[j]
            if abs(e) > DIVERGENCE_LIMIT_RAD:
                raise RunHealthError(
                    f"run diverged at t = {t:.4f} s: joint q{j + 1} is "
                    f"{math.degrees(e):+.1f} deg from its reference (limit "
                    f"{math.degrees(DIVERGENCE_LIMIT_RAD):.0f} deg; q{j + 1} = "
                    f"{math.degrees(q):.2f} deg, reference {math.degrees(row[j]):.2f} deg, "
                    f"speed {math.degrees(d.qvel[st.dof[j]]):.1f} deg/s, joint-3 motor torque "
                    f"{ud[layout.U_OUT + 2]:.3g} N·m)"
                )

    def _check_before_run(self, duration_s: float, log_every_ticks: int) -> None:
        """The model's timestep as built, the run's size, the clock and the springs."""
        m, d = self.model, self.data
        if m.opt.timestep != self.params[layout.P_TIMESTEP]:
            raise InvalidParameterError(
                f"model.opt.timestep was changed to {m.opt.timestep:g} s after the model was built "
                f"for {self.params[layout.P_TIMESTEP]:g} s; set SimConfig.timestep_s instead"
            )
        check_run_size(
            duration_s,
            m.opt.timestep,
            self.config.gains.ctrl_dt_s,
            int(log_every_ticks),
            m.nq + m.nv + m.na + layout.N_USERDATA_LOGGED,
        )
        check_clock(m, d)
        self._check_springs()

    def _arm_recorder(self, stride: float, cap: int) -> None:
        """Set the control kernel's recorder: a row every ``stride`` steps (0: off) from now."""
        ud = self.data.userdata
        ud[layout.U_REC_STRIDE] = stride
        ud[layout.U_REC_NEXT] = self._step0
        ud[layout.U_REC_LAST] = -1.0
        ud[layout.U_REC_ROWS] = 0.0
        ud[layout.U_REC_CAP] = cap
        ud[layout.U_REC_LOST] = 0.0

    def _recorded_columns(self, rec: Array) -> dict[str, Array]:
        """The columns of the rows drained into ``rec`` (and ``self.states`` from them)."""
        r = self._rows
        nq, nv, na = self.model.nq, self.model.nv, self.model.na
        self.states = self._states(rec[:r, 1 + nq + nv : 1 + nq + nv + na])
        return self._columns(
            rec[:r, 0],
            rec[:r, 1 : 1 + nq],
            rec[:r, 1 + nq : 1 + nq + nv],
            rec[:r, 1 + nq + nv : 1 + nq + nv + na],
            rec[:r, 1 + nq + nv + na :],
        )

    def run(
        self, duration_s: float, log_every_ticks: int = 1, *, keep_partial: bool = False
    ) -> tuple[dict[str, Array], float]:
        """Step for ``duration_s``; return recorded columns and the stepping wall time (s).

        The reference table has one row per control tick; a run that goes past its last row
        repeats that row as it is (its positions, speeds and accelerations, and the recorded
        ``*_ref`` columns with them). Build the table for the whole run (``Scenario.table``)
        unless that hold is what you want.

        Ctrl-C (KeyboardInterrupt) stops the run early. ``keep_partial``: keep what was recorded
        - the columns then end at the interruption and ``self.interrupted`` is True (``fsarm
        run``: a long run is not lost). Otherwise (studies, sweeps, fits: a cut run's numbers
        would pass for a whole run's) the KeyboardInterrupt propagates after the run is cleaned
        up.
        """
        duration_s = check_duration(duration_s)
        log_every_ticks = whole_number(
            log_every_ticks, "log_every_ticks (0: no logging)", 0, MAX_LOG_EVERY
        )
        m, d = self.model, self.data
        self._check_before_run(duration_s, log_every_ticks)
        steps_per_tick = round(self.config.gains.ctrl_dt_s / m.opt.timestep)
        n_steps = round(duration_s / m.opt.timestep)
        stride = steps_per_tick * log_every_ticks if log_every_ticks > 0 else n_steps + 1
        n_rec = n_steps // stride + 1 if log_every_ticks > 0 else 0
        self._stride = stride
        width = layout.rec_width(m.nq, m.nv, m.na)
        cap = (m.nuserdata - layout.N_USERDATA) // width
        if n_rec and cap < 1:
            raise ModelStructureError(
                f"the model has no recording buffer (nuserdata {m.nuserdata} < "
                f"{layout.N_USERDATA + width}): build it with engine.model.build_model"
            )
        rec = resident_empty((n_rec, width))  # its page faults out of the timed loop
        self._step0 = self.step_index()
        self.interrupted = False
        self._rows = 0
        failure: RunFailedError | None = None
        ud = d.userdata
        self._arm_recorder(stride if n_rec else 0.0, cap)
        with callbacks.active(self.backend):
            start = _time.perf_counter()
            try:
                self._loop(n_steps, n_rec, stride, rec, cap)
            except KeyboardInterrupt:
                self.interrupted = True
            except RunFailedError as exc:
                failure = exc
            finally:
                ud[layout.U_REC_STRIDE] = 0.0  # recording off outside run()
            wall = _time.perf_counter() - start
        if self.interrupted and not keep_partial:
            raise KeyboardInterrupt
        if ud[layout.U_REC_LOST] > 0.0:
            raise ModelStructureError(
                f"the run recorder lost {int(ud[layout.U_REC_LOST])} rows (a full buffer): a bug"
            )
        cols = self._recorded_columns(rec)
        try:
            if failure is not None:
                raise failure
            raise_on_warning(d)
            if not self.interrupted:
                self.health()
        except RunFailedError as exc:
            exc.columns = dict(cols)  # keep what was recorded up to the failure
            raise
        return cols, wall

    def _loop(self, n_steps: int, n_rec: int, stride: int, rec: Array, cap: int) -> None:
        """Step ``n_steps`` in chunks; the control kernel records a row every ``stride`` steps
        into the recorder's buffer (``physics.record_row``), drained into ``rec`` after every
        chunk (a chunk never holds more rows than the buffer). Warnings and health are checked
        between chunks, and per-tick hooks run at their ticks.

        ``self._rows`` counts the rows drained, so an interruption keeps them."""
        m, d = self.model, self.data
        ud = d.userdata
        width = rec.shape[1]
        buf = (
            ud[layout.U_REC_BUF : layout.U_REC_BUF + cap * width].reshape(cap, width)
            if n_rec
            else rec
        )
        step = 0
        per_tick = round(self.config.gains.ctrl_dt_s / m.opt.timestep)
        hooks = self.hooks
        next_check = WARNING_CHECK_EVERY
        try:
            while step < n_steps:
                if step >= next_check:
                    raise_on_warning(d)
                    self.health()
                    next_check = step + WARNING_CHECK_EVERY
                if hooks and step % per_tick == 0:
                    for hook in hooks:
                        hook(step // per_tick)
                chunk = min(next_check - step, n_steps - step)
                if n_rec:
                    chunk = min(chunk, cap * stride - step % stride)
                if hooks:
                    chunk = min(chunk, per_tick - step % per_tick)
                mujoco.mj_step(m, d, nstep=chunk)
                step += chunk
                self._drain(rec, buf)
        finally:
            self._drain(rec, buf)

    def _states(self, act: Array) -> dict[str, Array]:
        """The transmission's states (named by its module's STATES) and the conduit branches."""
        st = self.structure
        out = {
            name: act[:, st.act_slip + i].copy()
            for i, name in enumerate(self.config.transmission_model().states)
        }
        for i, adr in enumerate(st.act_branch):
            out[f"conduit_branch{i + 1}"] = act[:, adr].copy()
        return out

    def _drain(self, rec: Array, buf: Array) -> None:
        """Move the recorder's rows into ``rec`` (after ``self._rows``)."""
        ud = self.data.userdata
        rows = int(ud[layout.U_REC_ROWS])
        if rows == 0:
            return
        r = self._rows
        n = min(rows, rec.shape[0] - r)
        rec[r : r + n] = buf[:n]
        self._rows = r + n
        ud[layout.U_REC_ROWS] = 0.0
        ud[layout.U_REC_LAST] = -1.0

    def _columns(
        self, t: Array, qpos: Array, qvel: Array, act: Array, ud: Array
    ) -> dict[str, Array]:
        st = self.structure
        ref = self._views()[1]
        # the tick each row's step belongs to (the control clock's own count, never data.time)
        per_tick = round(self.config.gains.ctrl_dt_s / self.model.opt.timestep)
        stride = self._stride
        steps = self._step0 + stride * np.arange(len(t))
        ref = ref[np.clip(steps // per_tick, 0, ref.shape[0] - 1)]  # each row's reference, once
        theta_m = st.coef_m * qpos[:, st.qadr[3]]
        theta_s = st.coef_s * qpos[:, st.qadr[2]]
        log = ud[:, layout.U_LOG :]
        cols: dict[str, Array] = {"t": t}
        for j in range(3):
            cols[f"q{j + 1}"] = qpos[:, st.qadr[j]]
        for j in range(3):
            cols[f"q{j + 1}_ref"] = ref[:, j]
        for j in range(3):
            cols[f"qd{j + 1}"] = qvel[:, st.dof[j]]
        for j in range(3):
            cols[f"qd{j + 1}_ref"] = ref[:, 3 + j]
        for j in range(3):  # the whole reference: a replay of the record needs no differences
            cols[f"qdd{j + 1}_ref"] = ref[:, 6 + j]
        cols.update(
            theta_m=theta_m,
            theta_s=theta_s,
            twist=theta_m - theta_s,
            phi_b=qpos[:, st.qadr[1]],
            omega_m=st.coef_m * qvel[:, st.dof[3]],
            omega_d=log[:, layout.L_OMEGA_D],
            # computed by the passive kernel at the row's state (never recomputed here)
            tau_shaft=log[:, layout.L_TAU_SHAFT],
            tau_model=log[:, layout.L_TAU_MODEL],
            tau_d_shaft=log[:, layout.L_TAU_D_SHAFT],
            tau_d_joint3=log[:, layout.L_TAU_D_JOINT],
            tau_bend=log[:, layout.L_TAU_BEND],
            tau_conduit=log[:, layout.L_TAU_CONDUIT],
            pid_p=log[:, layout.L_PID_P],
            pid_i=log[:, layout.L_PID_I],
            pid_d=log[:, layout.L_PID_D],
            tau1=ud[:, layout.U_OUT],
            tau2=ud[:, layout.U_OUT + 1],
            tau_motor=ud[:, layout.U_OUT + 2],
        )
        for effect, state in law_state_names(self.config.effects):  # the laws' own states
            a = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{effect}.{state}")
            cols[f"{effect}.{state}"] = act[:, int(self.model.actuator_actadr[a])]
        return cols


def disturbance_hook(sim: Simulation, dist: scenarios.Disturbance) -> scenarios.TickHook:
    """Tick hook applying ``dist`` at its site through ``qfrc_applied`` (held over the tick).

    The site's pose comes from a scratch copy of the state (``mj_kinematics``/``mj_comPos``), so
    the run's own data is only written in ``qfrc_applied``.
    """
    m = sim.model
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, dist.site)
    if site < 0:
        raise InvalidParameterError(f"the arm has no site named {dist.site!r} to apply a force at")
    body = int(m.site_bodyid[site])
    scratch = mujoco.MjData(m)
    zero = np.zeros(3)

    def apply(k: int) -> None:
        scratch.qpos[:] = sim.data.qpos
        mujoco.mj_kinematics(m, scratch)
        mujoco.mj_comPos(m, scratch)
        force = scratch.site_xmat[site].reshape(3, 3) @ np.asarray(
            dist.force_n(k * sim.config.gains.ctrl_dt_s), dtype=np.float64
        )
        sim.data.qfrc_applied[:] = 0.0
        mujoco.mj_applyFT(
            m, scratch, force, zero, scratch.site_xpos[site], body, sim.data.qfrc_applied
        )

    return apply


def run_scenario(
    name: str | scenarios.Scenario,
    config: SimConfig | None = None,
    *,
    duration_s: float | None = None,
    payload_kg: float | None = None,
    backend: Backend = DEFAULT_BACKEND,
    log_every_ticks: int = 1,
    lean: bool = True,
    keep_partial: bool = False,
) -> RunResult:
    """Run a registered scenario (or a :class:`~fsarm_sim.sim.scenarios.Scenario`) headless and
    compute its metrics. Its disturbance and outer loop, if any, run once per control tick.
    ``lean``: step the lean twin of the model (the same dynamics; see :class:`Simulation`).
    ``keep_partial``: on Ctrl-C return what was recorded (``interrupted`` set; metrics over the
    finished part) instead of raising KeyboardInterrupt (:meth:`Simulation.run`)."""
    sc = name if isinstance(name, scenarios.Scenario) else scenarios.get(name)
    duration = check_duration(sc.duration_s if duration_s is None else duration_s)
    log_every_ticks = whole_number(
        log_every_ticks, "log every N control ticks (--log-every): N", 1, MAX_LOG_EVERY
    )
    if payload_kg is not None:
        real_number(payload_kg, "payload_kg (--payload-kg)")
    cfg = config or SimConfig()
    cfg = cfg.with_(payload_kg=sc.payload_kg if payload_kg is None else payload_kg)
    cfg.validate()
    timestep = cfg.timestep_s if cfg.timestep_s is not None else DEFAULT_TIMESTEP_S
    check_run_size(duration, timestep, cfg.gains.ctrl_dt_s, int(log_every_ticks), 120)
    n_ticks = round(duration / cfg.gains.ctrl_dt_s) + 1
    table = sc.table(n_ticks, cfg.gains.ctrl_dt_s)
    sim = Simulation(cfg, table, backend, lean=lean)
    if sc.disturbance is not None:
        sim.hooks.append(disturbance_hook(sim, sc.disturbance))
    if sc.outer_loop is not None:
        sim.hooks.append(sc.outer_loop(sim))
    cols, wall = sim.run(duration, log_every_ticks=int(log_every_ticks), keep_partial=keep_partial)
    if sim.interrupted:
        if len(cols["t"]) < 2:
            raise KeyboardInterrupt  # nothing worth keeping yet
        duration = sim.step_index() * float(sim.model.opt.timestep)
    metrics = compute_metrics(
        cols, duration, wall, sim.structure, cfg.rating_nm(), acc=sim.data.userdata[layout.U_ACC :]
    )
    return RunResult(
        scenario=sc.name,
        config=cfg,
        duration_s=duration,
        columns=cols,
        metrics=metrics,
        interrupted=sim.interrupted,
        states=sim.states,
        warnings=sc.tracking_warnings(metrics["rmse_deg"]),  # type: ignore[arg-type]
    )
