"""Build a configured MuJoCo model of the arm: MJCF + shaft + payload + gains + reference.

The MJCF (``models/fsarm/fsarm.xml``) is the one place where geometry, masses, inertias, gear
ratios and limits are written. This module reads them back by name from the compiled model and
adds what belongs to one run: the payload mass, the shaft parameters, controller gains and the
reference table (see :mod:`fsarm_sim.kernels.layout` for where each lands).
"""

from __future__ import annotations

import copy
import functools
import math
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt

from fsarm_sim.engine import callbacks, hysteresis_model
from fsarm_sim.engine.config import CONTROLLERS as CONTROLLERS
from fsarm_sim.engine.config import INTEGRATORS as INTEGRATORS
from fsarm_sim.engine.config import PAYLOAD_COM_OFFSET_M, PAYLOAD_HEIGHT_M, PAYLOAD_RADIUS_M
from fsarm_sim.engine.config import PAYLOAD_MAX_KG as PAYLOAD_MAX_KG
from fsarm_sim.engine.config import Effects as Effects
from fsarm_sim.engine.config import Gains as Gains
from fsarm_sim.engine.config import SimConfig as SimConfig
from fsarm_sim.engine.config import validate_laws as validate_laws
from fsarm_sim.engine.lean import idle_off, strip
from fsarm_sim.engine.structure import ArmStructure as ArmStructure
from fsarm_sim.engine.structure import fixed_tendon as fixed_tendon
from fsarm_sim.engine.structure import named_id
from fsarm_sim.engine.structure import read_structure as read_structure
from fsarm_sim.errors import InvalidParameterError, ModelStructureError
from fsarm_sim.kernels import layout
from fsarm_sim.plant.effects import registry
from fsarm_sim.plant.effects.base import model_writes
from fsarm_sim.plant.transmissions.base import Transmission, TransmissionError


@functools.lru_cache(maxsize=8)
def model_path(name: str = "fsarm") -> Path:
    """Path of a packaged MJCF (``fsarm``, ``series_bench``, ``parallel_bench``)."""
    folder = "fsarm" if name == "fsarm" else "bench"
    file = "fsarm.xml" if name == "fsarm" else f"{name}.xml"
    return Path(str(resources.files("fsarm_sim.models").joinpath(folder, file)))


def law_state_names(fx: Effects) -> list[tuple[str, str]]:
    """(effect, state) of every own state of the registry laws switched on in ``fx``, in
    registry order: the ``data.act`` slots :func:`build_spec` adds (actuators
    ``<effect>.<state>``) and the recorded columns of the same names."""
    on = {name for name, _ in fx.laws}
    return [
        (e.name, d.name)
        for e in registry.arm_laws()
        if e.name in on and e.law is not None
        for d in e.law.STATES
    ]


def add_law_states(spec: mujoco.MjSpec, fx: Effects) -> None:
    """One state actuator (dyntype user, no force) per own state of a law that is on, after the
    MJCF's own: a run without such laws compiles exactly the model it always did."""
    for effect, state in law_state_names(fx):
        a = spec.add_actuator(name=f"{effect}.{state}", target="j3_rotor")
        a.trntype = mujoco.mjtTrn.mjTRN_JOINT
        a.dyntype = mujoco.mjtDyn.mjDYN_USER
        a.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        a.biastype = mujoco.mjtBias.mjBIAS_NONE
        a.gainprm[0] = 0.0
        a.gear[0] = 0.0
        a.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE


def build_spec(
    config: SimConfig,
    ref_table: npt.NDArray[np.float64],
    path: Path | None = None,
    *,
    ref_data: bool = True,
) -> mujoco.MjSpec:
    """The MjSpec of one run (payload, state ranges, parameter/reference storage) before compiling.

    ``build_spec(...).to_xml()`` is the exact MJCF of the run: feed it to Pinocchio so both
    engines read the same numbers. ``ref_data=False`` sizes the reference storage but leaves it
    zero (:func:`build_model` copies the table into the compiled model: handing 10^5 numbers to
    the spec one by one took 3 ms of every run).
    """
    spec = mujoco.MjSpec.from_file(str(path or model_path()))
    if config.payload_kg > 0.0:
        m, r, h = config.payload_kg, PAYLOAD_RADIUS_M, PAYLOAD_HEIGHT_M
        body = spec.body("payload")
        body.mass = m
        body.ipos = [0.0, 0.0, PAYLOAD_COM_OFFSET_M]
        body.inertia = [
            m * (3 * r * r + h * h) / 12.0,
            m * (3 * r * r + h * h) / 12.0,
            m * r * r / 2.0,
        ]
        body.explicitinertial = True
    sh = config.shaft
    if sh.inertia_kgm2 > 0.0:
        # eq. 1 J: the shaft's own inertia, lumped half at each end (the standard discretization
        # of a torsional shaft; a rigidly spinning shaft then has kinetic energy J w^2 / 2).
        # As joint armature both MuJoCo and Pinocchio read it. (A tendon armature J on
        # shaft_twist would be wrong twice over: it gives a rigid spin no energy, and MuJoCo 3.17
        # drops its coupling term between the rotor and q3, which sit on different branches.)
        with callbacks.suspended():
            st = read_structure(mujoco.MjSpec.from_file(str(path or model_path())).compile())
        spec.joint("j3_rotor").armature += 0.5 * sh.inertia_kgm2 * st.coef_m**2
        spec.joint("q3").armature += 0.5 * sh.inertia_kgm2 * st.coef_s**2
    tr = config.transmission_model()
    # the slip slots carry the transmission's own states (the shaft's Maxwell-slip elements...)
    for i, lim in enumerate(tr.state_limits(config.transmission_blocks()[0])):
        act = spec.actuator(f"shaft_slip{i + 1}")
        if lim is None:
            act.actlimited = mujoco.mjtLimited.mjLIMITED_FALSE
        else:
            act.actlimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.actrange = [lim[0], lim[1]]
    add_law_states(spec, config.effects)
    spec.add_numeric(name=layout.PARAMS_NAME, size=layout.N_PARAMS, data=np.zeros(layout.N_PARAMS))
    if ref_data:
        spec.add_numeric(name=layout.REF_NAME, size=ref_table.size, data=ref_table.ravel())
    else:
        spec.add_numeric(name=layout.REF_NAME, size=ref_table.size)
    # the kernels' userdata and the run recorder's buffer (layout.U_REC_*)
    spec.nuserdata = layout.N_USERDATA + layout.REC_ROWS_DEFAULT * layout.rec_width(
        *spec_sizes(spec)
    )
    return spec


_QPOS_SIZE = {mujoco.mjtJoint.mjJNT_FREE: 7, mujoco.mjtJoint.mjJNT_BALL: 4}
_DOF_SIZE = {mujoco.mjtJoint.mjJNT_FREE: 6, mujoco.mjtJoint.mjJNT_BALL: 3}


def spec_sizes(spec: mujoco.MjSpec) -> tuple[int, int, int]:
    """(nq, nv, na) the spec will compile to (joints by type; an actuator with dynamics has
    ``actdim`` states, 1 by default); tests/test_model.py checks it against the compiled model."""
    nq = sum(_QPOS_SIZE.get(j.type, 1) for j in spec.joints)
    nv = sum(_DOF_SIZE.get(j.type, 1) for j in spec.joints)
    na = sum(
        (a.actdim if a.actdim > 0 else 1)
        for a in spec.actuators
        if a.dyntype != mujoco.mjtDyn.mjDYN_NONE
    )
    return nq, nv, na


def build_model(
    config: SimConfig,
    ref_table: npt.NDArray[np.float64],
    path: Path | None = None,
    lean: bool = False,
) -> mujoco.MjModel:
    """Compile the arm for one run and write its parameters into ``fsarm_params``.

    ``ref_table`` has one row per control tick: ``q_ref[3], qd_ref[3], qdd_ref[3]``. ``lean``:
    the lean twin (:mod:`fsarm_sim.engine.lean`: no visual geoms or sensors; the same dynamics),
    for stepping only.

    The model returned is the caller's own: a copy of a compiled model kept per structure in this
    process (:func:`_compiled`; the same bytes as compiling afresh, tests/test_model.py), with
    this run's numbers written into it.
    """
    config.validate()
    ref = np.ascontiguousarray(ref_table, dtype=np.float64)
    if ref.ndim != 2 or ref.shape[1] != layout.REF_COLS or ref.shape[0] < 1:
        raise InvalidParameterError(
            f"reference table must have shape (n_ticks >= 1, {layout.REF_COLS}), got {ref.shape}"
        )
    if not np.all(np.isfinite(ref)):
        raise InvalidParameterError("reference table contains NaN or infinite values")
    if config.transmission_model().routed_over_joint2:  # phi_B = q2: the file's bend range
        config.shaft.check_bend(ref[:, 1], "joint 2's reference q2 (the shaft's bend phi_B)")
    tr = config.transmission_model()
    plant = config.transmission_blocks()[0]  # (~40 us each time: computed once here)
    limits = tr.state_limits(plant)
    base = _compiled(config, ref, path, lean, limits)
    model = copy.copy(base.model)  # mj_copyModel: nothing shared with the cache or other runs
    for a, lim in zip(base.slip_actuators, limits, strict=True):
        if lim is not None:  # (build_spec writes these; the key holds which are limited)
            model.actuator_actrange[a] = (lim[0], lim[1])
    model.numeric(layout.REF_NAME).data[:] = ref.ravel()  # (the spec sized it: build_spec)
    if config.timestep_s is not None:
        model.opt.timestep = config.timestep_s
    if config.integrator is not None:
        model.opt.integrator = INTEGRATORS[config.integrator]
    ratio = config.gains.ctrl_dt_s / model.opt.timestep
    if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
        raise InvalidParameterError(
            f"control period {config.gains.ctrl_dt_s:g} s must be a whole multiple of the physics "
            f"timestep {model.opt.timestep:g} s"
        )
    if not config.joint_damping:
        model.dof_damping[:] = 0.0
    st = base.structure
    write_law_model(model, config.effects)
    write_params(model, st, config, ref.shape[0], lever_arms=base.lever_arms)
    if lean:
        idle_off(model)  # MuJoCo's spring stage, where no element has a spring (engine.lean)
    omega = float(np.sqrt(tr.max_stiffness(plant) * base.mode_inertia(ref[0, :3])))
    if config.effects.series and omega * model.opt.timestep > MAX_OMEGA_DT:
        raise InvalidParameterError(
            f"timestep {model.opt.timestep:g} s is too large for the shaft: its stiffest mode is "
            f"{omega:.0f} rad/s and omega*dt must stay below {MAX_OMEGA_DT:g}; "
            f"use a timestep of at most {MAX_OMEGA_DT / omega:.2g} s"
        )
    return model


# Compiled models kept per structure in one process (build_model copies them): a sweep's points
# differ in numbers, not structure, and reading + compiling the MJCF took ~1.5 ms of each.
MODEL_CACHE_ENTRIES = 8  # structures (a sweep has one; estimate, a few MB each at most)
# Runs with longer reference tables compile afresh and are not kept: 2^21 numbers = 16 MiB,
# ~230 s at 1 kHz (a sweep point runs seconds; an hour-long run would pin 260 MB).
MODEL_CACHE_MAX_REF_NUMBERS = 1 << 21


@dataclass
class _Compiled:
    """One compiled structure and what follows from it alone. ``model`` is never handed out
    nor written once kept (build_model copies it)."""

    model: mujoco.MjModel
    structure: ArmStructure
    slip_actuators: tuple[int, ...]  # the shaft_slip actuators build_spec limits, in order
    lever_arms: tuple[float, float]  # payload_lever_arms_m: kinematics at the zero pose only
    # q -> c_m^2 / I_rotor + c_s^2 / M_33 (the mass matrix depends on the structure and q only)
    _modes: dict[tuple[float, ...], float] = field(default_factory=dict)

    def mode_inertia(self, q: npt.NDArray[np.float64]) -> float:
        key = tuple(float(v) for v in q)
        inv = self._modes.get(key)
        if inv is None:
            inv = _mode_inertia(self.model, self.structure, q)
            if len(self._modes) < 64:
                self._modes[key] = inv
        return inv


_cache: OrderedDict[tuple[object, ...], _Compiled] = OrderedDict()
_cache_lock = threading.Lock()


def _compiled(
    config: SimConfig,
    ref: npt.NDArray[np.float64],
    path: Path | None,
    lean: bool,
    state_limits: Sequence[tuple[float, float] | None],
) -> _Compiled:
    """The compiled structure of a run, from the cache or compiled (and kept when small).

    Keyed by everything :func:`build_spec` and :func:`~fsarm_sim.engine.lean.strip` read: the
    MJCF file (path, size, modification time), ``lean``, the reference table's size, the payload,
    the shaft inertia, and which transmission states are limited; the limits themselves are
    numbers the compiler only copies, so build_model writes them into its copy.
    ``state_limits``: the transmission's (``Transmission.state_limits``, as build_spec sets them).
    """
    file = Path(path or model_path())
    stat = file.stat()
    limits = tuple(None if lim is None else (float(lim[0]), float(lim[1])) for lim in state_limits)
    key = (
        str(file),
        stat.st_mtime_ns,
        stat.st_size,
        bool(lean),
        int(ref.size),
        float(config.payload_kg),
        float(config.shaft.inertia_kgm2),
        tuple(lim is None for lim in limits),
        tuple(law_state_names(config.effects)),
    )
    # a range the compiler would reject (or a large table) is compiled afresh, never kept
    keep = ref.size <= MODEL_CACHE_MAX_REF_NUMBERS and all(
        lim is None or (math.isfinite(lim[0]) and math.isfinite(lim[1]) and lim[0] < lim[1])
        for lim in limits
    )
    with _cache_lock:
        hit = _cache.get(key) if keep else None
        if hit is not None:
            _cache.move_to_end(key)
    if hit is None:
        spec = build_spec(config, ref, path, ref_data=False)
        if lean:
            strip(spec)
        with callbacks.suspended():
            compiled = spec.compile()
        A = mujoco.mjtObj.mjOBJ_ACTUATOR
        hit = _Compiled(
            model=compiled,
            structure=read_structure(compiled),
            slip_actuators=tuple(
                named_id(compiled, A, f"shaft_slip{i + 1}") for i in range(len(limits))
            ),
            lever_arms=payload_lever_arms_m(compiled),
        )
        if keep:
            with _cache_lock:
                _cache[key] = hit
                while len(_cache) > MODEL_CACHE_ENTRIES:
                    _cache.popitem(last=False)
    return hit


def clear_model_cache() -> None:
    """Forget the compiled models kept by :func:`build_model` (tests; memory)."""
    with _cache_lock:
        _cache.clear()


MAX_OMEGA_DT = (
    1.0  # explicit springs: stable below 2 (Euler) / 2.8 (RK4); 1 keeps phase errors small
)


def max_stiffness(config: SimConfig) -> float:
    """Largest stiffness joint 3's transmission can show (N*m/rad, shaft side).

    Flexible shaft: the stiffer eq. 3 side straight plus the slip elements; any other: the
    largest stiffness of its law over its valid twist range and the bends joint 2 can reach.
    """
    return config.transmission_model().max_stiffness(config.transmission_blocks()[0])


def _mode_inertia(model: mujoco.MjModel, st: ArmStructure, q: npt.NDArray[np.float64]) -> float:
    """c_m^2 / I_rotor + c_s^2 / M_33 at pose ``q``: the rotor-against-load transmission mode's
    w^2 / K (two inertias on one spring; twist coefficients c_m = 1/i_G1, c_s = i_G2)."""
    data = mujoco.MjData(model)
    data.qpos[list(st.qadr[:3])] = q
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    mujoco.mj_crb(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    return float(
        st.coef_m**2 / full[st.dof[3], st.dof[3]] + st.coef_s**2 / full[st.dof[2], st.dof[2]]
    )


def write_params(
    model: mujoco.MjModel,
    st: ArmStructure,
    config: SimConfig,
    n_ticks: int,
    *,
    lever_arms: tuple[float, float] | None = None,
) -> None:
    """Fill ``fsarm_params`` (layout.P_*). ``lever_arms``: :func:`payload_lever_arms_m` of this
    model if known (None: computed here)."""
    p = model.numeric(layout.PARAMS_NAME).data
    sh, cm_sh, g, fx = (
        config.shaft,
        config.controller_shaft or config.shaft,
        config.gains,
        config.effects,
    )
    on = {True: 1.0, False: 0.0}
    p[:] = 0.0
    p[layout.P_MAGIC] = layout.MAGIC
    p[layout.P_QADR_Q1], p[layout.P_QADR_Q2], p[layout.P_QADR_Q3], p[layout.P_QADR_ROT] = st.qadr
    p[layout.P_DOF_Q1], p[layout.P_DOF_Q2], p[layout.P_DOF_Q3], p[layout.P_DOF_ROT] = st.dof
    p[layout.P_COEF_M], p[layout.P_COEF_S] = st.coef_m, st.coef_s
    p[layout.P_ACT_BR1], p[layout.P_ACT_BR2] = st.act_branch
    p[layout.P_ACT_SLIP1] = st.act_slip
    p[layout.P_CTRL_J1], p[layout.P_CTRL_J2], p[layout.P_CTRL_J3] = st.ctrl
    p[layout.P_MADR_Q1], p[layout.P_MADR_Q2], p[layout.P_MADR_Q3] = st.madr
    p[layout.P_KB], p[layout.P_BETA] = sh.kb, sh.beta
    p[layout.P_BR_K1], p[layout.P_BR_K2] = sh.conduit_k
    p[layout.P_BR_TAU1], p[layout.P_BR_TAU2] = sh.conduit_tau
    p[layout.P_EN_SERIES] = on[fx.series]
    p[layout.P_EN_BEND] = on[fx.bending]
    p[layout.P_EN_CONDUIT] = on[fx.conduit]
    p[layout.P_EN_COUPLING] = on[fx.coupling]
    p[layout.P_EN_CONTROL] = on[fx.control]
    p[layout.P_CTRL_DT] = g.ctrl_dt_s
    p[layout.P_N_TICKS] = n_ticks
    p[layout.P_TIMESTEP] = model.opt.timestep
    p[layout.P_STEPS_PER_TICK] = max(1, round(g.ctrl_dt_s / model.opt.timestep))
    p[layout.P_WN1], p[layout.P_WN2], p[layout.P_WN3] = g.wn_rad_s
    p[layout.P_ZETA1], p[layout.P_ZETA2], p[layout.P_ZETA3] = g.zeta
    p[layout.P_TAU_BW], p[layout.P_TAU_WI] = g.torque_bandwidth_rad_s, g.torque_integral_rad_s
    p[layout.P_TAU_KDN] = g.torque_derivative
    p[layout.P_SPD_KP], p[layout.P_SPD_KI] = g.speed_kp, g.speed_ki
    p[layout.P_OMEGA_MAX] = st.motor_speed_limit
    p[layout.P_TAU1_MAX], p[layout.P_TAU2_MAX], p[layout.P_TAU_MOT_MAX] = st.tau_max
    p[layout.P_CM_KB], p[layout.P_CM_BETA] = cm_sh.kb, cm_sh.beta
    p[layout.P_CM_BEND_COMP] = on[g.bend_compensation]
    p[layout.P_SPEED_FF] = on[g.speed_ff and g.controller != "paper-pid"]
    p[layout.P_CTRL_KIND] = CONTROLLERS[g.controller]
    p[layout.P_DOB_WQ] = g.dob_bandwidth_rad_s
    if g.controller == "hysteresis-comp":
        hm = hysteresis_model.resolve(g.hysteresis_model, cm_sh)
        p[layout.P_HM : layout.P_HM + layout.N_HM] = hm
    p[layout.P_GAIN_SCHED] = on[g.gain_schedule]
    p[layout.P_SETUP] = layout.SETUP_ARM
    p[layout.P_RK4] = on[model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4]
    write_transmission(p, config)
    write_arm_effects(model, p, config.effects, lever_arms=lever_arms)


def write_transmission(p: npt.NDArray[np.float64], config: SimConfig) -> None:
    """Joint 3's transmission: id, plant and controller blocks; shaft-only effects off if absent."""
    tr = config.transmission_model()
    plant, ctrl = config.transmission_blocks()
    p[layout.P_TRANS] = tr.kind
    p[layout.P_TR : layout.P_TR + layout.N_TR] = plant
    p[layout.P_TRC : layout.P_TRC + layout.N_TR] = ctrl
    p[layout.P_TR_K0] = _reference_stiffness(tr, ctrl)
    if not tr.routed_over_joint2:  # no shaft over joint 2: no bending moment to feel or cancel
        p[layout.P_EN_BEND] = p[layout.P_EN_CONDUIT] = p[layout.P_EN_COUPLING] = 0.0
        p[layout.P_CM_KB] = p[layout.P_CM_BETA] = 0.0


REFERENCE_TORQUE_FRACTION = 0.3  # of the rating: the operating point fixed gains are tuned for


def reference_stiffness(config: SimConfig) -> float:
    """The controller's stiffness at its nominal operating point, straight (N*m/rad).

    The twist that holds 30 % of the rating on the positive side (the bias of the bandwidth
    test, arm_metrics), unbent: fixed torque-PID gains are tuned for it (``gain_schedule=False``)
    and the scheduler never goes below :data:`layout.STIFFNESS_FLOOR` of it. For the linear eq. 8
    shaft this is simply K_sp(0); for stiffening laws (RTCA, QA-Joint) it avoids tuning on the
    near-zero stiffness at zero twist.
    """
    return _reference_stiffness(config.transmission_model(), config.transmission_blocks()[1])


def _reference_stiffness(tr: Transmission, ctrl: npt.NDArray[np.float64]) -> float:
    """:func:`reference_stiffness` of the controller's block ``ctrl`` of ``tr``."""
    try:
        x = tr.twist_for_torque(ctrl, REFERENCE_TORQUE_FRACTION * tr.rating_nm(ctrl), 0.0)
    except TransmissionError:
        x = 0.0
    return max(tr.stiffness(ctrl, x, 0.0), 0.0)


def law_model_writes(fx: Effects) -> list[tuple[str, str, float]]:
    """(model field, joint, value) of every model write of the registry laws switched on in
    ``fx`` (:class:`~fsarm_sim.plant.effects.base.ModelWrite`), in registry order; a parameter
    not given is the law's declared default."""
    given = dict(fx.laws)
    out = []
    for e in registry.arm_laws():
        if e.name not in given:
            continue
        values = {d.name: d.default for d in e.law.KERNEL_PARAMS} if e.law else {}
        values.update(given[e.name])
        out += [(w.field, w.joint, values[w.param]) for w in model_writes(e.law)]
    return out


def write_law_model(model: mujoco.MjModel, fx: Effects) -> None:
    """Add the model writes of the laws switched on (:func:`law_model_writes`) to the compiled
    model's per-dof fields; a law on a joint the model lacks is a ModelStructureError."""
    for name, joint, value in law_model_writes(fx):
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if j < 0:
            raise ModelStructureError(f"an effect law acts on joint {joint!r}; the model has none")
        getattr(model, name)[model.jnt_dofadr[j]] += value


def write_laws(p: npt.NDArray[np.float64], fx: Effects, model: mujoco.MjModel) -> None:
    """The registry's arm laws: on/off slot, the address of their own states in ``data.act``
    (the actuators :func:`add_law_states` added; -1 when off or without any) and parameters
    (declared defaults unless given)."""
    given = dict(fx.laws)
    by_name = {e.name: e for e in registry.arm_laws()}
    for b in layout.ARM_LAW_BLOCKS:
        law = by_name[b.name].law
        assert law is not None
        values = dict(given.get(b.name, ()))
        p[b.on] = 1.0 if b.name in given else 0.0
        p[b.act] = -1.0
        if b.name in given and law.STATES:
            first = f"{b.name}.{law.STATES[0].name}"
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, first)
            if a < 0:
                raise ModelStructureError(f"the model has no state actuator {first!r}")
            p[b.act] = float(model.actuator_actadr[a])
        for i, d in enumerate(law.KERNEL_PARAMS):
            p[b.start + i] = values.get(d.name, d.default)


def write_arm_effects(
    model: mujoco.MjModel,
    p: npt.NDArray[np.float64],
    fx: Effects,
    *,
    lever_arms: tuple[float, float] | None = None,
) -> None:
    """Plant-only arm effects (the registry's laws), each law's ``FROM_MODEL`` parameters read
    from the compiled MJCF (:func:`model_quantities`; ``lever_arms``: :func:`payload_lever_arms_m`
    of ``model`` if known)."""
    write_laws(p, fx, model)
    known = model_quantities(model, lever_arms)
    for b in layout.ARM_LAW_BLOCKS:
        law = registry.get(b.name).law
        assert law is not None
        for i, d in enumerate(law.KERNEL_PARAMS):
            if d.name in getattr(law, "FROM_MODEL", ()):
                p[b.start + i] = known[d.name]


def model_quantities(
    model: mujoco.MjModel, lever_arms: tuple[float, float] | None = None
) -> dict[str, float]:
    """What a law's ``FROM_MODEL`` may name, read from the compiled MJCF: ``l2`` (joint 2 ->
    joint 3) and ``l3`` (joint 3 -> payload centre of mass) at the zero pose, m, and ``gravity``
    (|g|, m/s^2)."""
    l2, l3 = payload_lever_arms_m(model) if lever_arms is None else lever_arms
    return {"l2": l2, "l3": l3, "gravity": float(np.linalg.norm(model.opt.gravity))}


def payload_lever_arms_m(model: mujoco.MjModel) -> tuple[float, float]:
    """(joint 2 -> joint 3, joint 3 -> payload centre of mass) distances at the zero pose, m.

    (0, 0) for a model without the arm's joint 2 / payload (the benches).
    """
    J = mujoco.mjtObj.mjOBJ_JOINT
    if (
        mujoco.mj_name2id(model, J, "q2") < 0
        or mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "payload") < 0
    ):
        return 0.0, 0.0
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    a2 = data.xanchor[named_id(model, J, "q2")]
    a3 = data.xanchor[named_id(model, J, "q3")]
    b = named_id(model, mujoco.mjtObj.mjOBJ_BODY, "payload")
    com = data.xpos[b] + data.xmat[b].reshape(3, 3) @ np.array([0.0, 0.0, PAYLOAD_COM_OFFSET_M])
    return float(np.linalg.norm(a3 - a2)), float(np.linalg.norm(com - a3))


def params(model: mujoco.MjModel) -> npt.NDArray[np.float64] | None:
    """The parameter vector of an fsarm model, or None for any other model."""
    try:
        p = model.numeric(layout.PARAMS_NAME).data
    except KeyError:
        return None
    if p.size != layout.N_PARAMS or p[layout.P_MAGIC] != layout.MAGIC:
        return None
    return p


def reference(model: mujoco.MjModel) -> npt.NDArray[np.float64]:
    return model.numeric(layout.REF_NAME).data
