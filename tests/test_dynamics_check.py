"""Pinocchio referees MuJoCo, at reduced size: every check passes on the real model and fails on a
model that is wrong on one side only (a check that cannot fail is not a check)."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from typer.testing import CliRunner

from fsarm_sim.cli import app
from fsarm_sim.engine.model import SimConfig
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.kernels import layout
from fsarm_sim.plant import transmissions
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import dynamics_check

N = 50  # random states per model (the CLI default is 200)
SHORT_S = 0.05  # trajectory length in the tests
DTS = (1e-3, 5e-4)


def _pair(**changes: object) -> dynamics_check.Pair:
    return dynamics_check.make_pair(
        dynamics_check.open_loop(SimConfig().with_(**changes)), dynamics_check.hold_table()
    )


@pytest.fixture(scope="module")
def pairs() -> list[dynamics_check.Pair]:
    slip = load_catalogue().shaft(series_hysteresis=True)
    return [_pair(), _pair(payload_kg=15.0, shaft=slip)]


def _body(pair: dynamics_check.Pair, name: str) -> int:
    return int(mujoco.mj_name2id(pair.mj, mujoco.mjtObj.mjOBJ_BODY, name))


# --- the real model passes -------------------------------------------------------------------


def test_mass_bias_qacc_and_controller_inputs_agree(pairs: list[dynamics_check.Pair]) -> None:
    for check in (
        dynamics_check.check_mass_matrix,
        dynamics_check.check_bias,
        dynamics_check.check_qacc,
        dynamics_check.check_controller_inputs,
    ):
        result = check(pairs, N)
        assert result.passed, result
        assert result.measured < result.tolerance / 100  # round-off, not luck near the bound


def test_structure_of_eq_5_to_7_has_the_values_the_mjcf_implies(
    pairs: list[dynamics_check.Pair],
) -> None:
    pair = pairs[0]
    structure = dynamics_check.elastic_structure(pair)
    assert dynamics_check.check_structure(structure).passed
    entry = {e.name: e for e in structure.entries}
    rotor_izz = pair.mj.body_inertia[_body(pair, "j3_rotor"), 2]
    i_g1, i_g2 = pair.st.i_g1, pair.st.i_g2
    assert entry["S(1,3) = I_r3,zz i_G1"].measured == pytest.approx(rotor_izz * i_g1, rel=1e-12)
    assert entry["B(3,3) = I_r3,zz i_G1^2"].measured == pytest.approx(
        rotor_izz * i_g1**2, rel=1e-12
    )
    assert entry["S(2,3) = 0"].measured == 0.0
    k_sp = pair.config.shaft.k_spring(0.0, 1)  # eq. 3 less the slip elements' apparent share
    assert structure.k_sea_pos[2, 2] == pytest.approx(k_sp * i_g2**2, rel=1e-9)
    assert structure.k_sea_pos[1, 1] == pytest.approx(pair.config.shaft.kb, rel=1e-9)
    assert not structure.k_sea_pos[0].any()  # joint 1 carries no spring


def test_trajectory_agrees_step_for_step_and_converges() -> None:
    study = dynamics_check.trajectory_study(SHORT_S, DTS)
    for result in dynamics_check.check_trajectory(study):
        assert result.passed, result
    first, second = study.rows
    assert second.mujoco_vs_reference_rad < first.mujoco_vs_reference_rad
    assert second.pinocchio_vs_reference_rad < first.pinocchio_vs_reference_rad / 8  # ~4th order


# --- a model that is wrong on one side fails ---------------------------------------------------


def _scale_rotor_inertia(pair: dynamics_check.Pair) -> None:
    pair.mj.body_inertia[_body(pair, "j3_rotor"), 2] *= 1.1


def _add_q2_armature(pair: dynamics_check.Pair) -> None:
    pair.mj.dof_armature[pair.st.dof[1]] += 0.05


def _heavier_motor_housing(pair: dynamics_check.Pair) -> None:
    pair.mj.body_mass[_body(pair, "j3_motor_housing")] *= 1.2


@pytest.mark.parametrize(
    ("perturb", "failing_entry"),
    [
        (_scale_rotor_inertia, "S(1,3)"),
        (_add_q2_armature, "B(2,2)"),
        (_heavier_motor_housing, "M_R(1,1)"),
    ],
)
def test_mujoco_side_inertia_error_fails_mass_structure_and_qacc(
    perturb: Callable[[dynamics_check.Pair], None], failing_entry: str
) -> None:
    pair = _pair()
    perturb(pair)
    assert not dynamics_check.check_mass_matrix([pair], 5).passed
    assert not dynamics_check.check_qacc([pair], 5).passed
    structure = dynamics_check.elastic_structure(pair)
    assert not dynamics_check.check_structure(structure).passed
    worst = max(structure.entries, key=lambda e: e.error)
    assert worst.name.startswith(failing_entry)


def test_pinocchio_side_link_mass_error_fails_mass_bias_and_trajectory() -> None:
    pair = _pair()
    jid = pair.arm.model.getJointId("q3")
    old = pair.arm.model.inertias[jid]
    pair.arm.model.inertias[jid] = pin.Inertia(old.mass * 1.01, old.lever, old.inertia)
    assert not dynamics_check.check_mass_matrix([pair], 5).passed
    assert not dynamics_check.check_bias([pair], 5).passed
    study = dynamics_check.trajectory_study(SHORT_S, DTS[:1], arm=pair.arm)
    same_dt = next(
        r for r in dynamics_check.check_trajectory(study) if r.key == "trajectory_same_dt"
    )
    assert not same_dt.passed


def test_wrong_inertia_index_in_the_controller_fails_only_the_controller_check() -> None:
    pair = _pair()
    pair.params[layout.P_MADR_Q2] = pair.params[layout.P_MADR_Q1]
    assert dynamics_check.check_mass_matrix([pair], 5).passed
    assert not dynamics_check.check_controller_inputs([pair], 5).passed


def test_series_stiffness_wired_wrong_fails_the_structure() -> None:
    pair = _pair()
    pair.params[layout.P_TR] *= (
        1.01  # k_pos (first in the block): the shaft no longer matches its parameters
    )
    structure = dynamics_check.elastic_structure(pair)
    assert not dynamics_check.check_structure(structure).passed
    errors = {e.name: e.error for e in structure.entries}
    sh = pair.config.shaft  # 1 % of eq. 3's K_sp, relative to the plant's (smaller) spring
    assert errors["K_SEA(3,3) = K_s i_G2^2 (winding, K_sp)"] == pytest.approx(
        0.01 * sh.k_pos / sh.k_spring(0.0, 1), rel=1e-6
    )
    assert errors["K_SEA(3,3) = K_s i_G2^2 (unwinding, K_sn)"] < 1e-12  # the other side is right


def test_shaft_inertia_passes_the_mass_matrix_check() -> None:
    """eq. 1 J is lumped as armature at both shaft ends, which both engines read. (As a tendon
    armature MuJoCo 3.17 dropped its rotor-q3 coupling; this check caught that.)"""
    pair = _pair(shaft=dataclasses.replace(load_catalogue().shaft(), inertia_kgm2=2.3e-6))
    assert dynamics_check.check_mass_matrix([pair], 3).passed


# --- inputs and the CLI ----------------------------------------------------------------------


def test_qacc_check_refuses_a_closed_loop_model() -> None:
    closed = dynamics_check.make_pair(SimConfig(), dynamics_check.hold_table())
    with pytest.raises(InvalidParameterError, match="controller off"):
        dynamics_check.check_qacc([closed], 1)


@pytest.mark.parametrize("bad", [{"samples": 0}, {"dts": (5e-4, 1e-3)}, {"dts": (3e-4,)}])
def test_bad_check_sizes_raise_named_errors(bad: dict[str, object]) -> None:
    with pytest.raises(InvalidParameterError):
        dynamics_check.run_checks(**{"samples": 1, "duration_s": 0.002, **bad})  # type: ignore[arg-type]


def test_cli_prints_table_writes_json_and_exits_zero(tmp_path: Path) -> None:
    out = tmp_path / "dyn.json"
    res = CliRunner().invoke(
        app, ["check-dynamics", "--samples", "3", "--duration", "0.02", "--json", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert "mass matrix" in res.output and "pass" in res.output
    data = json.loads(out.read_text())
    for key in (
        "mass_matrix_max_abs_err",
        "bias_max_abs_err",
        "qacc_max_abs_err",
        "trajectory_max_abs_err_rad",
        "convergence",
    ):
        assert key in data
    assert data["passed"] is True
    assert [row["dt_s"] for row in data["convergence"]] == list(dynamics_check.TRAJECTORY_DTS)
    drift = data["energy_drift_j"]  # per transmission, the free bent arm without dissipation
    assert set(drift) == set(transmissions.names())
    assert max(drift.values()) <= 1e-6


def test_cli_exits_non_zero_when_a_check_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    real = dynamics_check.make_pair

    def wrong_rotor(
        config: SimConfig, ref_table: np.ndarray, label: str = ""
    ) -> dynamics_check.Pair:
        pair = real(config, ref_table, label)
        body = pair.mj.body("j3_rotor").id
        pair.mj.body_inertia[body, 2] *= 1.2  # MuJoCo side only
        return pair

    monkeypatch.setattr(dynamics_check, "make_pair", wrong_rotor)
    res = CliRunner().invoke(app, ["check-dynamics", "--samples", "2", "--no-trajectory"])
    assert res.exit_code == 1, res.output
    assert "FAIL" in res.output
