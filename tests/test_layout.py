"""The kernels' parameter vector is declared block by block; offsets are computed, never typed."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fsarm_sim.kernels import layout, physics
from fsarm_sim.paramblocks import Decl, Layout, LayoutError
from fsarm_sim.plant import transmissions


def test_every_slot_is_declared_once_and_blocks_do_not_overlap() -> None:
    slots = layout.LAYOUT.slots
    assert [s.index for s in slots] == list(range(layout.N_PARAMS))
    spans = sorted(layout.LAYOUT.blocks().values())
    for (_, a1), (b0, _) in itertools.pairwise(spans):
        assert a1 <= b0
    assert spans[0][0] == 0 and spans[-1][1] == layout.N_PARAMS
    for s in slots:
        assert s.decl.unit and s.decl.source, s  # every slot says what it holds


def test_every_named_constant_points_into_its_declared_block() -> None:
    named = {k: v for k, v in vars(layout).items() if k.startswith("P_") and isinstance(v, int)}
    assert len(set(named.values())) == len(named)  # no two names share a slot
    for v in named.values():
        assert 0 <= v < layout.N_PARAMS
    lo, hi = layout.LAYOUT.bounds("plant_transmission")
    assert (layout.P_TR, hi - lo) == (lo, layout.N_TR)


def test_a_law_module_declares_its_own_block() -> None:
    from fsarm_sim.plant.effects import backlash, bending

    lo, hi = layout.LAYOUT.bounds("bending")
    assert [s.decl.name for s in layout.LAYOUT.slots[lo:hi]] == [
        d.name for d in bending.KERNEL_PARAMS
    ]
    # a registry law's block: its on/off and state-address slots, then its own declarations
    b = layout.LAW_BLOCK["backlash"]
    assert [s.decl for s in layout.LAYOUT.slots[b.start : b.end]] == list(backlash.KERNEL_PARAMS)


def test_duplicate_declarations_are_refused() -> None:
    lay = Layout()
    lay.block("a", (Decl("x", "-", 0.0, "s"),))
    with pytest.raises(LayoutError):
        lay.block("a", (Decl("y", "-", 0.0, "s"),))
    with pytest.raises(LayoutError):
        lay.block("b", (Decl("x", "-", 0.0, "s"), Decl("x", "-", 0.0, "s")))


@pytest.mark.parametrize("name", transmissions.names())
def test_every_transmission_id_reaches_its_own_module(name: str) -> None:
    """Integer dispatch in physics: the registry's id of each transmission runs that module."""
    tr = transmissions.get(name)
    assert tr.kind == layout.TRANSMISSION_MODULES.index(tr.module.__name__.rsplit(".", 1)[1])
    block = tr.block() if name != transmissions.DEFAULT else np.array(tr.block())
    act = np.zeros(8)
    for x in (-0.1, 0.05, 0.2):
        x *= tr.twist_range_rad
        assert physics.tr_torque(tr.kind, block, x, 0.3, 0.4, act, 0) == tr.module.torque_nm(
            block, x, 0.3, 0.4, act, 0
        )
        assert physics.tr_sensor_torque(tr.kind, block, x, 0.4) == tr.module.sensor_torque_nm(
            block, x, 0.4
        )
        assert physics.tr_potential(tr.kind, block, x, 0.4, act, 0) == tr.module.potential_j(
            block, x, 0.4, act, 0
        )
        # the motor end: the module's own motor_torque_nm where it has one, else torque_nm
        own = getattr(tr.module, "motor_torque_nm", tr.module.torque_nm)
        assert physics.tr_motor_torque(tr.kind, block, x, 0.3, 0.4, act, 0) == own(
            block, x, 0.3, 0.4, act, 0
        )
        for i in range(len(tr.module.STATES)):  # the motor-side speed reaches state_rate
            assert physics.tr_state_rate(
                tr.kind, block, x, 0.3, 0.4, act, 0, i, -0.7
            ) == tr.module.state_rate(block, x, 0.3, 0.4, act, 0, i, -0.7)
        assert physics.tr_bend_torque(tr.kind, block, x, 0.4, act, 0) == tr.module.bend_torque_nm(
            block, x, 0.4, act, 0
        )


def test_the_bench_replay_vector_is_declared_too() -> None:
    """The discrepancy replay's parameter vector comes from the same declarations mechanism."""
    from fsarm_sim.discrepancy import replay

    slots = replay.REPLAY_LAYOUT.slots
    assert [s.index for s in slots] == list(range(replay.N_R))
    names = {k: v for k, v in vars(replay).items() if k.startswith("R_") and isinstance(v, int)}
    assert len(set(names.values())) == len(names)
    assert all(0 <= v < replay.N_R for v in names.values())
    assert slots[replay.R_BL_W].decl.name == "width_rad"  # the backlash law's own declaration
