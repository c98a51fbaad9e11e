"""The series and parallel benches as a :class:`.setup_protocol.Setup`: the record replayed by the
Numba engine (:mod:`.replay`), grey-box candidates fitted inside it (:mod:`.candidates`).

Setups ``series_bench`` (blocked output: a replay of the input's history; inertia load: the load
simulated in segments from its measured state) and ``parallel_bench``. The cost is the MSE of the
main output channel (``tau_s`` / ``m_b``), the noise variance that of its white noise (from the
data). With an inertia load every candidate is screened with a short output-error refinement and
the step's leader is redone in full; a hysteresis effect, once named, has its elements moved off
the candidates' fixed grid (:func:`.candidates.refine_elements`); the final model's nonlinear
parameters are refined jointly (:func:`.candidates.refine`). The verdict names the noise floor
and the output error the recorded inputs' own errors cause (:mod:`.input_errors`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from fsarm_sim.discrepancy import (
    candidate_inertia,
    candidate_structure,
    candidates,
    core,
    realness,
    replay,
    replay_inputs,
    retest,
    selection,
    variants,
)
from fsarm_sim.discrepancy.bench_output import channel_nrmse, residual_signature, write_plots
from fsarm_sim.discrepancy.bench_verdict import replay_error_floor, unexplained, verdict
from fsarm_sim.discrepancy.benchmodel import BenchModel, save_model, stated_model
from fsarm_sim.discrepancy.core import UnsupportedSetupError
from fsarm_sim.discrepancy.input_errors import input_error_floor
from fsarm_sim.discrepancy.residuals import (
    gap_excess,
    noise_floor,
    nrmse,
    nrmse_floor,
)
from fsarm_sim.discrepancy.selection import Score
from fsarm_sim.discrepancy.uncertainty import interval_lines, intervals
from fsarm_sim.discrepancy.unexplained import Signals, characterise
from fsarm_sim.plant.effects import registry
from fsarm_sim.records.measured import Dataset

SETUPS = (registry.SERIES, registry.PARALLEL)


class BenchDiagnosis(core.Diagnosis[candidate_structure.Fit]):
    """A bench diagnosis, with its noise floors in held-out NRMSE units."""

    @property
    def sigma_inputs(self) -> float:
        """The output error caused by the recorded inputs' own errors (RMS, output units)."""
        return float(self.extras.get("sigma_inputs", 0.0))

    @property
    def noise_floor_nrmse(self) -> float:
        """The estimated noise floor in held-out NRMSE units (a perfect model's gap)."""
        return nrmse_floor(self.ctx.inp.y, self.ctx.sigma_y, self.ctx.held)

    @property
    def noise_floor_inputs_nrmse(self) -> float:
        """The output error the recorded inputs' own errors cause, held-out NRMSE units."""
        return nrmse_floor(self.ctx.inp.y, self.sigma_inputs, self.ctx.held)

    @property
    def noise_floor_total_nrmse(self) -> float:
        """Output noise and propagated input errors together (they add in variance)."""
        return math.hypot(self.noise_floor_nrmse, self.noise_floor_inputs_nrmse)

    @property
    def gap_excess_before(self) -> float:
        """Held-out gap of the nominal model above the noise floor."""
        return gap_excess(self.gap_before, self.noise_floor_nrmse)

    @property
    def gap_excess_after(self) -> float:
        """Held-out gap of the final model above the noise floor."""
        return gap_excess(self.gap_after, self.noise_floor_nrmse)


def _structure_key(st: candidate_structure.Structure) -> tuple[Any, ...]:
    """A structure's terms and settings as a hashable key (arrays by their bytes)."""
    return tuple(
        (f.name, v.tobytes() if isinstance(v, np.ndarray) else v)
        for f in dataclasses.fields(st)
        for v in (getattr(st, f.name),)
    )


def _nrmse_cell(sc: Score) -> str:
    return f"{100 * sc.nrmse_held:.3f}"


class BenchSetup:
    """A bench record as a :class:`.setup_protocol.Setup` (fits:
    :class:`.candidate_structure.Fit`)."""

    mse_name = "MSE"
    look_alikes = selection.LOOK_ALIKES
    score_cell = ("held-out NRMSE %", _nrmse_cell)
    load_hint = (
        "load the final model: fsarm_sim.discrepancy.benchmodel.load_model(MODEL) -> BenchModel"
    )

    def __init__(self, ds: Dataset) -> None:
        if ds.setup not in SETUPS:
            raise UnsupportedSetupError(
                f"this diagnose handles the bench setups ({', '.join(SETUPS)}); for "
                f"'{ds.setup}' use fsarm_sim.discrepancy.arm.diagnose_arm (`fsarm diagnose` picks "
                "the right one)"
            )
        self.dataset = ds
        self.ctx = candidate_structure.make_context(
            replay_inputs.prepare_inputs(ds), stated_model(ds)
        )
        self.main_channel = ds.output_column
        self.noise_var = self.ctx.sigma_y**2
        self.pairs = registry.applicable(ds.setup, self.ctx.inp.inertia_load)
        # each candidate's fit on top of a structure, once: the joint search, the restart and
        # the re-test extend the same structures again (the fit depends on nothing else)
        self._fits: dict[tuple[Any, ...], candidate_structure.Fit | None] = {}

    # ------------------------------------------------------------------ selection

    def nominal(self) -> tuple[candidate_structure.Fit, candidate_structure.Fit]:
        return candidates.stated(self.ctx), candidates.nominal(self.ctx)

    def candidates(
        self, cur: candidate_structure.Fit, named: Sequence[str]
    ) -> list[candidate_structure.Fit]:
        ctx = self.ctx
        inertia = ctx.inp.inertia_load
        if inertia:  # screen with a short output-error refinement, redo the leader
            ctx.options["oe_nfev"] = candidate_inertia.OE_NFEV_SCREEN
        fits = [self._candidate(cur, e, v) for e, v in self.pairs if e not in named]
        ctx.options.pop("oe_nfev", None)
        good = [f for f in fits if f is not None and math.isfinite(f.mse_held)]
        if inertia and good:
            i_lead = min(range(len(good)), key=lambda i: good[i].mse_held)
            lead = good[i_lead]
            redo = candidate_inertia.solve(ctx, lead.structure)
            redo.label, redo.effect, redo.variant = lead.label, lead.effect, lead.variant
            if redo.mse_teach <= lead.mse_teach:
                good[i_lead] = redo
        return good

    def _candidate(
        self, cur: candidate_structure.Fit, effect: str, variant: str
    ) -> candidate_structure.Fit | None:
        """:func:`.candidates.candidate`, fitted once per structure (a blocked series or a
        parallel bench; an inertia load's screening fits depend on the options too): a copy of
        the fit, whose label and effect the caller may set."""
        if self.ctx.inp.inertia_load:
            return candidates.candidate(self.ctx, cur, effect, variant)
        key = (_structure_key(cur.structure), effect, variant)
        if key not in self._fits:
            self._fits[key] = candidates.candidate(self.ctx, cur, effect, variant)
        fit = self._fits[key]
        return None if fit is None else dataclasses.replace(fit)

    def cost(self, fit: candidate_structure.Fit) -> tuple[float, float, int]:
        return fit.mse_teach, fit.mse_held, fit.k

    def residual(
        self, fit: candidate_structure.Fit
    ) -> tuple[
        candidate_structure.FloatArray, candidate_structure.BoolArray, candidate_structure.BoolArray
    ]:
        return self.ctx.inp.y - fit.yhat, self.ctx.teach, self.ctx.held

    def gap(self, fit: candidate_structure.Fit) -> float:
        return nrmse(self.ctx.inp.y, fit.yhat, self.ctx.held)

    def effect_params(self, fit: candidate_structure.Fit) -> dict[str, Any]:
        eff = fit.model.effect(fit.effect or "", fit.variant)
        return dict(eff.params) if eff is not None else {}

    def accept(self, fit: candidate_structure.Fit) -> candidate_structure.Fit:
        # hysteresis elements were fitted on a fixed grid: move them off it before the next
        # step, so that the grid's approximation error is not left for another effect
        out = (
            candidates.refine_elements(self.ctx, fit) if fit.effect == variants.HYSTERESIS else fit
        )
        # the nonlinear settings of the effects named before, searched again with this one in
        return candidates.backfit(self.ctx, out, fit.effect)

    def swap_variants(
        self, fit: candidate_structure.Fit
    ) -> tuple[candidate_structure.Fit, dict[str, str]]:
        """:func:`.candidates.swap_variants` (the core's pruning, optional in the protocol; an
        inertia load's fits are output-error fits: kept as they are)."""
        if self.ctx.inp.inertia_load:
            return fit, {}
        return candidates.swap_variants(self.ctx, fit, list(self.pairs), self.look_alikes)

    def holds(self, fit: candidate_structure.Fit, effect: str) -> bool:
        """Does ``fit``'s structure still hold ``effect`` (hysteresis elements can all be
        pruned when later effects are fitted)? (The core's pruning, optional in the protocol.)"""
        return any(e == effect for e, _ in candidates.present(fit.structure))

    def without(self, fit: candidate_structure.Fit, effect: str) -> candidate_structure.Fit | None:
        """:func:`.candidates.without` (the core's pruning, optional in the protocol; None on
        an inertia load)."""
        if self.ctx.inp.inertia_load:
            return None
        return candidates.without(self.ctx, fit, effect)

    def finish(self, fit: candidate_structure.Fit, named: Sequence[str]) -> candidate_structure.Fit:
        return candidates.refine(self.ctx, fit) if named else fit

    def conclude(
        self, nominal: candidate_structure.Fit, final: candidate_structure.Fit, named: Sequence[str]
    ) -> tuple[str, dict[str, Any]]:
        sigma_in = input_error_floor(self.dataset, self.ctx, final.model)
        half = replay_inputs.prepare_inputs(self.dataset, window_scale=0.5)
        sigma_rep = replay_error_floor(self.ctx, final, half)
        sigma_all = math.hypot(sigma_in, sigma_rep)
        extras: dict[str, Any] = {"sigma_inputs": sigma_in, "sigma_replay": sigma_rep}
        sig = characterise(self.signal_set(final))
        extras["unexplained"] = unexplained(self.ctx, final, sigma_all, sig)
        extras["residual_signature"] = sig
        extras["confidence_intervals"] = intervals(
            final.model,
            self.ctx.inp,
            self.ctx.teach,
            final.yhat,
            self.ctx.multi_bend,
            half=half,
        )
        text = verdict(self.ctx, nominal, final, named, sigma_all, extras["unexplained"])
        if extras["unexplained"]:
            text += f"; what remains: {sig['summary']}"
        return text, extras

    def signal_set(self, fit: candidate_structure.Fit) -> Signals:
        """The main channel's residual (warm-up excluded) and the signals it may depend on."""
        inp = self.ctx.inp
        use = self.ctx.teach | self.ctx.held
        s = inp.theta_s if inp.inertia_load and inp.theta_s is not None else inp.s
        x = inp.u - s
        xd = np.gradient(x, inp.h)
        cand = {
            "twist": x,
            "twist rate": xd,
            "direction": np.sign(xd) * (np.abs(xd) > 0.05 * float(np.std(xd))),
            "|twist|": np.abs(x),
            "input angle": inp.u,
            "bend": inp.phi,
            "input acceleration": inp.uacc,
            "model output": fit.yhat,
        }
        signals: dict[str, candidate_structure.FloatArray] = {}
        for name, v in cand.items():
            v = np.asarray(v, dtype=np.float64)[use]
            if any(v.shape == w.shape and np.allclose(v, w) for w in signals.values()):
                continue  # the same signal by another name (e.g. the blocked bench's twist)
            signals[name] = v
        angles: dict[str, tuple[candidate_structure.FloatArray, list[str]]] = {}
        cand_angles = {self.dataset.input_column: inp.u, "twist": x}
        if inp.inertia_load and inp.theta_s is not None:
            cand_angles["theta_s"] = inp.theta_s
        if self.dataset.input_column != "phi_b":
            cand_angles["bend"] = inp.phi
        for name, v in cand_angles.items():
            v = np.asarray(v, dtype=np.float64)[use]
            if float(np.ptp(v)) <= 1e-9:
                continue
            same = next(
                (k for k, (w, _) in angles.items() if np.allclose(v - v[0], w - w[0], atol=1e-12)),
                None,
            )
            if same is not None:  # the same angle up to a constant (blocked: twist = theta_m)
                angles[same][1].append(name)
                continue
            angles[name] = (v, [])
        return Signals(
            channel=self.main_channel,
            unit="N·m",
            t=inp.t[use],
            residual=(inp.y - fit.yhat)[use],
            output=fit.yhat[use],
            sigma=self.ctx.sigma_y,
            inputs=[inp.u[use]],
            signals=signals,
            angles=angles,
        )

    # ------------------------------------------------------------------ report

    def parameters(self, model: BenchModel) -> dict[str, Any]:
        return {"nominal": dict(model.nominal), "effects": [e.as_dict() for e in model.effects]}

    def save_model(self, model: BenchModel, path: Path) -> Path:
        return save_model(model, path)

    def report(self, diag: core.Diagnosis[candidate_structure.Fit]) -> core.ReportParts:
        ctx = self.ctx
        inp = ctx.inp
        ds = self.dataset
        floors = diag if isinstance(diag, BenchDiagnosis) else _floors(diag)
        return core.ReportParts(
            head={
                "setup": ds.setup,
                "load": "inertia"
                if inp.inertia_load
                else ("blocked" if ds.setup == registry.SERIES else None),
                "samples": inp.n,
                "rate_hz": 1.0 / inp.h,
                "duration_s": float(inp.t[-1] - inp.t[0]),
                "main_channel": ds.output_column,
            },
            gaps={
                "noise_floor_nrmse": floors.noise_floor_nrmse,
                "noise_floor_inputs_nrmse": floors.noise_floor_inputs_nrmse,
                "noise_floor_total_nrmse": floors.noise_floor_total_nrmse,
                "gap_excess_before": floors.gap_excess_before,
                "gap_excess_after": floors.gap_excess_after,
                "residual_over_noise": {
                    "nominal": _over_noise(diag.nominal.mse_held, ctx.sigma_y),
                    "final": _over_noise(diag.final.mse_held, ctx.sigma_y),
                },
                "gap_catalogue": nrmse(inp.y, diag.catalogue.yhat, ctx.held),
            },
            nominal_refit={
                "catalogue": dict(diag.catalogue.model.nominal),
                "refit": dict(diag.nominal.model.nominal),
            },
            noise_floor={
                ds.output_column: ctx.sigma_y,
                f"{ds.input_column} (smoothed)": ctx.sigma_u,
                f"{ds.output_column} from the recorded inputs' errors (propagated)": (
                    floors.sigma_inputs
                ),
                f"{ds.output_column} from the replay's smoothing (filter windows halved)": float(
                    diag.extras.get("sigma_replay", 0.0)
                ),
                **(
                    {"theta_s": noise_floor(inp.theta_s)}
                    if inp.inertia_load and inp.theta_s is not None
                    else {}
                ),
            },
            nrmse=channel_nrmse(diag),
            signatures={
                "before": residual_signature(diag, diag.nominal),
                "after": residual_signature(diag, diag.final),
            },
            method={
                "bic": "n_eff ln(MSE) + k ln(n_eff), n_eff from the residual autocorrelation time",
                "noise_floor": "4th-difference MAD estimate of the main channel's white noise; "
                "noise_floor_nrmse = that / (max - min) of the channel on the held-out samples",
                "noise_floor_inputs": "the recorded angles re-measured (their encoder grid at a "
                "random phase, or their white noise) and the final model replayed on both: RMS "
                "output difference on the held-out samples",
                "inertia_load_replay": f"segments of {replay.SEGMENT_S:g} s started from the "
                "measured load state",
            },
        )

    def plots(self, diag: core.Diagnosis[candidate_structure.Fit], folder: Path) -> list[Path]:
        signal_set = diag.setup.signal_set if isinstance(diag.setup, BenchSetup) else None
        return write_plots(diag, folder, signal_set)

    def summary_lines(self, diag: core.Diagnosis[candidate_structure.Fit]) -> list[str]:
        ds = self.dataset
        return [
            f"named effects: {diag.named or 'none'}",
            f"held-out NRMSE of {ds.output_column}: nominal {100 * diag.gap_before:.3f} % -> "
            f"final {100 * diag.gap_after:.3f} %",
            diag.verdict,
            *interval_lines(diag.extras.get("confidence_intervals")),
            *ds.column_notes(),
            f"runtime {diag.runtime_s:.1f} s",
        ]


def _floors(diag: core.Diagnosis[candidate_structure.Fit]) -> BenchDiagnosis:
    """The diagnosis as a :class:`BenchDiagnosis` (for its noise floors)."""
    return BenchDiagnosis(**{f.name: getattr(diag, f.name) for f in dataclasses.fields(diag)})


def _over_noise(mse: float, sigma: float) -> float:
    return math.sqrt(mse) / sigma if sigma > 0 else math.inf


RETEST = True  # False: the selection without the re-test (for comparison)


def diagnose(ds: Dataset, *, max_effects: int = selection.MAX_EFFECTS) -> BenchDiagnosis:
    """Find, name and fit the effects missing from the nominal model of a bench dataset (with
    :data:`RETEST`, the effects not named tested again while something is unexplained:
    :mod:`.retest`); the named effects that do not hold (:func:`check_real`) are reported as
    stand-ins."""
    t0 = time.perf_counter()
    setup = BenchSetup(ds)
    # restart and pruning refit whole structures: not on an inertia load (output-error fits)
    restart = not setup.ctx.inp.inertia_load
    diag = core.diagnose(setup, max_effects, kind=BenchDiagnosis, started=t0, restart=restart)
    if RETEST:
        retest.retest(setup, setup.ctx, diag, max_effects)
    check_real(setup, diag)
    diag.runtime_s = time.perf_counter() - t0
    return diag


def check_real(setup: BenchSetup, diag: BenchDiagnosis) -> None:
    """The realness checks of :mod:`.realness` on every named effect (blocked series and
    parallel bench; an inertia load's fits are output-error fits, refit per effect too slowly:
    not checked, said in ``realness``). An effect that fails is not named: it goes to
    ``extras["stand_ins"]`` with why, the final model is refit without it and the verdict,
    ``unexplained`` and the residual signature are redone on that model."""
    ctx = setup.ctx
    if not diag.named:
        diag.extras.setdefault("stand_ins", [])
        return
    if ctx.inp.inertia_load:
        diag.extras["stand_ins"] = []
        diag.extras["realness"] = {"checked": False, "why": "inertia load (output-error fits)"}
        return
    final = diag.final
    use = ctx.teach | ctx.held
    # nothing left unexplained: an effect at a bound of its range stands in for nothing
    explained = not diag.extras.get("unexplained", True)
    checks: list[realness.EffectCheck] = []
    without: dict[str, candidate_structure.Fit] = {}
    for e, v in candidates.present(final.structure):
        if e not in diag.named:
            continue
        wo = candidate_inertia.solve(ctx, candidates.strip(final.structure, e))
        without[e] = wo
        eff = final.model.effect(e, v)
        params = dict(eff.params) if eff is not None else {}
        c = realness.check(
            e, v, params, ctx.inp.y, final.yhat, wo.yhat, ctx.inp.t, use, ctx.sigma_y
        )
        checks.append(realness.bound_waived(c) if explained else c)
    bad = [c for c in checks if not c.passed]
    stand: list[dict[str, Any]] = []
    if bad:
        st = final.structure
        for c in bad:
            st = candidates.strip(st, c.effect)
        named = [e for e in diag.named if e not in {c.effect for c in bad}]
        new = candidate_inertia.solve(ctx, st)
        new = setup.finish(new, named) if named else new
        new.label = "nominal + " + " + ".join(named) if named else diag.nominal.label
        new.effect = new.variant = None
        for c in bad:
            eff = final.model.effect(c.effect, c.variant)
            stand.append(
                {
                    "effect": c.effect,
                    "variant": c.variant,
                    "params": dict(eff.params) if eff is not None else {},
                    "gap_with_it": nrmse(ctx.inp.y, final.yhat, ctx.held),
                    "gap_without_it": nrmse(ctx.inp.y, without[c.effect].yhat, ctx.held),
                    "why_not_named": c.reasons,
                }
            )
        if not named:
            new = diag.nominal
        diag.final, diag.named = new, named
        diag.verdict, extras = setup.conclude(diag.nominal, new, named)
        diag.extras = extras
        names = ", ".join(c.effect for c in bad)
        diag.verdict += (
            f"; stand-in{'s' if len(bad) > 1 else ''} not named: {names} (shrink"
            f"{'' if len(bad) > 1 else 's'} the gap but do"
            f"{'' if len(bad) > 1 else 'es'} not hold across the record's parts or sit"
            f"{'' if len(bad) > 1 else 's'} at a bound: see stand_ins)"
        )
    diag.extras["stand_ins"] = stand
    diag.extras["realness"] = {"checked": True, "effects": [c.as_dict() for c in checks]}
