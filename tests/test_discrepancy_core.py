"""The diagnosis core behind its Setup protocol: a toy third setup (a spring read through a
torque sensor, fitted by linear least squares) runs through the same forward selection,
judgement, scores, report and print-out as the benches and the arm; the effect text of every
setup goes through one registry-driven parser."""

from __future__ import annotations

import io
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rich.console import Console

from fsarm_sim.discrepancy import core, report, selection
from fsarm_sim.discrepancy.effect_text import parse_effect
from fsarm_sim.discrepancy.residuals import noise_floor, nrmse, split_masks
from fsarm_sim.errors import InvalidParameterError
from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.records.measured import Dataset

FloatArray = np.ndarray


@dataclass(eq=False)
class ToyFit:
    model: dict[str, float]  # coefficient per column
    yhat: FloatArray
    k: int
    mse_teach: float
    mse_held: float
    label: str = "nominal"
    effect: str | None = None
    variant: str | None = None
    note: str = ""


class ToySetup:
    """``y = K x [+ offset] [+ F sgn(x')] + noise``: the stated K, a refit K, two candidates."""

    main_channel = "y"
    mse_name = "MSE"
    look_alikes = (frozenset({"sensor_offset", "coulomb_friction"}),)
    score_cell = ("held-out MSE", lambda sc: f"{sc.mse_held:.3g}")
    load_hint = "load the final model: json.load(MODEL)"

    def __init__(self, ds: Dataset, k_stated: float) -> None:
        self.dataset = ds
        x, y = ds.columns["x"], ds.columns["y"]
        self.y = y
        self.teach, self.held = split_masks(y.size)
        self.cols = {
            "k": x,
            "sensor_offset": np.ones_like(x),
            "coulomb_friction": np.sign(np.gradient(x)),
        }
        self.ctx = {"k_stated": k_stated}
        self.noise_var = noise_floor(y) ** 2

    def _fit(self, names: list[str], fixed: dict[str, float] | None = None) -> ToyFit:
        free = [n for n in names if not fixed or n not in fixed]
        base = sum((v * self.cols[n] for n, v in (fixed or {}).items()), np.zeros_like(self.y))
        a = np.column_stack([self.cols[n] for n in free]) if free else np.zeros((self.y.size, 0))
        coef = np.linalg.lstsq(a[self.teach], (self.y - base)[self.teach], rcond=None)[0]
        model = {**(fixed or {}), **dict(zip(free, (float(c) for c in coef), strict=True))}
        yhat = base + a @ coef
        r = self.y - yhat
        mt, mh = float(np.mean(r[self.teach] ** 2)), float(np.mean(r[self.held] ** 2))
        return ToyFit(model, yhat, len(free), mt, mh)

    def nominal(self) -> tuple[ToyFit, ToyFit]:
        cat = self._fit(["k"], {"k": self.ctx["k_stated"]})
        cat.label = "nominal (stated)"
        nom = self._fit(["k"])
        nom.label = "nominal (refit)"
        return cat, nom

    def candidates(self, cur: ToyFit, named: Sequence[str]) -> list[ToyFit]:
        out = []
        for e in ("sensor_offset", "coulomb_friction"):
            if e not in named:
                f = self._fit([*cur.model, e])
                f.effect, f.variant, f.label = e, "toy", f"{e}[toy]"
                out.append(f)
        return out

    def cost(self, fit: ToyFit) -> tuple[float, float, int]:
        return fit.mse_teach, fit.mse_held, fit.k

    def residual(self, fit: ToyFit) -> tuple[FloatArray, FloatArray, FloatArray]:
        return self.y - fit.yhat, self.teach, self.held

    def gap(self, fit: ToyFit) -> float:
        return nrmse(self.y, fit.yhat, self.held)

    def effect_params(self, fit: ToyFit) -> dict[str, Any]:
        return {"value": fit.model[fit.effect or ""]}

    def accept(self, fit: ToyFit) -> ToyFit:
        return fit

    def finish(self, fit: ToyFit, named: Sequence[str]) -> ToyFit:
        return fit

    def conclude(
        self, nominal: ToyFit, final: ToyFit, named: Sequence[str]
    ) -> tuple[str, dict[str, Any]]:
        return (f"missing: {', '.join(named)}" if named else "nothing is missing"), {"toy": 1}

    def parameters(self, model: dict[str, float]) -> dict[str, Any]:
        return {"nominal": {"k": model["k"]}, "effects": {k: v for k, v in model.items()}}

    def save_model(self, model: dict[str, float], path: Path) -> Path:
        path.write_text(json.dumps(model))
        return path

    def report(self, diag: core.Diagnosis[ToyFit]) -> core.ReportParts:
        fits = {"catalogue": diag.catalogue, "nominal": diag.nominal, "final": diag.final}
        return core.ReportParts(
            head={"setup": "toy"},
            gaps={},
            nominal_refit={"refit": diag.nominal.model},
            noise_floor={"y": self.noise_var**0.5},
            nrmse={"y": {k: self.gap(f) for k, f in fits.items()}},
            signatures={},
            method={"bic": "n ln(MSE) + k ln(n)"},
            tail={"toy": diag.extras["toy"]},
        )

    def plots(self, diag: core.Diagnosis[ToyFit], folder: Path) -> list[Path]:
        return []

    def summary_lines(self, diag: core.Diagnosis[ToyFit]) -> list[str]:
        return [f"named effects: {diag.named or 'none'}", diag.verdict]


def _toy(offset: float, friction: float, seed: int = 0) -> ToySetup:
    rng = np.random.default_rng(seed)
    t = np.arange(6000) * 1e-3
    x = 0.3 * np.sin(2 * np.pi * 0.7 * t) + 0.1 * np.sin(2 * np.pi * 2.3 * t + 1.0)
    y = 11.0 * x + offset + friction * np.sign(np.gradient(x)) + 0.01 * rng.standard_normal(t.size)
    cols = {"t": t, "x": x, "y": np.asarray(y, dtype=np.float64)}
    ds = Dataset(Path("toy.csv"), "toy", cols, {}, load_catalogue().shaft())
    return ToySetup(ds, k_stated=10.0)


def test_a_third_setup_runs_through_the_core(tmp_path: Path) -> None:
    setup: core.Setup[ToyFit] = _toy(offset=0.05, friction=0.2)
    diag = core.diagnose(setup, max_effects=4)
    # the larger effect first, then the smaller one, then nothing left (the selection stops)
    assert diag.named == ["coulomb_friction", "sensor_offset"]
    assert diag.final.model["coulomb_friction"] == pytest.approx(0.2, rel=0.02)
    assert diag.final.model["sensor_offset"] == pytest.approx(0.05, rel=0.05)
    assert diag.final.label == "nominal + coulomb_friction + sensor_offset"
    assert diag.gap_after < 0.2 * diag.gap_before and diag.gap_over_noise(diag.final) < 1.1
    first, second = diag.steps[:2]
    assert first.added == "coulomb_friction" and first.runner_up == "sensor_offset"
    assert first.look_alike and first.bic_margin is not None and first.bic_margin > 10
    assert first.scores[0].earns_place and not first.scores[0].extra
    assert second.scores[0].extra  # judged as an extra effect (the stricter rule)
    assert [st.reason for st in diag.steps[2:]] == ["no candidate could be fitted"]  # none left

    res = report.result_dict(diag, tmp_path / "m.json")
    assert res["named_effects"] == ["coulomb_friction", "sensor_offset"]
    assert res["setup"] == "toy" and res["toy"] == 1
    assert res["bic"]["final"] < res["bic"]["nominal"]
    assert res["method"]["bic_threshold"] == selection.BIC_THRESHOLD
    files = report.write_report(diag, tmp_path / "rep")
    assert json.loads(files["model"].read_text())["k"] == pytest.approx(11.0, rel=0.01)
    assert files["bic"].is_file()
    out = io.StringIO()
    report.print_diagnosis(diag, Console(file=out, width=200))
    text = out.getvalue()
    assert "coulomb_friction[toy]" in text and "held-out MSE" in text and "missing:" in text


def test_a_clean_toy_record_names_nothing() -> None:
    diag = core.diagnose(_toy(offset=0.0, friction=0.0, seed=1), max_effects=4)
    assert diag.named == [] and diag.final is diag.nominal
    st = diag.steps[0]
    assert st.added is None and "does not earn its place" in st.reason


def test_one_effect_text_parser_for_every_setup() -> None:
    e = parse_effect("backlash=0.02", "arm")  # the arm's backlash centre defaults to 0
    assert (e.name, e.variant, e.params) == (
        "backlash",
        "twist",
        {"width_rad": 0.02, "center_rad": 0.0},
    )
    e = parse_effect("delay:q3=0.004", "arm")
    assert (e.variant, e.params) == ("q3", {"delay_s": 0.004})
    e = parse_effect("hysteresis=4,0.003,2,0.01", "arm")
    assert e.params == {"k_nm_per_rad": [4.0, 2.0], "delta_rad": [0.003, 0.01]}
    e = parse_effect("hysteresis:viscoelastic=5,0.2", "parallel_bench")
    assert e.params == {"k_nm_per_rad": [5.0], "tau_s": [0.2]}
    for text, setup, words in (
        ("delay=0.004", "arm", "needs its variant"),  # which recorded channel lags
        ("backlash=0.02", "series_bench", "takes 2 value"),  # the benches' centre is required
        ("hysteresis=1,0.01,2,0.02,3,0.03,4,0.04", "arm", "1 to 3 groups"),
        ("nonlinear_stiffness=0,1", "arm", "does not act in setup 'arm'"),
        ("coulomb_friction:shaft=0.1", "arm", "no variant 'shaft'"),
        ("payload_error=20", "arm", "outside"),
        ("gremlins=1", "arm", "unknown effect"),
    ):
        with pytest.raises(InvalidParameterError, match=words):
            parse_effect(text, setup, 0.4)


def _toy_pair(d_amp: float, seed: int = 2) -> ToySetup:
    """Two effects that each look like nothing alone: columns a = s + d and b = s - d with a
    large common part s the output does not contain, and the output holding (a - b) / 2 = d."""
    toy = _toy(offset=0.0, friction=0.0, seed=seed)
    t = toy.dataset.columns["t"]
    s = np.sin(2 * np.pi * 0.23 * t + 0.4)  # absent from the output
    d = d_amp * np.sin(2 * np.pi * 3.1 * t)
    toy.cols["sensor_offset"] = s + d
    toy.cols["coulomb_friction"] = s - d
    toy.y = toy.y + d
    toy.noise_var = noise_floor(toy.y) ** 2
    return toy


def test_effects_that_come_together_are_named_together() -> None:
    # alone, neither candidate explains more than ~1 % of what is missing (it earns no place)
    greedy = core.diagnose(_toy_pair(0.1), max_effects=4, joint=False)
    assert greedy.named == []
    diag = core.diagnose(_toy_pair(0.1), max_effects=4)
    assert sorted(diag.named) == ["coulomb_friction", "sensor_offset"]
    joint = diag.steps[1]
    assert joint.joint and joint.added_effects == diag.named
    assert joint.scores[0].earns_place and "joint search" in joint.reason
    assert diag.gap_over_noise(diag.final) < 1.1
    # the same pair hidden below the noise: the joint search does not even start
    quiet = core.diagnose(_toy_pair(0.002), max_effects=4)
    assert quiet.named == [] and not any(st.joint for st in quiet.steps)
