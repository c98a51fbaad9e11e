"""The generalisation protocol of issue 28: the outside generator (tests/batteries/gen_bench.py)
imports nothing of the diagnosis, its kinds are split once, its records load."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from batteries import gen_bench

GEN = Path(gen_bench.__file__)


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
    return out


def test_generator_imports_no_diagnosis_code() -> None:
    mods = _imports(GEN)
    assert mods, "the generator's imports could not be read"
    assert not [m for m in mods if m.startswith("fsarm_sim.discrepancy")]
    # nor does anything it imports pull the diagnosis in
    code = (
        "import sys; sys.path.insert(0, 'tests');"
        "from batteries import gen_bench;"
        "gen_bench.make_record(gen_bench.KINDS[0], 3);"
        "bad = [m for m in sys.modules if m.startswith('fsarm_sim.discrepancy')];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    root = GEN.parent.parent.parent
    r = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


# round 2's held-out kinds, as the seeded split drew them before any diagnosis ran on them
HELDOUT_ROUND2 = {
    "backlash+coulomb_friction",
    "viscous_damping+sensor_offset",
    "delay+coulomb_friction+nonlinear_stiffness",
    "hysteresis+viscous_damping+delay",
    "emi_spikes",
    "emi_spikes+hysteresis",
    "gain_step",
    "gain_step+nonlinear_stiffness",
    "pwm_crosstalk",
    "pwm_crosstalk+coulomb_friction+nonlinear_stiffness",
    "table_knock",
    "table_knock+coulomb_friction+sensor_offset",
    "null_ar1_slow",
    "null_pink_short",
}


# round 3's held-out kinds, as the seeded split drew them (seed 3028) before any diagnosis ran
# on them; round 2's held-out kinds above have been evaluated and looked at: development now.
# Run once at the end of round 3's development (2 records per kind): strict 17/28, unexplained
# wrongly true 3/12, library effects for an outside cause 2/16, signature 14/16 (CHANGELOG).
HELDOUT_ROUND3 = {
    "backlash+sensor_offset",
    "hysteresis+nonlinear_stiffness",
    "backlash+coulomb_friction+delay",
    "nonlinear_stiffness+viscous_damping+sensor_offset",
    "belt_error",
    "belt_error+coulomb_friction",
    "stiffness_drift",
    "stiffness_drift+delay+sensor_offset",
    "stiction_burst",
    "stiction_burst+viscous_damping",
    "cable_tether",
    "cable_tether+coulomb_friction+delay",
    "null_lowpass_quantised",
    "null_pink_lowpass",
}


# round 4's held-out kinds, as the seeded split drew them (seed 4028) before any diagnosis ran
# on them; round 3's held-out kinds above have been evaluated and looked at: development now.
# Run once, with the diagnosis unchanged since round 3 (2 records per kind): strict 14/28,
# unexplained wrongly true 3/12, library effects for an outside cause 4/16, signature 8/16
# (round-4 development: 14/28, 4/12, 4/16, 12/16; CHANGELOG).
HELDOUT_ROUND4 = {
    "backlash+nonlinear_stiffness",
    "delay+viscous_damping",
    "hysteresis+nonlinear_stiffness+delay",
    "backlash+coulomb_friction+sensor_offset",
    "gain_temp_cycle",
    "gain_temp_cycle+viscous_damping",
    "encoder_interp_4x",
    "encoder_interp_4x+nonlinear_stiffness+sensor_offset",
    "thermostat_offset",
    "thermostat_offset+backlash+hysteresis",
    "pump_vibration",
    "pump_vibration+delay+nonlinear_stiffness",
    "null_ar2_hump30",
    "null_pink_short_quantised",
}


def test_round2_split_is_as_it_was() -> None:
    sp = gen_bench.split(2)
    assert set(sp) == {k.name for k in gen_bench.KINDS if k.round <= 2}
    assert {n for n, s in sp.items() if s == "heldout"} == HELDOUT_ROUND2
    r1 = gen_bench.split_round1()
    assert sum(s == "heldout" for s in r1.values()) == 18  # round 1's, as it was


def test_round3_split_is_as_it_was() -> None:
    sp = gen_bench.split(3)
    assert set(sp) == {k.name for k in gen_bench.KINDS if k.round <= 3}
    assert {n for n, s in sp.items() if s == "heldout"} == HELDOUT_ROUND3
    names = {r.kind.name for r in gen_bench.battery("heldout", 1, rounds=(3,), rnd=3)}
    assert names == HELDOUT_ROUND3


def test_split_is_fixed_and_covers_every_category() -> None:
    sp = gen_bench.split()
    assert sp == gen_bench.split()
    assert set(sp) == {k.name for k in gen_bench.KINDS}
    held_names = {n for n, s in sp.items() if s == "heldout"}
    assert held_names == HELDOUT_ROUND4
    last = gen_bench.LAST_ROUND
    # every kind seen before (rounds 1 to 3, both of their sets) is development now
    assert all(sp[k.name] == "dev" for k in gen_bench.KINDS if k.round < last)
    held = [k for k in gen_bench.KINDS if sp[k.name] == "heldout"]
    for cat in ("library_multi", "outside", "outside_plus", "null"):
        assert {sp[k.name] for k in gen_bench.KINDS if k.category == cat and k.round == last} == {
            "dev",
            "heldout",
        }, cat
    assert {len(k.library) for k in held if k.category == "library_multi"} == {2, 3}
    assert {len(k.library) for k in held if k.category == "outside_plus"} == {1, 2}
    # no outside cause of the held-out set appears in development, of any round
    dev_causes = {k.outside for k in gen_bench.KINDS if sp[k.name] == "dev"}
    assert not dev_causes & {k.outside for k in held if k.outside}
    # nor does a held-out multi-effect set appear in development
    dev_sets = {frozenset(k.library) for k in gen_bench.KINDS if sp[k.name] == "dev"}
    assert not dev_sets & {frozenset(k.library) for k in held if k.category == "library_multi"}
    # every multi-effect set of the last round is new
    old_sets = {frozenset(k.library) for k in gen_bench.KINDS if k.round < last}
    assert not old_sets & {
        frozenset(k.library)
        for k in gen_bench.KINDS
        if k.round == last and k.category == "library_multi"
    }
    new_outside = [k for k in gen_bench.KINDS if k.category == "outside" and k.round == last]
    assert len(new_outside) >= 6
    earlier = set(gen_bench.OUTSIDE_ROUND1) | set(gen_bench.OUTSIDE_ROUND2)
    assert not {k.outside for k in new_outside} & (earlier | set(gen_bench.OUTSIDE_ROUND3))
    assert all(k.noise != "white" for k in held if k.category == "null")
    # the battery's held-out records are of held-out kinds only
    names = {r.kind.name for r in gen_bench.battery("heldout", 1, rounds=(last,))}
    assert names == HELDOUT_ROUND4


@pytest.mark.parametrize(
    "kind",
    [
        "stiffness_drift",
        "clock_drift",
        "logger_dropouts",
        "cable_tether",
        "belt_error",
        "gain_temp_cycle",
        "encoder_interp_4x",
        "mount_expansion",
        "intermittent_contact",
        "magnet_pickup",
        "thermostat_offset",
        "excitation_ripple",
        "pump_vibration",
    ],
)
def test_later_causes_are_well_above_the_noise(kind: str) -> None:
    """Each new outside cause moves tau_s (against the stated shaft's torque of the recorded
    angle) by at least twice the noise in RMS; a null by the noise only."""
    from fsarm_sim.records.measured import stated_shaft

    sh = stated_shaft(gen_bench.DIAMETER_MM, gen_bench.LENGTH_MM)
    sigma = gen_bench.NOISE * 2 * 0.8 * float(sh.rating_nm)

    def excess(name: str) -> float:
        rec = gen_bench.make_record(next(k for k in gen_bench.KINDS if k.name == name), 3)
        th = rec.columns["theta_m"]
        nom = np.where(th >= 0, float(sh.k_pos) * th, float(sh.k_neg) * th)
        return float(np.std(rec.columns["tau_s"] - nom)) / sigma

    assert excess(kind) > 2.0
    assert excess("null_pink_lowpass") == pytest.approx(1.0, abs=0.1)


@pytest.mark.parametrize("kind", ["null_pink", "mesh_ripple", "backlash+delay+sensor_offset"])
def test_records_load_in_the_measured_format(kind: str, tmp_path: Path) -> None:
    from fsarm_sim.records.measured import load_dataset

    k = next(k for k in gen_bench.KINDS if k.name == kind)
    rec = gen_bench.make_record(k, 3)  # index 3: a short record
    ds = load_dataset(gen_bench.write_record(rec, tmp_path))
    assert ds.setup == "series_bench"
    assert rec.truth["duration_s"] == gen_bench.SHORT_S
    tau = rec.columns["tau_s"]
    assert np.all(np.isfinite(tau)) and float(np.ptp(tau)) > 0


# ----------------------------------------------------------------------------- realness


def test_an_effect_that_holds_across_segments_passes_and_a_stand_in_does_not() -> None:
    from fsarm_sim.discrepancy import realness as Real

    rng = np.random.default_rng(1)
    n = 20000
    t = np.arange(n) * 1e-3
    u = np.sin(2 * np.pi * (0.2 + 0.1 * t) * t)
    v = np.gradient(u, t)
    sigma = 0.01
    use = np.ones(n, dtype=bool)
    c = 0.05 * np.sign(v)  # a friction's contribution, the same size everywhere
    noise = sigma * rng.standard_normal(n)
    y_wo = np.zeros(n)
    ok = Real.check(
        "coulomb_friction", "shaft", {"f_c_nm": 0.05}, c + noise, c, y_wo, t, use, sigma
    )
    assert ok.passed, ok.reasons
    assert all(abs(s["scale"] - 1.0) < 0.1 for s in ok.segments)
    # the cause grows over the record (a drift); the friction's best average fit stands in
    cause = 0.1 * (t / t[-1]) * np.sign(v)
    fit = 0.05 * np.sign(v)
    bad = Real.check(
        "coulomb_friction", "shaft", {"f_c_nm": 0.05}, cause + noise, fit, y_wo, t, use, sigma
    )
    assert not bad.passed
    assert any("size in" in r for r in bad.reasons)


def test_parameters_at_a_bound_or_outside_the_range_are_named() -> None:
    from fsarm_sim.discrepancy.realness import params_at_bounds

    assert params_at_bounds("delay", "input", {"delay_s": 0.01}) == []
    assert params_at_bounds("delay", "input", {"delay_s": 0.1})  # the fit's upper bound
    assert params_at_bounds("coulomb_friction", "shaft", {"f_c_nm": 0.0})  # absent
    assert params_at_bounds("backlash", "coupling", {"width_rad": 0.9, "center_rad": 0.0})


# ----------------------------------------------------------------------------- residual search


def _sig(residual: np.ndarray, t: np.ndarray, angle: np.ndarray, sigma: float) -> dict:
    from fsarm_sim.discrepancy.unexplained import Signals, characterise

    y = 15.0 * angle
    return characterise(
        Signals(
            channel="tau_s",
            unit="N·m",
            t=t,
            residual=residual,
            output=y,
            sigma=sigma,
            inputs=[angle],
            signals={
                "twist": angle,
                "twist rate": np.gradient(angle, t),
                "input acceleration": np.gradient(np.gradient(angle, t), t),
                "model output": y,
            },
            angles={"theta_m": (angle, ["twist"])},
        )
    )


@pytest.fixture(scope="module")
def bench_like() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(30000) * 1e-3
    f = 0.1 + 2.9 * t / t[-1]
    ang = 0.45 * np.sin(2 * np.pi * np.cumsum(f) * 1e-3) / (1 + 0.3 * f)
    return t, ang


def test_coloured_noise_is_not_structure(bench_like: tuple) -> None:
    from scipy.signal import lfilter

    t, ang = bench_like
    sigma = 0.01
    hits = 0
    for seed in range(6):
        rng = np.random.default_rng(seed)
        e = lfilter([1.0], [1.0, -0.9], rng.standard_normal(t.size))
        sig = _sig(sigma * e / e.std(), t, ang, sigma * 0.3)  # white floor 0.3 x the total
        hits += bool(sig["structured"])
    assert hits <= 1


def test_the_search_names_a_period_in_an_angle_a_resonance_and_a_saturation(
    bench_like: tuple,
) -> None:
    from scipy.signal import lfilter

    t, ang = bench_like
    rng = np.random.default_rng(3)
    sigma = 0.01
    noise = sigma * rng.standard_normal(t.size)
    per = 2 * np.pi / 40
    sig = _sig(0.04 * np.sin(2 * np.pi * ang / per) + noise, t, ang, sigma)
    top = sig["findings"][0]
    assert sig["structured"] and top["kind"] == "angle_periodic"
    assert top["period_rad"] == pytest.approx(per, rel=0.02) and top["signal"] == "theta_m"
    w, zeta, h = 2 * np.pi * 33.0, 0.03, 1e-3
    r = np.exp(-zeta * w * h)
    z = lfilter([1.0], [1.0, -2 * r * np.cos(w * h), r * r], rng.standard_normal(t.size))
    sig = _sig(0.04 * z / z.std() + noise, t, ang, sigma)
    top = sig["findings"][0]
    assert top["kind"] == "resonance" and top["frequency_hz"] == pytest.approx(33.0, rel=0.03)
    y = 15.0 * ang
    lim = 0.8 * np.abs(y).max()
    sig = _sig(np.clip(y, -lim, lim) - y + noise, t, ang, sigma)
    assert sig["findings"][0]["kind"] == "saturation"


# ----------------------------------------------------------------------------- one record each


def _diagnose(rec: gen_bench.Record, tmp_path: Path) -> dict:
    from fsarm_sim.discrepancy import diagnose_record
    from fsarm_sim.discrepancy.report import result_dict
    from fsarm_sim.records.measured import load_dataset

    return result_dict(diagnose_record(load_dataset(gen_bench.write_record(rec, tmp_path))))


def test_a_friction_that_grows_over_the_record_is_a_stand_in_not_named(tmp_path: Path) -> None:
    """Coulomb friction whose level rises 19-fold over the record (grease warming: outside the
    library, whose friction is constant): a constant friction shrinks the gap on average, but its
    size disagrees between the record's parts - reported as a stand-in, the rest unexplained."""
    rec = gen_bench.make_record(next(k for k in gen_bench.KINDS if k.name == "null_white"), 3)
    t, th = rec.columns["t"], rec.columns["theta_m"]
    v = np.gradient(th, t)
    f = 0.04 * float(np.ptp(rec.columns["tau_s"])) * (0.1 + 1.8 * t / t[-1])
    rec.columns["tau_s"] = rec.columns["tau_s"] + f * np.tanh(v / (0.02 * np.abs(v).max()))
    res = _diagnose(rec, tmp_path)
    assert res["named_effects"] == []
    assert [s["effect"] for s in res["stand_ins"]] == ["coulomb_friction"]
    assert any("size in" in w for w in res["stand_ins"][0]["why_not_named"])
    assert res["unexplained"] is True and "stand-in not named" in res["verdict"]


def test_a_pink_noise_null_is_not_unexplained(tmp_path: Path) -> None:
    """1/f noise lifts the residual above the white-noise floor; no structure: not unexplained."""
    rec = gen_bench.make_record(next(k for k in gen_bench.KINDS if k.name == "null_pink"), 3)
    res = _diagnose(rec, tmp_path)
    assert res["named_effects"] == [] and res["stand_ins"] == []
    assert res["residual_over_noise"]["final"] > 1.3  # above the old sqrt 2 test's reach
    assert res["unexplained"] is False


def test_the_noise_floor_is_not_raised_by_a_narrow_line() -> None:
    """A 300 Hz line (a vibration aliased by the sampling) passes the 4th differences nearly
    whole: with ``lines=True`` it is cut and the floor is the noise's; without lines the two
    estimates are the same."""
    from fsarm_sim.discrepancy.residuals import noise_floor

    rng = np.random.default_rng(5)
    t = np.arange(20000) * 1e-3
    e = 0.04 * rng.standard_normal(t.size)
    y = 3.0 * np.sin(2 * np.pi * 0.3 * t) + e
    assert noise_floor(y, lines=True) == noise_floor(y)
    y_line = y + 0.2 * np.sin(2 * np.pi * 300.0 * t)
    assert noise_floor(y_line) > 2.0 * 0.04
    assert noise_floor(y_line, lines=True) == pytest.approx(0.04, rel=0.1)


def test_a_slowly_wandering_offset_is_found_and_1_over_f_noise_is_not(bench_like: tuple) -> None:
    from fsarm_sim.discrepancy.residual_search import Signals, slow_offset

    t, ang = bench_like

    def run(r: np.ndarray) -> dict:
        sig = Signals("tau_s", "N·m", t, r, 15.0 * ang, 1.0, [ang])
        return slow_offset(sig)

    n = t.size
    cycle = 4.0 * np.sqrt(2.0) * np.sin(2 * np.pi * t / 20.0 + 0.4)  # 4 x the noise RMS
    assert run(cycle + np.random.default_rng(0).standard_normal(n))["significant"]
    for seed in range(5):
        f = np.fft.rfftfreq(n, 1e-3)
        rng = np.random.default_rng(seed)
        spec = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / np.sqrt(
            np.maximum(f, 0.05)
        )
        pink = np.fft.irfft(spec, n)
        assert not run(pink / pink.std())["significant"]


def test_sizes_that_drift_across_the_parts_fail_jointly() -> None:
    """Each part's size within the per-part tolerance (0.7 ... 1.3 x the whole record's), but
    drifting steadily well beyond their intervals: a stand-in (the joint test)."""
    from fsarm_sim.discrepancy import realness as Real

    rng = np.random.default_rng(2)
    n = 20000
    t = np.arange(n) * 1e-3
    c = 0.05 * np.sign(np.sin(2 * np.pi * 0.7 * t))
    g = np.repeat([0.7, 0.9, 1.1, 1.3], n // 4)
    use = np.ones(n, dtype=bool)
    y = g * c + 0.005 * rng.standard_normal(n)
    segs, reasons = Real.segment_agreement(y, c, np.zeros(n), t, use, 0.005)
    assert all(abs(s["scale"] - 1.0) < Real.REL_TOL for s in segs)
    assert any("differs between the record's parts" in r for r in reasons)
    _, ok = Real.segment_agreement(
        c + 0.005 * rng.standard_normal(n), c, np.zeros(n), t, use, 0.005
    )
    assert ok == [], ok


def test_a_bound_is_waived_only_for_a_parameter_at_it() -> None:
    """With nothing unexplained, a parameter at its range's end is no stand-in; one beyond the
    range or at zero (absent) still fails."""
    from fsarm_sim.discrepancy import realness as Real

    at = Real.params_at_bounds("backlash", "coupling", {"width_rad": 0.5, "center_rad": 0.0})
    c = Real.EffectCheck("backlash", "coupling", False, [f"parameter {b}" for b in at], [], at)
    assert at and Real.bound_waived(c).passed
    zero = Real.params_at_bounds("coulomb_friction", "shaft", {"f_c_nm": 0.0})
    c = Real.EffectCheck("coulomb_friction", "shaft", False, [f"parameter {b}" for b in zero])
    assert not Real.bound_waived(c).passed


# ----------------------------------------------------------------------------- re-test


def _retest_case(outside: float, calls: list[str] | None = None) -> tuple[bool, list[str], str]:
    """The re-test on a stand-in setup: a backlash named, a Coulomb friction of 2 noise RMS
    left out, and ``outside`` x the noise RMS of a 50 Hz line no library effect takes up."""
    from types import SimpleNamespace as NS

    from fsarm_sim.discrepancy import selection
    from fsarm_sim.discrepancy.retest import retest

    rng = np.random.default_rng(4)
    n, sigma = 6000, 0.01
    t = np.arange(n) * 1e-3
    b = 0.3 * np.sin(2 * np.pi * 0.9 * t)  # what the named effect explains
    c = 2 * sigma * np.sign(np.cos(2 * np.pi * 0.9 * t))
    y = b + c + outside * sigma * np.sqrt(2) * np.sin(2 * np.pi * 50.0 * t)
    y = y + sigma * rng.standard_normal(n)
    teach, held = (t % 1.0) < 0.5, (t % 1.0) >= 0.5

    def fit(yhat: np.ndarray, effect: str | None, k: int) -> NS:
        r = y - yhat
        return NS(
            yhat=yhat,
            mse_teach=float(np.mean(r[teach] ** 2)),
            mse_held=float(np.mean(r[held] ** 2)),
            k=k,
            label=f"{effect}[shaft]",
            effect=effect,
            variant="shaft",
            note="",
            model=NS(effect=lambda e, v: NS(params={"f_c_nm": 0.02})),
        )

    cur = fit(b, "backlash", 3)

    class Stub:
        noise_var, mse_name, look_alikes = sigma**2, "MSE", selection.LOOK_ALIKES

        def candidates(self, cur_: NS, named: list[str]) -> list[NS]:
            return (
                [] if "coulomb_friction" in named else [fit(cur_.yhat + c, "coulomb_friction", 4)]
            )

        def cost(self, f: NS) -> tuple[float, float, int]:
            return f.mse_teach, f.mse_held, f.k

        def residual(self, f: NS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            return y - f.yhat, teach, held

        def gap(self, f: NS) -> float:
            return 0.0

        def effect_params(self, f: NS) -> dict:
            return {"f_c_nm": 0.02}

        def accept(self, f: NS) -> NS:
            return f

        def finish(self, f: NS, named: list[str]) -> NS:
            if calls is not None:
                calls.append("finish")
            return f

        def conclude(self, nom: NS, final: NS, named: list[str]) -> tuple[str, dict]:
            if calls is not None:
                calls.append("conclude")
            return "v", {"unexplained": bool(final.mse_held > 2 * sigma**2)}

    ctx = NS(inp=NS(inertia_load=False, y=y, t=t), teach=teach, held=held, sigma_y=sigma)
    diag = NS(
        named=["backlash"],
        extras={"unexplained": True},
        final=cur,
        nominal=fit(0 * y, None, 2),
        steps=[],
    )
    done = retest(Stub(), ctx, diag, 4)  # type: ignore[arg-type]
    return done, diag.named, diag.steps[-1].reason if diag.steps else ""


def test_the_retest_names_a_lost_effect_that_explains_what_is_left() -> None:
    done, named, why = _retest_case(0.0)
    assert done and named == ["backlash", "coulomb_friction"], why


def test_the_retest_keeps_the_model_and_verdict_that_resolved_it() -> None:
    """The final model and verdict of the effect that left nothing unexplained are the
    diagnosis's: not refit and judged a second time."""
    calls: list[str] = []
    done, named, _ = _retest_case(0.0, calls)
    assert done and named == ["backlash", "coulomb_friction"]
    assert calls == ["finish", "conclude"]


def test_the_retest_names_nothing_when_the_rest_stays_unexplained() -> None:
    done, named, why = _retest_case(3.0)
    assert not done and named == ["backlash"]
    assert "stays unexplained" in why


def test_slowly_correlated_noise_is_not_localised_and_a_burst_is(bench_like: tuple) -> None:
    """AR(1) noise with a 200 ms correlation time on a 10 s record: its 0.25 s windows' energies
    scatter far beyond white noise's (the robust z alone flags 4 of these 40 records), but no
    more than phase-randomised copies of it; a 1 s burst of 3 noise RMS on white noise stands
    out of both."""
    from scipy.signal import lfilter

    from fsarm_sim.discrepancy.residual_search import Signals, localisation

    t = np.arange(10000) * 1e-3
    ang = bench_like[1][: t.size]
    hits = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        e = lfilter([1.0], [1.0, -0.995], rng.standard_normal(t.size))
        r = e / e.std() + 0.5 * rng.standard_normal(t.size)
        hits += localisation(Signals("tau_s", "N·m", t, r, 15.0 * ang, 0.5, [ang]), 0.25)[
            "significant"
        ]
    assert hits <= 1
    rng = np.random.default_rng(9)
    r = rng.standard_normal(t.size) + 3.0 * ((t > 4.0) & (t < 5.0)) * rng.standard_normal(t.size)
    found = localisation(Signals("tau_s", "N·m", t, r, 15.0 * ang, 1.0, [ang]), 0.25)
    assert found["significant"] and 3 <= found["windows"] <= 5
