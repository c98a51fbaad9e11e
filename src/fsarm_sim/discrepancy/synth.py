"""``fsarm synth``: measured-format datasets from the bench models with chosen hidden effects.

The truth is a :class:`~fsarm_sim.discrepancy.benchmodel.BenchModel` (nominal parameters and
effects, the same file format ``fsarm diagnose`` writes), replayed by the Numba engine of
:mod:`fsarm_sim.discrepancy.replay` - the simulator's own constitutive kernels - on a grid
``oversample`` times finer than the recorded rate, with the exact input and its exact rate, then
sampled the way a bench records:

* input encoders quantised (default 2^14 counts/rev: the resolution of a 14-bit absolute encoder,
  an estimate for the bench's EM2 position sensor),
* Gaussian noise on the torque channel (``noise`` = standard deviation as a fraction of the clean
  torque's range; 0.2-1 % is the order of a strain-gauge torque sensor's accuracy on a 20 N*m
  range with the shaft loading a fraction of it),
* delays and sensor offsets as the truth's effects say.

Every dataset's sidecar says ``"synthetic": {...}`` and ``notes`` starts with "SYNTHETIC".
The diagnosis never reads the ``synthetic`` key. Input trajectories: :data:`TRAJECTORIES`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.signal import butter, sosfiltfilt

from fsarm_sim.discrepancy import effect_text, replay
from fsarm_sim.discrepancy.benchmodel import (
    BenchModel,
    EffectInstance,
    load_model,
    nominal_from_shaft,
)
from fsarm_sim.errors import InvalidParameterError, real_number
from fsarm_sim.paths import regular_file
from fsarm_sim.plant.effects import registry, sensor_offset
from fsarm_sim.plant.shaft import ShaftParams
from fsarm_sim.records import sidecar as records
from fsarm_sim.records.measured import MAX_SAMPLE_INTERVAL_S, stated_shaft, write_dataset

FloatArray = npt.NDArray[np.float64]

TRAJECTORIES = ("chirp", "multisine", "triangle", "random", "steps", "biased_sine")
DEFAULT_TRAJECTORY = "chirp"
ENCODER_COUNTS = 131072
# Shaft-input speed limit of the series bench: motor no-load speed 1078.6 rad/s / 91
# (models/bench/series_bench.xml); used at 80 %.
SERIES_RATE_LIMIT = 1078.6 / 91.0
PARALLEL_RATE_LIMIT = 6.0  # rad/s at the bend joint: estimate (Fig. 9 bends at 0.1-1 Hz)
MAX_SAMPLES = 1_000_000  # recorded samples of one dataset (1000 Hz for 1000 s)
WORK_ARRAYS = 12  # float64 arrays of the oversampled length alive at once (estimate)
MIN_RATE_HZ = 1.0 / MAX_SAMPLE_INTERVAL_S  # the slowest rate fsarm diagnose accepts


@lru_cache(maxsize=1)
def parallel_link_inertia() -> float:
    """Inertia about the bend joint of the parallel bench's link, read from its MJCF."""
    import mujoco

    from fsarm_sim.engine import callbacks
    from fsarm_sim.engine.model import model_path

    with callbacks.suspended():
        m = mujoco.MjModel.from_xml_path(str(model_path("parallel_bench")))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    dof = m.joint("bend").dofadr[0]
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    return float(full[dof, dof])


def envelope(t: FloatArray, ramp_s: float = 1.0) -> FloatArray:
    """Smooth start and end (raised cosine) so the input begins and ends at rest."""
    e = np.ones_like(t)
    a = np.clip(t / ramp_s, 0, 1)
    b = np.clip((t[-1] - t) / ramp_s, 0, 1)
    return e * 0.5 * (1 - np.cos(np.pi * a)) * 0.5 * (1 - np.cos(np.pi * b))


def trajectory(
    kind: str, t: FloatArray, amplitude: float, rate_limit: float, seed: int = 0
) -> FloatArray:
    """An input deflection trajectory u(t) (rad) of peak ``amplitude``, rate below ``rate_limit``."""
    rng = np.random.default_rng(seed)
    dur = float(t[-1] - t[0])
    tt = t - t[0]
    if kind == "chirp":  # seed 000 Sec. III-A: chirps into the torque controller (here 0.2-5 Hz)
        f0, f1 = 0.2, 5.0
        k = math.log(f1 / f0)
        phase = 2 * np.pi * f0 * dur / k * (np.exp(k * tt / dur) - 1.0)
        f_inst = f0 * np.exp(k * tt / dur)
        amp = np.minimum(amplitude, 0.8 * rate_limit / (2 * np.pi * f_inst))
        u = amp * np.sin(phase)
    elif kind == "multisine":
        freqs = np.array([0.13, 0.31, 0.57, 1.1, 1.9, 3.3])
        ph = rng.uniform(0, 2 * np.pi, freqs.size)
        u = sum(np.sin(2 * np.pi * f * tt + p) / (1 + f) for f, p in zip(freqs, ph, strict=True))
    elif kind == "triangle":  # nested loops: amplitude steps down and up
        period = 4.0
        tri = 2.0 / np.pi * np.arcsin(np.sin(2 * np.pi * tt / period))
        levels = np.array([1.0, 0.45, 0.75, 0.25, 0.9, 0.6])
        idx = np.minimum((tt / (2 * period)).astype(int) % levels.size, levels.size - 1)
        env = sosfiltfilt(butter(2, 0.5, fs=1.0 / (t[1] - t[0]), output="sos"), levels[idx])
        u = tri * env
        u = sosfiltfilt(butter(2, 3.0, fs=1.0 / (t[1] - t[0]), output="sos"), u)
    elif kind == "random":
        w = rng.standard_normal(t.size)
        u = sosfiltfilt(butter(4, 1.5, fs=1.0 / (t[1] - t[0]), output="sos"), w)
    elif kind == "steps":
        hold, ramp = 1.5, 0.3
        n = int(dur / (hold + ramp)) + 2
        levels = rng.uniform(-1, 1, n)
        levels[0] = 0.0
        seg = np.minimum((tt / (hold + ramp)).astype(int), n - 2)
        frac = np.clip((tt - seg * (hold + ramp)) / ramp, 0, 1)
        smooth = 0.5 * (1 - np.cos(np.pi * frac))
        u = levels[seg] + (levels[seg + 1] - levels[seg]) * smooth
    elif kind == "biased_sine":  # mostly one twist sign, slowly rising frequency
        f = 0.3 + 1.2 * tt / dur
        phase = 2 * np.pi * np.cumsum(f) * (t[1] - t[0])
        u = 0.45 + 0.55 * np.sin(phase) - 0.1 * np.sin(0.37 * phase)
    else:
        raise InvalidParameterError(
            f"unknown trajectory {kind!r}; known: {', '.join(TRAJECTORIES)}"
        )
    u = np.asarray(u, dtype=np.float64) * envelope(t)
    peak = float(np.max(np.abs(u)))
    u *= amplitude / peak if peak > 0 else 0.0
    rate = float(np.max(np.abs(np.gradient(u, t))))
    if rate > 0.8 * rate_limit:
        u *= 0.8 * rate_limit / rate
    return u


@dataclass(frozen=True)
class Recording:
    """How the synthetic bench records: rate, duration, noise, encoders, trajectory."""

    duration_s: float = 30.0
    rate_hz: float = 1000.0
    noise: float = 0.003  # torque noise std as a fraction of the clean torque's range
    trajectory: str = DEFAULT_TRAJECTORY
    amplitude: float | None = None  # rad; None: 80 % of the rated torque's twist / 70 deg bend
    bend_rad: float = 0.0  # series bench: the held bend angle
    encoder_counts: int = ENCODER_COUNTS
    oversample: int = 10
    seed: int = 0
    input_file: str | None = None  # a trajectory file (:func:`read_input_file`) instead

    def validate(self) -> None:
        for name in ("duration_s", "rate_hz", "noise", "bend_rad"):
            real_number(getattr(self, name), name)  # True is not 1 s
        if self.amplitude is not None:
            real_number(self.amplitude, "amplitude")
        for name in ("duration_s", "rate_hz"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0:
                raise InvalidParameterError(f"{name} must be > 0, got {v!r}")
        if self.rate_hz < MIN_RATE_HZ:
            raise InvalidParameterError(
                f"rate_hz (--rate) must be >= {MIN_RATE_HZ:g} Hz, the slowest sampling fsarm "
                f"diagnose accepts, got {self.rate_hz!r}"
            )
        if not math.isfinite(self.noise) or self.noise < 0:
            raise InvalidParameterError(f"noise must be >= 0, got {self.noise!r}")
        if self.oversample < 1 or self.encoder_counts < 0:
            raise InvalidParameterError("oversample must be >= 1 and encoder_counts >= 0")
        if self.amplitude is not None and not (
            math.isfinite(self.amplitude) and self.amplitude > 0
        ):
            raise InvalidParameterError(
                f"amplitude (--amplitude) must be a finite number of rad > 0, got {self.amplitude!r}"
            )
        if not math.isfinite(self.bend_rad):
            raise InvalidParameterError(f"bend_rad must be finite, got {self.bend_rad!r}")
        n = self.n_samples()
        if n > MAX_SAMPLES:
            raise InvalidParameterError(
                f"rate_hz x duration_s (--rate x --duration) = {self.rate_hz:g} Hz x "
                f"{self.duration_s:g} s gives {n:,} samples (about "
                f"{self.memory_bytes() / 1e9:.3g} GB of working memory); at most "
                f"{MAX_SAMPLES:,} samples are allowed: lower --rate or --duration"
            )
        from fsarm_sim.sim.simulation import available_memory_bytes

        if self.memory_bytes() > available_memory_bytes() // 2:
            raise InvalidParameterError(
                f"rate_hz x duration_s (--rate x --duration) needs about "
                f"{self.memory_bytes() / 1e9:.3g} GB of working memory, more than half of what "
                f"is available ({available_memory_bytes() / 1e9:.3g} GB): lower --rate or "
                "--duration"
            )

    def n_samples(self) -> int:
        """Recorded samples: duration x rate + 1."""
        return round(self.duration_s * self.rate_hz) + 1

    def memory_bytes(self) -> int:
        """Estimated working memory of :func:`synthesize` (oversampled float64 arrays)."""
        return WORK_ARRAYS * 8 * ((self.n_samples() - 1) * self.oversample + 1)


def default_amplitude(model: BenchModel, shaft: ShaftParams) -> float:
    if model.setup == "parallel_bench":
        return math.radians(70.0)
    k = max(model.nominal["k_pos"], 1e-6)
    return 0.8 * shaft.rating_nm / k


def _reading(x: FloatArray, bias: float) -> FloatArray:
    """Elementwise :func:`fsarm_sim.plant.effects.sensor_offset.reading` of a recorded channel."""
    return np.array([sensor_offset.reading(float(v), bias) for v in x]) if bias else x.copy()


def _quantise(x: FloatArray, counts: int) -> FloatArray:
    if counts <= 0:
        return x
    q = 2 * np.pi / counts
    return np.round(x / q) * q


def synthesize(
    truth: BenchModel, rec: Recording, shaft: ShaftParams | None = None
) -> tuple[dict[str, FloatArray], dict[str, Any]]:
    """(columns, sidecar) of one synthetic dataset of ``truth`` recorded as ``rec`` says."""
    rec.validate()
    sh = shaft or stated_shaft(
        truth.shaft.get("diameter_mm", 9.0), truth.shaft.get("length_mm", 450.0)
    )
    if truth.setup == "series_bench":  # the one bend check, as runs, sweeps and the bench
        sh.check_bend(rec.bend_rad, "bend_rad (--bend-deg)")
    rng = np.random.default_rng(rec.seed + 7919)
    h = 1.0 / rec.rate_hz
    n = round(rec.duration_s * rec.rate_hz) + 1
    hf = h / rec.oversample
    nf = (n - 1) * rec.oversample + 1
    tf = np.arange(nf, dtype=np.float64) * hf
    rate_limit = SERIES_RATE_LIMIT if truth.setup == "series_bench" else PARALLEL_RATE_LIMIT
    if rec.input_file is not None:
        t_in, u_in = read_input_file(rec.input_file, truth.setup)
        if t_in[-1] - t_in[0] < tf[-1] - 1e-9:
            raise InvalidParameterError(
                f"the input file {rec.input_file} lasts {t_in[-1] - t_in[0]:g} s, shorter than "
                f"the record's {tf[-1]:g} s (--duration)"
            )
        u_true = np.interp(tf, t_in - t_in[0], u_in)
        amp = float(np.max(np.abs(u_true)))
    else:
        amp = rec.amplitude if rec.amplitude is not None else default_amplitude(truth, sh)
        u_true = trajectory(rec.trajectory, tf, amp, rate_limit, rec.seed)
    d, off = replay.input_transform(truth)
    # the model is driven by the true input, delayed by d (the recorded input is not)
    u_model = replay.shifted(u_true, d / hf) if d != 0.0 else u_true
    r = replay.param_vector(truth)
    z = np.zeros(nf)
    cols: dict[str, FloatArray] = {"t": np.arange(n, dtype=np.float64) * h}
    if truth.setup == "series_bench":
        phi = np.full(nf, rec.bend_rad)
        if truth.inertia_load:
            n_sub = replay.substeps(r, hf)
            zero = np.zeros(nf)
            y, th = replay.replay_inertia(
                r, u_model, phi, hf, n_sub, zero, zero, replay.restarts(nf, hf, None)
            )
        else:
            y = replay.replay_static(r, u_model, np.gradient(u_model, hf), z, z, z, phi, hf)
            th = z
        y = y[:: rec.oversample]
        theta_s = _quantise(th[:: rec.oversample], rec.encoder_counts)
        theta_m = _quantise(_reading(u_true[:: rec.oversample], off), rec.encoder_counts)
        cols.update(theta_m=theta_m, theta_s=theta_s, phi_b=np.full(n, rec.bend_rad))
        out_name = "tau_s"
    else:
        ud = np.gradient(u_model, hf)
        ua = np.gradient(ud, hf)
        y = replay.replay_static(r, u_model, ud, ua, z, z, u_model, hf)[:: rec.oversample]
        phi_rec = _quantise(_reading(u_true[:: rec.oversample], off), rec.encoder_counts)
        cols.update(phi_b=phi_rec)
        out_name = "m_b"
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(cols.get("theta_s", y)))):
        raise InvalidParameterError(
            "the truth model's replay diverged (non-finite output): an effect's parameters make "
            "the load dynamics unstable at this sample rate; reduce them or the stiffness"
        )
    span = float(np.ptp(y))
    sigma = rec.noise * span
    cols[out_name] = y + sigma * rng.standard_normal(n)
    return cols, synthetic_record(truth, rec, sh, amp, sigma, list(cols)).to_json()


INPUT_COLUMNS = {"series_bench": "theta_m", "parallel_bench": "phi_b"}


def read_input_file(path: str | Path, setup: str) -> tuple[FloatArray, FloatArray]:
    """(t, input angle) of a bench trajectory file: CSV with a header ``t,theta_m`` (series
    bench) or ``t,phi_b`` (parallel bench), t in s rising evenly, the angle in rad - what
    ``fsarm design-experiment`` writes and a bench plays."""
    p = Path(path)
    col = INPUT_COLUMNS.get(setup)
    if col is None:
        raise InvalidParameterError(f"an input file drives a bench, not the setup {setup!r}")
    regular_file(p, "the input file", InvalidParameterError)  # loops, long names ...
    try:
        head = [c.strip() for c in p.read_text("utf-8").splitlines()[0].strip().split(",")]
    except (OSError, ValueError, IndexError) as exc:
        raise InvalidParameterError(f"cannot read the input file {p}: {exc}") from exc
    repeated = sorted({c for c in head if head.count(c) > 1})
    if repeated:
        raise InvalidParameterError(
            f"the input file {p}: the column name(s) {repeated} are given twice; every column "
            "needs its own name"
        )
    if "t" not in head or col not in head:
        raise InvalidParameterError(
            f"the input file {p} needs the columns t and {col} (for {setup}), has {head}"
        )
    try:
        with warnings.catch_warnings():  # no rows: refused below, by name
            warnings.simplefilter("ignore", UserWarning)
            data = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as exc:
        raise InvalidParameterError(f"cannot read the input file {p}: {exc}") from exc
    if data.shape[0] and data.shape[1] != len(head):
        raise InvalidParameterError(
            f"the input file {p}: its rows have {data.shape[1]} values, its header "
            f"{len(head)} names"
        )
    if data.shape[0] < 10:
        raise InvalidParameterError(f"the input file {p} needs >= 10 finite rows")
    t = np.asarray(data[:, head.index("t")], dtype=np.float64)
    u = np.asarray(data[:, head.index(col)], dtype=np.float64)
    if t.size < 10 or not (np.all(np.isfinite(t)) and np.all(np.isfinite(u))):
        raise InvalidParameterError(f"the input file {p} needs >= 10 finite rows")
    if not np.all(np.diff(t) > 0):
        raise InvalidParameterError(f"the input file {p}: t must rise strictly")
    return t, u


def write_input_file(path: str | Path, t: FloatArray, u: FloatArray, setup: str) -> Path:
    """Write a bench trajectory file (:func:`read_input_file`)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    col = INPUT_COLUMNS[setup]
    np.savetxt(
        p, np.column_stack([t, u]), delimiter=",", header=f"t,{col}", comments="", fmt="%.9g"
    )
    return p


def synthetic_record(
    truth: BenchModel,
    rec: Recording,
    sh: ShaftParams,
    amp: float,
    sigma: float,
    columns: list[str],
) -> records.Sidecar:
    """The typed sidecar of a synthetic bench dataset (:mod:`fsarm_sim.records.sidecar`)."""
    hidden = [e.label for e in truth.effects]
    traj = rec.trajectory if rec.input_file is None else f"file {Path(rec.input_file).name}"
    load = None
    if truth.setup == "series_bench":
        load = (
            records.LoadRef("inertia", truth.load_inertia_kgm2)
            if truth.inertia_load
            else records.LoadRef("blocked")
        )
    return records.Sidecar(
        schema=records.SCHEMA,
        writer=records.WRITER_SYNTH,
        setup=truth.setup,
        shaft=records.ShaftRef(diameter_mm=sh.diameter_mm, length_mm=sh.length_mm),
        load=load,
        columns={c: records.UNITS[c] for c in columns},
        notes=(
            f"SYNTHETIC data from fsarm synth (not a measurement): trajectory {traj}, "
            f"{rec.duration_s:g} s at {rec.rate_hz:g} Hz, torque noise {100 * rec.noise:g} % of "
            f"range, hidden effects: {', '.join(hidden) if hidden else 'none'}"
        ),
        synthetic=records.jsonable(
            {
                "truth": truth.as_dict(),
                "trajectory": traj,
                "amplitude": amp,
                "noise_fraction": rec.noise,
                "noise_std": sigma,
                "seed": rec.seed,
                "bend_rad": rec.bend_rad,
                "oversample": rec.oversample,
                "encoder_counts": rec.encoder_counts,
            }
        ),
    )


# the inertia load a synthetic series-bench record states when none is given (kg*m^2; estimate:
# a 120 mm steel disc); `fsarm synth --load inertia` and the batteries use it
DEFAULT_LOAD_INERTIA_KGM2 = 0.01


def truth_model(
    setup: str,
    effects: list[EffectInstance] | None = None,
    *,
    shaft: ShaftParams | None = None,
    load_inertia_kgm2: float | None = None,
    stiffness_scale: float = 1.0,
    true_inertia_kgm2: float | None = None,
) -> BenchModel:
    """A truth model: the catalogue's nominal model (stiffness scaled by ``stiffness_scale``,
    e.g. a real shaft 10 % stiffer than the catalogue says) plus ``effects``.

    ``load_inertia_kgm2`` is what the sidecar will state; ``true_inertia_kgm2`` what acts
    (default: the stated value).
    """
    for name, v in (
        ("load_inertia_kgm2 (--inertia)", load_inertia_kgm2),
        ("true_inertia_kgm2 (--true-inertia)", true_inertia_kgm2),
        ("stiffness_scale (--stiffness-scale)", stiffness_scale),
    ):
        if v is not None and not (math.isfinite(v) and v > 0):
            raise InvalidParameterError(f"{name} must be a finite number > 0, got {v!r}")
    sh = shaft or stated_shaft()
    j_link = parallel_link_inertia() if setup == "parallel_bench" else 0.0
    m = nominal_from_shaft(setup, sh, load_inertia_kgm2, j_link=j_link)
    for key in ("k_pos", "s_pos", "k_neg", "s_neg", "kb"):
        if key in m.nominal:
            m.nominal[key] *= stiffness_scale
    if true_inertia_kgm2 is not None and m.inertia_load:
        m.nominal["j_load"] = true_inertia_kgm2
    for e in effects or []:
        m.effects.append(e)
    return m


def parse_effect(text: str, setup: str, x_ref: float) -> EffectInstance:
    """``NAME[:VARIANT]=v1[,v2...]`` -> an effect with its registry parameters in order
    (:func:`fsarm_sim.discrepancy.effect_text.parse_effect`, the one parser of every setup).

    Hysteresis takes pairs: ``hysteresis:maxwell_slip=k1,d1,k2,d2``. Nonlinear stiffness
    ``poly`` takes ``a2,a3`` (x_ref = the input amplitude).
    """
    return effect_text.parse_effect(text, setup, x_ref)


SETUPS = (registry.SERIES, registry.PARALLEL, registry.ARM)


def synthesize_setup(
    setup: str,
    effects: Sequence[str] = (),
    *,
    model_file: str | Path | None = None,
    shaft: ShaftParams | None = None,
    stiffness_scale: float = 1.0,
    load_inertia_kgm2: float | None = None,
    true_inertia_kgm2: float | None = None,
    recording: Any = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[dict[str, FloatArray], dict[str, Any], list[str]]:
    """``fsarm synth``: (columns, sidecar, hidden effect labels) of a SYNTHETIC record of any
    setup - the benches by the replay engine (:func:`synthesize`), the arm by the simulator
    (:func:`fsarm_sim.discrepancy.arm_synth.synthesize_arm`).

    The truth is a model file's (``fsarm diagnose`` writes them; a bench file names its own
    bench) or the catalogue's nominal model (``stiffness_scale``; benches: the stated and the
    acting load inertia) with ``effects`` in the effect text of
    :mod:`fsarm_sim.discrepancy.effect_text`, one parser for every setup. ``recording``: a
    :class:`Recording` (benches) or an ``ArmRecording`` (arm); None: the defaults. ``shaft``:
    the stated shaft (default: the catalogue's 9 x 450 mm, eq. 8). ``progress(step, done,
    total)`` is called before each of its two steps (the truth model, the record).
    """

    def report(step: str, done: int) -> None:
        if progress is not None:
            progress(step, done, 2)

    if setup not in SETUPS:
        raise InvalidParameterError(
            f"--setup must be {', '.join(SETUPS[:-1])} or {SETUPS[-1]}, got {setup!r}"
        )
    if setup == registry.ARM:
        from fsarm_sim.discrepancy import arm_modelfile, arm_synth

        report("the truth model", 0)
        if model_file is not None:
            arm_truth = arm_modelfile.load_arm_model(model_file)[0]
        else:
            arm_truth = arm_synth.truth_model(list(effects), stiffness_scale=stiffness_scale)
        rec = recording if recording is not None else arm_synth.ArmRecording()
        report("running the scenario", 1)
        cols, side = arm_synth.synthesize_arm(arm_truth, rec, shaft)
        return cols, side, list(arm_truth.labels)
    bench_rec = recording if recording is not None else Recording()
    report("the truth model", 0)
    if model_file is not None:
        truth = load_model(model_file)
    else:
        truth = truth_model(
            setup,
            shaft=shaft,
            load_inertia_kgm2=load_inertia_kgm2,
            stiffness_scale=stiffness_scale,
            true_inertia_kgm2=true_inertia_kgm2,
        )
        sh = shaft or stated_shaft()
        amp = bench_rec.amplitude
        amp = amp if amp is not None else default_amplitude(truth, sh)
        truth.effects.extend(parse_effect(text, setup, amp) for text in effects)
    report("simulating the bench", 1)
    cols, side = synthesize(truth, bench_rec, shaft)
    return cols, side, [e.label for e in truth.effects]


def write_synthetic(
    path: str | Path, truth: BenchModel, rec: Recording, shaft: ShaftParams | None = None
) -> tuple[Path, Path]:
    cols, side = synthesize(truth, rec, shaft)
    return write_dataset(path, cols, side)
