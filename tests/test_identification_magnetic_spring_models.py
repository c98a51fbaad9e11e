"""Seed 003's identification: eq. 1, eq. 3 and the Table 3 models with Table 4's criteria."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fsarm_sim.studies.identification import magnetic_spring_models as msm


def test_eq1_fit_recovers_a_known_law() -> None:
    true = msm.SpringLaw(b=(1.0, -0.06, -0.012), a=(-50.0, 300.0, 0.0, 0.0), rms_nm=0.0)
    d = np.repeat([0.0, 0.002, 0.004, 0.006, 0.008, 0.01], 83)
    ph = np.tile(np.arange(-41.0, 42.0), 6)
    fit = msm.fit_spring_law(d, ph, true.torque(d, ph))
    assert fit.b == pytest.approx(true.b, rel=1e-6, abs=1e-8)
    assert fit.torque(d, ph) == pytest.approx(true.torque(d, ph), abs=1e-9)
    # eq. 2: stiffness in stable equilibrium = -d tau / d phi_r at 0 (per rad)
    h = 1e-6
    slope = -(true.torque(0.004, h / (math.pi / 180)) - true.torque(0.004, -h / (math.pi / 180)))
    assert fit.stiffness_nm_per_rad(0.004) == pytest.approx(float(slope) / (2 * h), rel=1e-5)


def test_eq3_fit_recovers_inertia_and_friction() -> None:
    J, fr, r = 0.012, 0.05, 0.04
    m = np.array([0.2, 0.4, 0.8])
    acc = (m * 9.81 * r - fr) / (m * r * r + J)
    assert msm.fit_inertia(m, r, acc) == pytest.approx((J, fr), rel=1e-9)


def _synthetic(model_params: dict[str, float], n: int, seed: int) -> msm.Samples:
    rng = np.random.default_rng(seed)
    po = rng.uniform(-3, 3, n)
    vo = rng.normal(0, 2, n)
    vi = vo + rng.normal(0, 1, n)
    tau_sp = rng.normal(0, 0.5, n)
    p = model_params
    tau = (
        tau_sp - p["fr"] * np.tanh(p["v"] * vo) + p["w"] * np.sin(po + p["x"]) - p["z"] * (vo - vi)
    )
    acc = tau / p["J"] + rng.normal(0, p["noise"], n)
    return msm.Samples(acc=acc, phi_out=po, v_out=vo, v_in=vi, tau_sp=tau_sp, tau_lin=tau_sp)


TRUE = {"fr": 0.05, "v": 40.0, "w": 0.02, "x": 0.5, "z": 0.01, "J": 0.01, "noise": 0.3}


def test_model_f_recovers_its_parameters_and_ranks_first() -> None:
    teach, verify = _synthetic(TRUE, 8000, 1), _synthetic(TRUE, 8000, 2)
    rows = msm.select_models(teach, verify, TRUE["J"])
    f = rows["F"].fit
    fr, w1, w2, z = f.params
    assert fr == pytest.approx(TRUE["fr"], rel=0.05)
    assert math.hypot(w1, w2) == pytest.approx(TRUE["w"], rel=0.05)
    assert math.atan2(w2, w1) == pytest.approx(TRUE["x"], abs=0.05)
    assert z == pytest.approx(TRUE["z"], rel=0.05)
    assert f.v == pytest.approx(TRUE["v"], rel=0.15)
    assert rows["F"].verifying.mse == pytest.approx(TRUE["noise"] ** 2, rel=0.05)
    v = {m: r.verifying.mse for m, r in rows.items()}
    assert v["F"] < v["D"] < v["C"] < v["A"]


def test_criteria_are_table_4s_formulas() -> None:
    s = _synthetic(TRUE, 500, 3)
    fit = msm.fit_model("D", s, TRUE["J"])
    sc = msm.score(fit, s, TRUE["J"])
    r = fit.residual(s, TRUE["J"])
    n, k = 500, 4
    sse = float(r @ r)
    assert sc.mse == pytest.approx(sse / n)
    assert sc.se == pytest.approx(math.sqrt(sse / (n - k)))
    assert sc.bic == pytest.approx(n * math.log(sse / n) + k * math.log(n))
    r2 = 1 - sse / float(np.sum((s.acc - s.acc.mean()) ** 2))
    assert 1 - sc.one_minus_r2_adj == pytest.approx(1 - (1 - r2) * (n - 1) / (n - k - 1))
    text = msm.table4({"D": msm.SelectionRow(fit, sc, sc)})
    assert "D" in text and "BIC" in text and "‰" in text


def test_bad_input_raises_named_errors() -> None:
    s = _synthetic(TRUE, 50, 4)
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_model("G", s, 0.01)
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_model("A", s, 0.0)
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_spring_law([0.0, 0.001], [1.0, 2.0], [0.1, 0.2])  # < 5 distances
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_spring_law([0.0, 0.001], [1.0], [0.1, 0.2])
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_inertia([0.2, 0.2], 0.05, [1.0, 1.0])
    with pytest.raises(msm.ModelSelectionError):
        msm.fit_inertia([0.2, 0.3], 0.05, [1.0, math.nan])


@pytest.mark.parametrize("model", msm.MODELS + msm.LINEARISED)
def test_free_run_terms_are_the_fitted_columns(model: str) -> None:
    rng = np.random.default_rng(5)
    s = _synthetic(TRUE, 40, 6)
    cols = msm._columns(model, s, 30.0)
    params = tuple(float(x) for x in rng.normal(0, 0.1, size=int(cols.shape[1])).tolist())
    fit = msm.ModelFit(model=model, params=params, v=30.0)
    for i in range(s.n):
        expect = float(cols[i] @ np.array(params)) if cols.shape[1] else 0.0
        got = msm._extra_torque(fit, s.phi_out[i], s.v_out[i], s.v_in[i])
        assert got == pytest.approx(expect, abs=1e-12)


def test_free_run_is_eq7() -> None:
    law = msm.SpringLaw(b=(1.0, -0.06, -0.012), a=(-50.0, 0.0, 0.0, 0.0), rms_nm=0.0)
    fit = msm.ModelFit(model="C", params=(0.05,), v=50.0)
    T, J, d = 0.005, 0.01, 0.002
    t = np.arange(400) * T
    pin = np.radians(20.0 * np.sin(2 * np.pi * 0.8 * t))
    po = np.zeros_like(pin)
    for n in range(2, t.size):  # eq. 7 by hand, model C
        vo = (po[n - 1] - po[n - 2]) / T
        tau = float(law.torque(d, np.degrees(po[n - 1] - pin[n - 1]))) - 0.05 * np.tanh(50 * vo)
        po[n] = 2 * po[n - 1] - po[n - 2] + T * T / J * tau
    sim = msm.free_run(fit, law, J, pin, po, d, T)
    assert sim == pytest.approx(po, abs=1e-12)
    assert np.ptp(po) > 0.2  # the output moved


def test_named_params_use_table_5s_names() -> None:
    fit = msm.ModelFit(model="F", params=(0.05, 0.3, 0.4, 0.002), v=40.0)
    named = msm.named_params(fit)
    assert named["tau_fr"] == 0.05 and named["v"] == 40.0 and named["z"] == 0.002
    assert named["w"] == pytest.approx(0.5)
    assert named["x"] == pytest.approx(math.atan2(0.4, 0.3))
    assert msm.named_params(msm.ModelFit(model="A", params=(), v=0.0)) == {}
    assert set(msm.named_params(msm.ModelFit(model="B", params=(0.1,), v=0.0))) == {"tau_fr"}
