"""The kernel dispatch generated from the registries (fsarm_sim.kernels.dispatch)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from fsarm_sim.engine.model import Effects, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import dispatch, layout
from fsarm_sim.paramblocks import Decl
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import base, registry
from fsarm_sim.plant.effects.base import S_BEND, S_OMEGA_M, S_OWN, S_Q2, S_QD3, STATE


def _fake_law(scale: float, n_states: int = 0) -> SimpleNamespace:
    def arm_torques(blk, s):  # type: ignore[no-untyped-def]
        own = sum(s[S_OWN:])
        return scale * blk[0] * s[S_Q2], scale * blk[1] * s[S_QD3], scale * (s[S_BEND] + own)

    def state_rate(blk, s, i):  # type: ignore[no-untyped-def]
        return scale * (i + 1) * s[S_OWN + i] + s[S_OMEGA_M]

    states = tuple(Decl(f"z{i}", "-", 0.0, "test state") for i in range(n_states))
    return SimpleNamespace(
        KERNEL_PARAMS=(), STATES=states, arm_torques=arm_torques, state_rate=state_rate
    )


def _state(**values: float) -> tuple[float, ...]:
    s = [0.0] * S_OWN
    for name, v in values.items():
        s[[n for n, _, _ in STATE].index(name)] = v
    return tuple(s)


def test_law_dispatch_sums_the_laws_that_are_on() -> None:
    blocks = (layout.LawBlock("a", 0, 1, 2, 4, 0), layout.LawBlock("b", 4, 5, 6, 8, 2))
    laws = {"a": _fake_law(1.0), "b": _fake_law(10.0, n_states=2)}
    fn = dispatch.law_dispatch(blocks, laws)
    prm = np.array([0.0, -1.0, 2.0, 3.0, 0.0, 1.0, 5.0, 7.0])
    act = np.array([9.0, 0.5, 0.25])  # law b's own states at act[1], act[2]
    s = _state(q2=0.5, qd3=2.0, bend=0.125, omega_m=3.0)
    assert fn(prm, act, s) == (0.0, 0.0, 0.0)  # both off
    prm[0] = 1.0
    assert fn(prm, act, s) == (1.0, 6.0, 0.125)
    prm[4] = 1.0  # b on: its own states (0.5 + 0.25) are appended to the named state
    assert fn(prm, act, s) == (1.0 + 25.0, 6.0 + 140.0, 0.125 + 8.75)
    assert "# a" in dispatch.SOURCE["arm_law_torques"]  # the generated text is kept for reading


def test_state_rate_dispatch_reaches_the_owner_of_an_act_slot() -> None:
    blocks = (layout.LawBlock("a", 0, 1, 2, 4, 0), layout.LawBlock("b", 4, 5, 6, 8, 2))
    laws = {"a": _fake_law(1.0), "b": _fake_law(10.0, n_states=2)}
    owns = dispatch.law_owner_dispatch(blocks)
    rate = dispatch.law_rate_dispatch(blocks, laws)
    prm = np.array([1.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    act = np.array([9.0, 0.5, 0.25])
    s = _state(omega_m=3.0)
    assert not any(owns(prm, adr) for adr in range(3))  # b is off
    prm[4] = 1.0
    assert [owns(prm, adr) for adr in range(3)] == [False, True, True]
    assert rate(prm, act, s, 1) == 10.0 * 1 * 0.5 + 3.0
    assert rate(prm, act, s, 2) == 10.0 * 2 * 0.25 + 3.0


def test_every_registered_law_has_its_block_in_the_layout() -> None:
    laws = registry.arm_laws()
    assert [b.name for b in layout.ARM_LAW_BLOCKS] == [e.name for e in laws]
    for b, effect in zip(layout.ARM_LAW_BLOCKS, laws, strict=True):
        assert effect.law is not None
        assert b.end - b.start == len(effect.law.KERNEL_PARAMS)
        assert b.n_states == len(effect.law.STATES)
        assert (
            layout.LAYOUT.slots[b.on].block == layout.LAYOUT.slots[b.act].block == f"law:{b.name}"
        )
        assert [s.decl.name for s in layout.LAYOUT.slots[b.start : b.end]] == [
            d.name for d in effect.law.KERNEL_PARAMS
        ]
        # the registry's fit parameters of an arm law are its kernel parameters (the arm
        # diagnosis hands them to SimConfig by name)
        declared = {d.name for d in effect.law.KERNEL_PARAMS}
        for v in effect.variants:
            if registry.ARM in v.setups:
                assert {p.name for p in v.params} <= declared


def test_every_law_acts_through_its_hooks() -> None:
    """Each registered arm law acts in at least one way the kernels or the model builder apply;
    a law with own states has the rates of them; a model write adds a declared parameter to a
    per-dof field MuJoCo has; older records' keys name declared parameters."""
    import mujoco

    from fsarm_sim.engine.model import model_quantities

    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    for e in registry.arm_laws():
        hooks = base.hooks(e.law)
        assert hooks, e.name
        if e.law is not None and e.law.STATES:
            assert base.TORQUES in hooks, e.name
        declared = {d.name for d in e.law.KERNEL_PARAMS} if e.law else set()
        for w in base.model_writes(e.law):
            assert w.param in declared and w.field.startswith("dof_") and hasattr(model, w.field)
        assert {p for _, p in getattr(e.law, "LEGACY_FIELDS", ())} <= declared
        assert getattr(e.law, "SIZE", None) in declared | {None}
        # the parameters the model builder reads from the MJCF: ones it knows, ones it declares
        assert set(getattr(e.law, "FROM_MODEL", ())) <= set(model_quantities(model)) & declared
    assert set(registry.legacy_fields()) == {
        "payload_error_kg",
        "backlash_width_rad",
        "backlash_center_rad",
        "q3_friction_nm",
        "q3_damping_nms",
    }


def test_the_twist_dispatch_applies_the_laws_that_are_on_in_order() -> None:
    """``arm_law_twist``: each twist law that is on, in turn; the twist as it is when none is."""
    # the registry's: the backlash alone (a model-write law reaches neither dispatcher)
    assert [b.name for b in dispatch.TWIST_BLOCKS] == ["backlash"]
    torque_laws = [b.name for b in dispatch.TORQUE_BLOCKS]
    assert "payload_error" in torque_laws and "backlash" not in torque_laws
    assert "coulomb_friction" not in torque_laws and "viscous_damping" not in torque_laws

    def shift(by: float) -> SimpleNamespace:
        return SimpleNamespace(transmitted_twist=lambda blk, x, r: (blk[0] * x + by, r + by))

    blocks = (
        layout.LawBlock("a", on=0, act=1, start=2, end=3, n_states=0),
        layout.LawBlock("b", on=3, act=4, start=5, end=6, n_states=0),
    )
    twist = dispatch.law_twist_dispatch(blocks, {"a": shift(1.0), "b": shift(10.0)})
    prm = np.array([0.0, -1.0, 2.0, 0.0, -1.0, 3.0])
    assert twist(prm, 0.5, 0.25) == (0.5, 0.25)
    prm[0] = 1.0
    assert twist(prm, 0.5, 0.25) == (2.0, 1.25)
    prm[3] = 1.0
    assert twist(prm, 0.5, 0.25) == (3.0 * 2.0 + 10.0, 11.25)


def test_the_named_state_holds_what_the_kernels_compute() -> None:
    """law_state at a model's state: every named quantity equals its definition."""
    from fsarm_sim.engine.model import build_model, read_structure
    from fsarm_sim.kernels import physics

    m = build_model(SimConfig(), np.zeros((2, layout.REF_COLS)))
    st = read_structure(m)
    prm = m.numeric(layout.PARAMS_NAME).data
    qpos = np.array([0.1, 0.2, 0.3, 4.0])[np.argsort(st.qadr)]
    qvel = np.array([1.0, 2.0, 3.0, 40.0])[np.argsort(st.dof)]
    ud = np.zeros(layout.N_USERDATA)
    ud[layout.U_OUT + 2] = 0.7
    twist, rate = physics.twist_and_rate(prm, qpos, qvel)
    s = physics.law_state(prm, qpos, qvel, ud, twist, rate, 0.2)
    assert len(s) == S_OWN
    want = {
        "q2": 0.2,
        "q3": 0.3,
        "qd2": 2.0,
        "qd3": 3.0,
        "theta_m": st.coef_m * 4.0,
        "omega_m": st.coef_m * 40.0,
        "twist": st.coef_m * 4.0 - st.coef_s * 0.3,
        "twist_rate": st.coef_m * 40.0 - st.coef_s * 3.0,
        "bend": 0.2,
        "tau_rotor": 0.7,
        "coef_m": st.coef_m,
        "timestep": m.opt.timestep,
    }
    assert [n for n, _, _ in STATE] == list(want)
    assert s == pytest.approx(tuple(want.values()), rel=1e-15, abs=1e-15)


def test_generated_transmission_dispatch_has_one_branch_per_module() -> None:
    src = dispatch.SOURCE["tr_torque"]
    for i, mod in enumerate(transmissions.MODULES.values()):
        assert f"_tr{i}.torque_nm" in src
        assert transmissions.KIND[mod.__name__.rsplit(".", 1)[1]] == i


def test_unknown_law_is_a_named_error() -> None:
    with pytest.raises(InvalidParameterError, match="unknown arm effect law 'no_such'"):
        SimConfig(effects=Effects(laws=(("no_such", ()),))).validate()
