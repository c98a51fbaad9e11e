"""The kernel dispatch generated from the registries (fsarm_sim.kernels.dispatch)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from fsarm_sim.engine.model import Effects, SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import dispatch
from fsarm_sim.kernels import layout as L
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.effects import registry


def _fake_law(scale: float) -> SimpleNamespace:
    def arm_torques(blk, q2, q3, qd2, qd3, omega_m, twist, twist_rate, bend):  # type: ignore[no-untyped-def]
        return scale * blk[0] * q2, scale * blk[1] * qd3, scale * (omega_m + twist + bend)

    return SimpleNamespace(KERNEL_PARAMS=(), arm_torques=arm_torques)


def test_law_dispatch_sums_the_laws_that_are_on() -> None:
    blocks = (("a", 0, 1, 3), ("b", 3, 4, 6))
    fn = dispatch.law_dispatch(blocks, {"a": _fake_law(1.0), "b": _fake_law(10.0)})
    prm = np.array([0.0, 2.0, 3.0, 0.0, 5.0, 7.0])
    args = (0.5, 0.0, 0.0, 2.0, 1.0, 0.25, 0.0, 0.125)
    assert fn(prm, *args) == (0.0, 0.0, 0.0)  # both off
    prm[0] = 1.0
    assert fn(prm, *args) == (1.0, 6.0, 1.375)
    prm[3] = 1.0
    assert fn(prm, *args) == (1.0 + 25.0, 6.0 + 140.0, 1.375 + 13.75)
    assert "# a" in dispatch.SOURCE["arm_law_torques"]  # the generated text is kept for reading


def test_every_registered_law_has_its_block_in_the_layout() -> None:
    laws = registry.arm_laws()
    assert [b[0] for b in L.ARM_LAW_BLOCKS] == [e.name for e in laws]
    for (name, on, start, end), effect in zip(L.ARM_LAW_BLOCKS, laws, strict=True):
        assert effect.law is not None
        assert end - start == len(effect.law.KERNEL_PARAMS)
        assert L.LAYOUT.slots[on].block == f"law:{name}"
        assert [s.decl.name for s in L.LAYOUT.slots[start:end]] == [
            d.name for d in effect.law.KERNEL_PARAMS
        ]
        # the registry's fit parameters of an arm law are its kernel parameters (the arm
        # diagnosis hands them to SimConfig by name)
        declared = {d.name for d in effect.law.KERNEL_PARAMS}
        for v in effect.variants:
            if registry.ARM in v.setups:
                assert {p.name for p in v.params} <= declared


def test_generated_transmission_dispatch_has_one_branch_per_module() -> None:
    src = dispatch.SOURCE["tr_torque"]
    for i, mod in enumerate(transmissions.MODULES.values()):
        assert f"_tr{i}.torque_nm" in src
        assert transmissions.KIND[mod.__name__.rsplit(".", 1)[1]] == i


def test_unknown_law_is_a_named_error() -> None:
    with pytest.raises(InvalidParameterError, match="unknown arm effect law 'no_such'"):
        SimConfig(effects=Effects(laws=(("no_such", ()),))).validate()
