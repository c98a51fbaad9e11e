"""The arm's closed-loop replay and fits: rebuild a recorded run, simulate a model of it, fit the
nominal refit and the candidate effects (the arm's :class:`~.setup_protocol.Setup` is :mod:`.arm`).

**Replay.** An ``arm`` record (:mod:`fsarm_sim.records.measured`; sidecar schema :mod:`fsarm_sim.records.sidecar`)
is rebuilt from its sidecar - shaft (a run's exact ``shaft_params`` when recorded), stated
payload, controller gains, control period, timestep, integrator and joint 3's transmission with
its plant and controller parameters - into a :class:`~fsarm_sim.engine.model.SimConfig`,
and the run is simulated by the project's own simulator (MuJoCo + the native callbacks) with the
*recorded* references ``q*_ref`` (``qd*_ref``/``qdd*_ref`` if recorded, else central differences,
see :func:`.arm_run.reference_table`) driving the *run's* controller. The controller always keeps the
stated shaft and payload (what the real controller knew); refits and effects act on the plant
only (``SimConfig.controller_shaft``; the plant-only switches of :class:`~fsarm_sim.engine.model.Effects`).

**Channels.** The recorded ``q3``, ``theta_m`` and ``q2`` are compared in the basis
``q3``, ``twist = theta_m - i_G2 q3`` (the shaft twist, proportional to the shaft torque by eq. 8)
and ``q2`` (joint 2 feels the payload and the bending moment of eq. 2). Each channel's noise floor
``sigma_c`` comes from the data (:func:`.residuals.noise_floor`, at least the quantisation error
q / sqrt(12) of its encoder, :func:`channel_noise`); residuals are divided by it.

**Nominal refit first.** The plant's series stiffness - one scale on eq. 3's ``k`` and ``s``
for both twist signs, or one per sign when the record visits both (each >= 5 % of the samples) -
fitted as a compliance scale (the twist that carries a torque is linear in it), the bending
stiffness ``K_b`` (a scale, fitted when joint 2 bends the shaft by more than 5 deg) and, when the
sidecar states the payload loosely (``payload_tolerance_kg > 0``), the payload within that
tolerance (``payload_error`` is then no candidate). Scales stay within 4x of the catalogue. An
effect is missing only when no such refit removes the disagreement. With a transmission other
than the flexible shaft the series-stiffness scales (eq. 8's) and ``hysteresis[maxwell_slip]``
(the shaft's slip elements) do not apply and are left out.

**Candidates** (grey-box: every parameter acts inside the re-simulated closed loop):

=========================  =============================================================  ====
effect[variant]            acts as                                                        k
=========================  =============================================================  ====
payload_error[mass]        unstated payload mass (the ``payload_error`` law)              1
coulomb_friction[q3]       Coulomb friction at joint 3 (q3's ``dof_frictionloss``)        1
viscous_damping[q3]        extra viscous damping at joint 3 (q3's ``dof_damping``)        1
backlash[twist]            dead band on the shaft twist (width; centre too when the       1-2
                           twist crosses zero, both signs >= 0.2 % of the samples)
hysteresis[maxwell_slip]   elasto-slip elements on the shaft (``ShaftParams.slip_k/f``):  2/el.
                           stiffnesses on a grid of 3 slip deflections, elements below
                           1 % of K dropped, then stiffness and deflection refined
sensor_offset[CH]          constant bias on the recorded channel CH (q3, theta_m, q2)     1
delay[CH]                  the recorded channel CH lags the others by d                   1
=========================  =============================================================  ====

The last two are measurement effects: applied to the simulated channel
(:func:`.arm_model.apply_measurement`), not to the plant. Bounds: :mod:`fsarm_sim.plant.effects.registry`.

**Fitting** (few simulations: a 10 s record costs ~0.15 s per closed-loop run). Each step
linearises the weighted teaching residual once: secant columns (one simulation per plant
parameter; offsets and delays analytic: a constant and ``-dy/dt``) for every parameter already
in the model and every candidate parameter. Every candidate is solved jointly with the present
parameters by bounded linear least squares (:mod:`.lsq`) and *re-simulated* there; when
the nominal refit moved away from the catalogue, also from the catalogue's values (a refit can
mimic an effect - a softer shaft looks like a heavier payload - and the two valleys are not
joined by a straight line), keeping the better. The two most promising effects are then refined
on the simulation itself (Gauss-Newton with fresh secant Jacobians, bounded steps, at most
``REFINE_ITER`` iterations) and all are scored.

Runs are kept by their simulator input (:class:`ArmContext`: two models that build the same
simulator configuration - most effects present at zero - are one run) and the runs a step
needs are simulated side by side (:meth:`ArmContext.prefetch`; the refinements of a step in
lockstep, :func:`refine_many`): the same runs and fits as one after the other (issue 15).

The run read from the record is :mod:`.arm_run`'s, the model and its simulation
(:class:`~.arm_model.ArmModel`, :func:`~.arm_model.to_config`) :mod:`.arm_model`'s, the candidates
and the screening steps :mod:`.arm_screen`'s; the fit context and the refinement are here.

The choice among the fitted candidates is the diagnosis core's (:mod:`.core`, the arm as a
:class:`~.setup_protocol.Setup` in :mod:`.arm`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Generator, Iterator, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from fsarm_sim.discrepancy import lsq, replay_inputs
from fsarm_sim.discrepancy.arm_model import (
    BOUNDS,
    RAW,
    ArmModel,
    apply_measurement,
    simulate_config,
    to_basis,
    to_config,
)
from fsarm_sim.discrepancy.arm_run import ArmReplayError, ArmRun
from fsarm_sim.discrepancy.residuals import noise_floor, split_masks
from fsarm_sim.engine.model import PAYLOAD_MAX_KG, SimConfig
from fsarm_sim.errors import InvalidParameterError, SimulationWarningError
from fsarm_sim.records.measured import (
    Dataset,
)

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

BASIS = ("q3", "twist", "q2")  # fitting / scoring basis: twist = theta_m - i_G2 q3
MAIN = "q3"
MODEL_FORMAT = "fsarm-arm-model"
MODEL_VERSION = 1
SIGMA_MIN = 1e-9  # rad: the CSV's 10 significant digits on angles of a few rad
SIDE_MIN_FRACTION = 0.05  # both twist signs this often: one stiffness scale per sign, else one
BACKLASH_CROSS_FRACTION = 0.002  # both signs this often: the backlash centre is identifiable
KB_MIN_BEND_RAD = math.radians(5.0)  # K_b is refit when joint 2 bends the shaft further
N_SLIP_GRID = 3  # hysteresis: slip deflections tried (ShaftParams has three element slots)


# simulations run side by side where a step needs several (ArmContext.prefetch): the cores this
# process may use, at most 4; FSARM_DIAGNOSE_THREADS overrides (1: one after the other)
def sim_threads() -> int:
    """Simulation threads for a diagnosis step (FSARM_DIAGNOSE_THREADS, else the usable cores,
    at most 4)."""
    given = os.environ.get("FSARM_DIAGNOSE_THREADS", "").strip()
    if given:
        if not given.isdigit() or int(given) < 1:
            raise InvalidParameterError(
                f"FSARM_DIAGNOSE_THREADS must be a whole number >= 1, got {given!r}"
            )
        return int(given)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return min(4, cores or 1)


SIM_THREADS = sim_threads()
# set inside simulation_threads(): the limit for that block, in the thread that entered it
_THREADS: ContextVar[int | None] = ContextVar("fsarm_arm_sim_threads", default=None)


@contextmanager
def simulation_threads(n: int) -> Iterator[None]:
    """For the block, a diagnosis step runs at most ``n`` simulations side by side (1: one after
    the other; ``scripts/bench_diagnose.py`` compares the two). Scoped by a context variable: it
    holds in the thread that entered it, where :meth:`ArmContext.prefetch` reads it; the previous
    limit comes back on exit."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InvalidParameterError(f"simulation threads must be a whole number >= 1, got {n!r}")
    token = _THREADS.set(n)
    try:
        yield
    finally:
        _THREADS.reset(token)


def threads_now() -> int:
    """Simulations a diagnosis step may run side by side here (:func:`simulation_threads`, else
    :data:`SIM_THREADS`)."""
    n = _THREADS.get()
    return SIM_THREADS if n is None else n


REFINE_ITER = 3  # Gauss-Newton iterations of a refinement (each: free parameters + 1 runs)
NOMINAL_ITER = 5
REFINE_SECANT = 0.1  # secant step of the refinement, in units of each parameter's magnitude
REFINE_RTOL = 1e-3  # stop when an iteration lowers the teaching cost by less than this
N_REFINE = 2  # effects refined on the simulation per step (the leader and its runner-up)


# ----------------------------------------------------------------------------- context


@dataclass
class ArmContext:
    """Everything the fits of one record share."""

    ds: Dataset
    run: ArmRun
    coef_s: float
    y: dict[str, FloatArray]  # measured, fitting basis
    raw: dict[str, FloatArray]  # measured q3, theta_m, q2
    teach: BoolArray
    held: BoolArray
    sigma: dict[str, float]  # noise floor per basis channel
    sides: tuple[bool, bool]  # (positive, negative) twist side visited (SIDE_MIN_FRACTION)
    fit_kb: bool
    slip_grid: FloatArray
    two_sided: bool
    cache: dict[tuple[Any, ...], dict[str, FloatArray] | None] = field(default_factory=dict)
    n_sims: int = 0
    # runs by their simulator input (``repr`` of the SimConfig: every field, floats exactly;
    # the reference table is the context's own): two models that differ only in parameters
    # that do not reach the simulator - an effect present at zero, the slip deflection of an
    # element with no stiffness - are one run (issue 15)
    config_cache: dict[str, dict[str, FloatArray] | None] = field(default_factory=dict)

    def _input(self, m: ArmModel) -> tuple[SimConfig | None, str | None]:
        """The simulator input of ``m`` and its key (None, None: the configuration cannot be
        built, so the run fails)."""
        try:
            cfg = to_config(self.run, m)
        except InvalidParameterError:
            return None, None
        return cfg, repr(cfg)

    def _run(self, m: ArmModel) -> dict[str, FloatArray] | None:
        """``m``'s run, simulated now (None: it fails)."""
        return self._run_input(self._input(m)[0])

    def _run_input(self, cfg: SimConfig | None) -> dict[str, FloatArray] | None:
        if cfg is None:
            return None
        try:
            raw, _ = simulate_config(self.run, cfg)
        except (InvalidParameterError, SimulationWarningError):
            return None
        return raw if all(np.all(np.isfinite(v)) for v in raw.values()) else None

    def _shared(self, key: tuple[Any, ...], ck: str | None) -> bool:
        """Is a run of the same simulator input ``ck`` known? Then it is filed under ``key`` too."""
        if ck is not None and ck in self.config_cache:
            self.cache[key] = self.config_cache[ck]
            return True
        return False

    def _store(
        self, key: tuple[Any, ...], ck: str | None, raw: dict[str, FloatArray] | None
    ) -> None:
        self.n_sims += 1
        self.cache[key] = raw
        if ck is not None:
            self.config_cache.setdefault(ck, raw)

    def simulate(self, m: ArmModel) -> dict[str, FloatArray] | None:
        key = m.physical_key()
        if key not in self.cache:
            cfg, ck = self._input(m)
            if not self._shared(key, ck):
                self._store(key, ck, self._run_input(cfg))
        return self.cache[key]

    def prefetch(self, models: Sequence[ArmModel | None]) -> None:
        """Run the models not simulated yet side by side (:func:`threads_now` threads: the
        compiled callbacks step in parallel, MuJoCo releases the GIL while stepping); later
        :meth:`simulate` calls find them in the cache. The same runs as one after the other."""
        todo: dict[tuple[Any, ...], tuple[SimConfig | None, str | None]] = {}
        inputs: set[str] = set()
        for m in models:
            if m is None:
                continue
            key = m.physical_key()
            if key in self.cache or key in todo:
                continue
            cfg, ck = self._input(m)
            if self._shared(key, ck) or (ck is not None and ck in inputs):
                continue  # known, or the same run asked for twice: simulate() finds the first
            todo[key] = (cfg, ck)
            if ck is not None:
                inputs.add(ck)
        threads = min(threads_now(), len(todo))
        if threads < 2:
            return  # one run (or one core): simulate() runs it when it is asked for
        with ThreadPoolExecutor(threads) as ex:
            results = list(ex.map(self._run_input, [cfg for cfg, _ in todo.values()]))
        for (key, (_, ck)), raw in zip(todo.items(), results, strict=True):
            self._store(key, ck, raw)

    def predict(self, m: ArmModel) -> tuple[dict[str, FloatArray], dict[str, FloatArray]] | None:
        """(basis, raw) recorded channels the model predicts; None if its run fails."""
        sim = self.simulate(m)
        if sim is None:
            return None
        raw = apply_measurement(sim, m, self.run.h)
        return to_basis(raw, self.coef_s), raw

    def wresid(self, pred: Mapping[str, FloatArray], mask: BoolArray) -> FloatArray:
        return np.concatenate([((self.y[c] - pred[c]) / self.sigma[c])[mask] for c in BASIS])


def quantum(y: FloatArray) -> float:
    """Quantisation step of a recorded channel (0 if it does not look quantised): the smallest
    non-zero sample-to-sample change, when at least 10 % of the changes are exactly zero."""
    d = np.abs(np.diff(y))
    if d.size == 0 or np.mean(d == 0.0) < 0.1:
        return 0.0
    nz = d[d > 1e-12 * max(1.0, float(np.max(np.abs(y))))]
    return float(nz.min()) if nz.size else 0.0


def channel_noise(y: FloatArray) -> float:
    """Noise floor of a channel: the difference-based estimate of :func:`.residuals.noise_floor`,
    at least the quantisation error's q / sqrt(12) (a slow channel of a fine encoder sits on
    one count for long stretches: its 4th differences are mostly zero, its error is not) and at
    least SIGMA_MIN."""
    return max(noise_floor(y), quantum(y) / math.sqrt(12.0), SIGMA_MIN)


def _side_fractions(twist: FloatArray, sigma: float) -> tuple[float, float]:
    thr = 3.0 * sigma
    return float(np.mean(twist > thr)), float(np.mean(twist < -thr))


def make_context(ds: Dataset, run: ArmRun) -> ArmContext:
    """Measured channels, split, noise floors and what the record can identify."""
    c = ds.columns
    raw = {ch: c[ch] for ch in RAW}
    # i_G2 from the compiled model of the stated run (a one-tick build, no stepping)
    from fsarm_sim.engine.model import build_model, read_structure

    try:
        coef_s = read_structure(build_model(to_config(run, ArmModel()), run.ref_table[:2])).coef_s
    except InvalidParameterError as exc:
        raise ArmReplayError(f"{ds.path}: cannot rebuild the run: {exc}") from exc
    y = to_basis(raw, coef_s)
    teach, held = split_masks(ds.n)
    sigma = {ch: channel_noise(y[ch]) for ch in BASIS}
    fp, fn = _side_fractions(y["twist"], sigma["twist"])
    bend = float(np.quantile(np.abs(c["q2"]), 0.9))
    tw = y["twist"]
    ptp = float(np.ptp(tw)) or 1e-3
    return ArmContext(
        ds=ds,
        run=run,
        coef_s=float(coef_s),
        y=y,
        raw=raw,
        teach=teach,
        held=held,
        sigma=sigma,
        sides=(fp >= SIDE_MIN_FRACTION, fn >= SIDE_MIN_FRACTION),
        fit_kb=bend > KB_MIN_BEND_RAD,
        slip_grid=np.geomspace(0.05 * ptp, 0.5 * ptp, N_SLIP_GRID),
        two_sided=min(fp, fn) >= BACKLASH_CROSS_FRACTION,
    )


def nominal_keys(ctx: ArmContext) -> list[str]:
    keys = []
    if not ctx.run.flexible_shaft:
        pass  # the series stiffness refit is eq. 8's: the flexible shaft's own parameters
    elif all(ctx.sides):
        keys += ["c_scale_pos", "c_scale_neg"]
    else:  # a side visited rarely follows the other (a shaft rarely errs one way only)
        keys.append("c_scale")
    if ctx.fit_kb:
        keys.append("kb_scale")
    if ctx.run.payload_tolerance_kg > 0.0:
        keys.append("payload_kg_refit")
    return keys


def bounds_of(ctx: ArmContext, key: str) -> tuple[float, float, float]:
    lo, hi, unit = BOUNDS[key]
    if key == "payload_kg_refit":
        tol = ctx.run.payload_tolerance_kg
        lo, hi = max(-tol, -ctx.run.payload_kg), tol
    elif key == "payload_error.dm_kg":
        lo = max(lo, -ctx.run.payload_kg)
        hi = min(hi, PAYLOAD_MAX_KG - ctx.run.payload_kg)
    return lo, hi, unit


# ----------------------------------------------------------------------------- fits


@dataclass
class ArmFit:
    model: ArmModel
    pred: dict[str, FloatArray]  # basis
    raw: dict[str, FloatArray]
    free: list[str]  # fitted parameters
    k: int
    mse_teach: dict[str, float]
    mse_held: dict[str, float]
    label: str = "nominal"
    effect: str | None = None
    variant: str | None = None
    note: str = ""
    cost: float = math.inf  # weighted teaching sum of squares
    predicted: float = math.inf  # the cost the linearised screening expected

    def w(self, ctx: ArmContext, held: bool = True) -> float:
        """Weighted MSE: mean over channels of MSE_c / sigma_c^2 (1 = at the noise floor)."""
        mse = self.mse_held if held else self.mse_teach
        return float(sum(mse[c] / ctx.sigma[c] ** 2 for c in BASIS)) / len(BASIS)


def n_params(free: list[str], m: ArmModel) -> int:
    """BIC's k: fitted parameters; a hysteresis element counts two (stiffness and slip
    deflection, whether the deflection is on its grid value or refined)."""
    other = [k for k in free if not k.startswith("hysteresis.")]
    return len(other) + 2 * sum(1 for k in free if k.startswith("hysteresis.k"))


def evaluate(
    ctx: ArmContext, m: ArmModel, free: list[str], label: str = "nominal"
) -> ArmFit | None:
    p = ctx.predict(m)
    if p is None:
        return None
    pred, raw = p
    mt = {c: float(np.mean((ctx.y[c] - pred[c])[ctx.teach] ** 2)) for c in BASIS}
    mh = {c: float(np.mean((ctx.y[c] - pred[c])[ctx.held] ** 2)) for c in BASIS}
    r = ctx.wresid(pred, ctx.teach)
    return ArmFit(m, pred, raw, list(free), n_params(free, m), mt, mh, label, cost=float(r @ r))


def with_values(m: ArmModel, keys: list[str], x: FloatArray) -> ArmModel:
    out = m.copy()
    for k, v in zip(keys, x, strict=True):
        out.values[k] = float(v)
    return out


def jacobian_column(
    ctx: ArmContext,
    m: ArmModel,
    base: dict[str, FloatArray],
    raw: dict[str, FloatArray],
    key: str,
    frac: float = 1.0,
) -> FloatArray | None:
    """d(weighted teaching residual) / d(parameter in units of its typical magnitude), by a
    secant over ``frac`` units (plant parameters: one simulation) or analytically (measurement)."""
    unit = bounds_of(ctx, key)[2]
    h = ctx.run.h
    if key.startswith(("sensor_offset.", "delay.")):
        ch = key.split(".", 1)[1]
        # change of the recorded channel: a constant (offset) or y(t - d) ~ y(t) - d y'(t)
        dy = (
            unit
            if key.startswith("sensor_offset.")
            else -replay_inputs.derivative(raw[ch], h) * unit
        )
        d = {c: np.zeros_like(base[c]) for c in BASIS}
        if ch == "q3":  # q3 enters the twist basis as -i_G2 q3
            d["q3"] += dy
            d["twist"] -= ctx.coef_s * dy
        elif ch == "theta_m":
            d["twist"] += dy
        else:
            d["q2"] += dy
    else:
        step = _secant_step(ctx, m, key, frac)
        p = ctx.predict(with_values(m, [key], np.array([m.v(key) + step])))
        if p is None:
            return None
        d = {c: (p[0][c] - base[c]) * (unit / step) for c in BASIS}
    return -np.concatenate([(d[c] / ctx.sigma[c])[ctx.teach] for c in BASIS])


def _secant_step(ctx: ArmContext, m: ArmModel, key: str, frac: float) -> float:
    """The secant's step of a plant parameter: slip deflections relative (they range over
    decades), others one unit; backwards where forwards leaves the bounds."""
    _, hi, unit = bounds_of(ctx, key)
    x0 = m.v(key)
    step = (0.3 * x0 if key.startswith("hysteresis.d") and x0 > 0.0 else unit) * frac
    return step if x0 + step <= hi else -step


def secant_model(ctx: ArmContext, m: ArmModel, key: str, frac: float = 1.0) -> ArmModel | None:
    """The run :func:`jacobian_column` simulates for ``key`` (None: a measurement parameter,
    whose column is analytic)."""
    if key.startswith(("sensor_offset.", "delay.")):
        return None
    return with_values(m, [key], np.array([m.v(key) + _secant_step(ctx, m, key, frac)]))


def linear_solve(
    ctx: ArmContext, m: ArmModel, keys: list[str], jac: FloatArray, r0: FloatArray
) -> ArmModel:
    """Bounded linear least squares for the parameter changes (normalised units)."""
    v = np.array([m.v(k) for k in keys])
    a, b, unit = np.array([bounds_of(ctx, k) for k in keys], dtype=float).reshape(-1, 3).T
    # a value already outside its bounds may stay where it is
    a, b = np.minimum(a, v), np.maximum(b, v)
    dx = lsq.bounded(jac, -r0, (a - v) / unit, (b - v) / unit)
    # a step to a bound lands on it: v + ((a - v) / unit) * unit can round past it (a slip
    # stiffness of -1e-16 N*m/rad, which the transmission then refuses)
    return with_values(m, keys, np.clip(v + dx * unit, a, b))


def refine(ctx: ArmContext, fit: ArmFit, max_iter: int = REFINE_ITER) -> ArmFit:
    """Nonlinear refinement of a fit's free parameters on the simulation itself: Gauss-Newton
    with fresh secant Jacobians (steps of REFINE_SECANT units), each step a bounded linear
    least-squares problem (:mod:`.lsq`); a step that does not lower the teaching cost is
    halved once, then the search stops. Costs (free plant parameters + 1) runs per iteration
    (the secant runs of an iteration side by side: :func:`refine_many`)."""
    return refine_many(ctx, [fit], max_iter)[0]


def refine_many(
    ctx: ArmContext, fits: Sequence[ArmFit], max_iter: int = REFINE_ITER
) -> list[ArmFit]:
    """:func:`refine` of each fit, in lockstep: the runs every refinement needs next (an
    iteration's secant runs, its step, its halved step) are simulated side by side
    (:meth:`ArmContext.prefetch`) before each refinement goes on. Each refinement does what it
    does alone - the same runs, none on speculation (issue 15: the refinements were one run
    after the other)."""
    steps = [_refine_steps(ctx, f, max_iter) for f in fits]
    out: list[ArmFit | None] = [None] * len(fits)
    wants: dict[int, list[ArmModel | None]] = {}
    for i, g in enumerate(steps):
        try:
            wants[i] = next(g)
        except StopIteration as done:
            out[i] = done.value
    while wants:
        ctx.prefetch([m for i in wants for m in wants[i]])
        for i in list(wants):
            try:
                wants[i] = steps[i].send(None)
            except StopIteration as done:
                out[i] = done.value
                del wants[i]
    done_fits: list[ArmFit] = []
    for f in out:
        assert f is not None  # every refinement returned
        done_fits.append(f)
    return done_fits


def _refine_steps(
    ctx: ArmContext, fit: ArmFit, max_iter: int
) -> Generator[list[ArmModel | None], None, ArmFit]:
    """:func:`refine` of one fit as steps: yields the models whose runs it needs next (all of
    them then asked for), returns the refined fit."""
    keys = fit.free
    cur = fit
    for _ in range(max_iter):
        yield [secant_model(ctx, cur.model, k, REFINE_SECANT) for k in keys]
        cols = [jacobian_column(ctx, cur.model, cur.pred, cur.raw, k, REFINE_SECANT) for k in keys]
        if not keys or any(c is None for c in cols):
            break
        jac = np.column_stack([c for c in cols if c is not None])
        m_new = linear_solve(ctx, cur.model, keys, jac, ctx.wresid(cur.pred, ctx.teach))
        yield [m_new]
        new = evaluate(ctx, m_new, keys, fit.label)
        if new is None or new.cost >= cur.cost:
            half = {k: 0.5 * (cur.model.v(k) + m_new.v(k)) for k in keys}
            m_half = with_values(cur.model, keys, np.array([half[k] for k in keys]))
            yield [m_half]
            new = evaluate(ctx, m_half, keys, fit.label)
            if new is None or new.cost >= cur.cost:
                break
        done = new.cost > (1.0 - REFINE_RTOL) * cur.cost
        cur = new
        if done:
            break
    cur.label, cur.effect, cur.variant, cur.note = fit.label, fit.effect, fit.variant, fit.note
    return cur
