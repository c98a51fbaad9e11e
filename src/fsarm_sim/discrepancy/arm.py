"""The discrepancy workflow on the arm: replay a recorded run closed loop, name what is missing.

The arm is a :class:`~.setup_protocol.Setup` (:class:`ArmSetup`): the replay, the nominal refit and
the candidates' fits are :mod:`.arm_fit`'s (the run simulated by the project's simulator with the
recorded references and the run's controller; candidates linearised, solved jointly with the present
parameters and re-simulated, the most promising refined on the simulation itself); the choice is the
diagnosis core's (:func:`.core.diagnose`). Output: :mod:`.report` (the arm's parts:
:meth:`ArmSetup.report`, plots, print-out), model file :mod:`.arm_modelfile`.

**Ranking** - the rules of :mod:`.selection`: an effect earns its place when the BIC falls by
more than ``BIC_THRESHOLD`` on the teaching *and* the held-out blocks
(:func:`.residuals.split_masks`), the held-out MSE falls by ``MIN_GAIN`` and the explained part
exceeds ``MIN_EXPLAINED`` of the noise variance (an extra effect: the stricter limits of
:mod:`.selection`); one effect at a time while each earns its place, "nothing missing" when none
does; the held-out BIC margin to the runner-up effect is the confidence, look-alike pairs
flagged. With several channels the MSE is the weighted one::

    W = (1/3) sum_c MSE_c / sigma_c^2        (1 = every channel at its noise floor)
    BIC = n_eff ln(W) + k ln(n_eff)          (seed 003 Table 4's form, :func:`.residuals.bic`)

with ``n_eff`` from the autocorrelation of the weighted residual of all channels end to end
(:func:`.residuals.effective_n`); it is the Gaussian likelihood with the channels' variances
known up to one common factor, the same objective the fits minimise.
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
    arm_expert,
    arm_joint,
    arm_modelfile,
    core,
    replay_inputs,
    variants,
)
from fsarm_sim.discrepancy import arm_slip as slip
from fsarm_sim.discrepancy.arm_fit import (
    BASIS,
    MAIN,
    MODEL_FORMAT,
    MODEL_VERSION,
    ArmContext,
    ArmFit,
    make_context,
    nominal_keys,
    refine,
)
from fsarm_sim.discrepancy.arm_model import (
    BOUNDS,
    RAW,
    ArmModel,
    apply_measurement,
    simulate_config,
    to_basis,
    to_config,
)
from fsarm_sim.discrepancy.arm_run import (
    ArmReplayError,
    ArmRun,
    ArmSidecarError,
    arm_run,
    parse_gains,
    reference_table,
    stated_transmission,
)
from fsarm_sim.discrepancy.arm_screen import (
    MEASUREMENT_CANDIDATES,
    PLANT_CANDIDATES,
    nominal_fit,
    step_candidates,
)
from fsarm_sim.discrepancy.fit_label import labelled_as
from fsarm_sim.discrepancy.report import plot_channel_nrmse
from fsarm_sim.discrepancy.residuals import nrmse, signature
from fsarm_sim.discrepancy.selection import LOOK_ALIKES, Judgement, Score
from fsarm_sim.discrepancy.selection import judge as judge_rule
from fsarm_sim.discrepancy.uncertainty import interval_lines
from fsarm_sim.discrepancy.unexplained import plot as plot_signature
from fsarm_sim.records.measured import Dataset

__all__ = [
    "ARM_LOOK_ALIKES",
    "BASIS",
    "BOUNDS",
    "MAIN",
    "MAX_EFFECTS",
    "MEASUREMENT_CANDIDATES",
    "MODEL_FORMAT",
    "MODEL_VERSION",
    "PLANT_CANDIDATES",
    "RAW",
    "ArmContext",
    "ArmDiagnosis",
    "ArmFit",
    "ArmModel",
    "ArmReplayError",
    "ArmRun",
    "ArmSetup",
    "ArmSidecarError",
    "apply_measurement",
    "arm_run",
    "diagnose_arm",
    "make_context",
    "parse_gains",
    "reference_table",
    "residual_signature",
    "simulate_config",
    "stated_transmission",
    "to_basis",
    "to_config",
]

MAX_EFFECTS = 3
CHANNELS = ("q3", "theta_m", "q2", "twist")  # the report's channels
# the core's joint search of pairs / triples (issue 16), with the restart from the nominal model
# and the final pruning (``restart``): the arm's pairs are fitted together from the start
# (:meth:`ArmSetup.joint_pairs`, :mod:`.arm_joint`). Without it the greedy selection named both
# effects of 16/21 pairs of scripts/discrepancy_battery_arm_expert.py: where two effects hide
# each other (payload error + Coulomb friction: the nominal refit runs to a wrong stiffness and
# K_b, no single candidate earns its place) it named nothing. Runtime: see the README's rate
# table (8 s records, measured by that script).
JOINT_SEARCH = True
WITHIN_NOISE = 1.15  # residual (noise-floor units, channel average) "within noise"
ARM_LOOK_ALIKES = (
    *LOOK_ALIKES,
    frozenset({variants.BACKLASH, variants.OFFSET}),  # one-sided twist: a play is a twist offset
    frozenset({variants.PAYLOAD, variants.OFFSET}),
    frozenset({variants.PAYLOAD, variants.BACKLASH}),
    # a slip element that never slips offsets the twist
    frozenset({variants.BACKLASH, variants.HYSTERESIS}),
)

ArmDiagnosis = core.Diagnosis  # an arm diagnosis is the core's (fits: ArmFit)


def _weighted_cell(sc: Score) -> str:
    return f"{sc.mse_held:.4g}"


class ArmSetup:
    """An ``arm`` record as a :class:`.setup_protocol.Setup` (fits: :class:`.arm_fit.ArmFit`)."""

    main_channel = MAIN
    mse_name = "weighted MSE"
    noise_var = 1.0  # the weighted MSE is in noise-variance units
    look_alikes = ARM_LOOK_ALIKES
    score_cell = ("held-out W", _weighted_cell)
    load_hint = (
        "load the final model: "
        "fsarm_sim.discrepancy.arm_modelfile.load_arm_config(MODEL) -> SimConfig"
    )

    def __init__(self, ds: Dataset) -> None:
        self.dataset = ds
        self.run = arm_run(ds)
        self.ctx = make_context(ds, self.run)
        self._nominal: ArmFit | None = None  # the refit nominal model (the extra-effect rule)
        self.slip_added: list[slip.Added] = []  # elements finish() added (:mod:`.arm_slip`)
        self.offset_moved = ""  # the encoder offset finish() moved to the other encoder, if any

    # ------------------------------------------------------------------ selection

    def nominal(self) -> tuple[ArmFit, ArmFit]:
        cat, nom = nominal_fit(self.ctx)
        self._nominal = nom
        return cat, nom

    def candidates(self, cur: ArmFit, named: Sequence[str]) -> list[ArmFit]:
        return step_candidates(self.ctx, cur, named)

    def cost(self, fit: ArmFit) -> tuple[float, float, int]:
        return fit.w(self.ctx, False), fit.w(self.ctx), fit.k

    def residual(self, fit: ArmFit) -> tuple[core.FloatArray, core.BoolArray, core.BoolArray]:
        ctx = self.ctx
        r = np.concatenate([(ctx.y[c] - fit.pred[c]) / ctx.sigma[c] for c in BASIS])
        return r, np.tile(ctx.teach, len(BASIS)), np.tile(ctx.held, len(BASIS))

    def gap(self, fit: ArmFit) -> float:
        return nrmse(self.ctx.y[MAIN], fit.pred[MAIN], self.ctx.held)

    def effect_params(self, fit: ArmFit) -> dict[str, Any]:
        effs = {e.label: e for e in fit.model.effects()}
        eff = effs.get(fit.label) or effs.get(f"{fit.effect}[{fit.variant}]")
        return dict(eff.params) if eff is not None else {}

    def joint_pairs(
        self, cur: ArmFit, named: Sequence[str]
    ) -> list[tuple[list[tuple[str, str]], ArmFit]]:
        """Pairs fitted together from the start (:func:`.arm_joint.pair_candidates`; the
        core's joint search, optional in the protocol)."""
        return arm_joint.pair_candidates(self.ctx, cur, named)

    def swap_variants(self, fit: ArmFit) -> tuple[ArmFit, dict[str, str]]:
        """:func:`.arm_joint.swap_variants` (the core's pruning, optional in the protocol)."""
        return arm_joint.swap_variants(self.ctx, fit)

    def holds(self, fit: ArmFit, effect: str) -> bool:
        """Does ``fit``'s model still hold ``effect``? (The core's pruning.)"""
        return any(lab.startswith(effect + "[") for lab in fit.model.labels)

    def without(self, fit: ArmFit, effect: str) -> ArmFit | None:
        """``fit``'s model without ``effect``, the rest refit on the simulation (the core's
        pruning); None when it does not hold the effect."""
        return arm_joint.without(self.ctx, fit, effect)

    def accept(self, fit: ArmFit) -> ArmFit:
        return fit

    def finish(self, fit: ArmFit, named: Sequence[str]) -> ArmFit:
        """The final model: with hysteresis named, slip elements added while one more earns its
        place by the rule of an extra effect (:func:`.arm_slip.grow`), and an encoder offset
        beside it tried on the other encoder with the elements grown again."""
        nom = self._nominal
        self.slip_added = []
        self.offset_moved = ""
        if variants.HYSTERESIS not in named or nom is None:
            return fit

        def judge(cur: ArmFit, cand: ArmFit) -> Judgement:
            n_t, n_h = core.common_n_eff(self, [cur, cand])
            return judge_rule(
                self.cost(cur), self.cost(cand), n_t, n_h, self.noise_var, self.cost(nom)[1]
            )

        out, self.slip_added = slip.grow(self.ctx, fit, judge)
        # an encoder offset beside hysteresis: both bias the twist, and the offset's channel is
        # easily the wrong one (.arm_joint.twist_equivalent); the other channel's offset with
        # the elements grown again is kept when it fits the teaching and held-out blocks better
        for alt in arm_joint.twist_equivalent(self.ctx, out):
            grown, added = slip.grow(self.ctx, refine(self.ctx, alt), judge)
            if grown.cost < out.cost and grown.w(self.ctx) < out.w(self.ctx):
                self.offset_moved = f"{alt.effect}[{alt.variant}]"
                out, self.slip_added = labelled_as(grown, fit), added
        return out

    def conclude(
        self, nominal: ArmFit, final: ArmFit, named: Sequence[str]
    ) -> tuple[str, dict[str, Any]]:
        ctx = self.ctx
        gap_b, gap_a = self.gap(nominal), self.gap(final)
        noise_units = math.sqrt(final.w(ctx))
        unexp = arm_expert.unexplained(ctx, final)
        sig = arm_expert.signature(ctx, final)
        if not named and not unexp:
            verdict = (
                "nothing is missing within noise: the refit nominal model leaves a held-out "
                f"residual of {noise_units:.3g} x the noise floor (channel average); no "
                "candidate earns its place"
            )
        elif not named:
            verdict = (
                "no library effect earns its place, but the refit nominal model leaves "
                f"{noise_units:.2g} x the noise floor (channel average): something outside the "
                "library or the recorded inputs' own errors"
            )
        else:
            verdict = (
                f"missing: {', '.join(named)}; held-out NRMSE of q3 {100 * gap_b:.3g} % -> "
                f"{100 * gap_a:.3g} %"
                + (
                    "; the rest is within noise"
                    if noise_units <= WITHIN_NOISE
                    else f"; residual {noise_units:.2g} x the noise floor remains (channel average)"
                )
            )
        if unexp:
            verdict += f"; what remains: {sig['summary']}"
        if self.offset_moved:
            verdict += (
                f"; the encoder offset is {self.offset_moved} (its twist-equivalent on the other "
                "encoder, with the hysteresis refit, fits better)"
            )
        if self.slip_added:
            verdict += "; " + "; ".join(a.text() for a in self.slip_added)
        extras: dict[str, Any] = {
            "simulations": ctx.n_sims,
            "reference": self.run.ref_note,
            "slip_elements_added": [dataclasses.asdict(a) for a in self.slip_added],
            "offset_moved_to": self.offset_moved,
            "unexplained": unexp,
            "residual_signature": sig,
            "confidence_intervals": arm_expert.intervals(ctx, final),
        }
        extras["simulations"] = ctx.n_sims  # the intervals' runs included
        return verdict, extras

    # ------------------------------------------------------------------ report

    def parameters(self, model: ArmModel) -> dict[str, Any]:
        return {"nominal": model.nominal(), "effects": [e.as_dict() for e in model.effects()]}

    def save_model(self, model: ArmModel, path: Path) -> Path:
        return arm_modelfile.save_arm_model(self.run, model, path)

    def report(self, diag: core.Diagnosis[ArmFit]) -> core.ReportParts:
        ctx = self.ctx
        ds = self.dataset
        return core.ReportParts(
            head={
                "setup": "arm",
                "scenario": ds.sidecar.get("scenario"),
                "samples": ds.n,
                "rate_hz": 1.0 / ctx.run.h,
                "duration_s": float(ctx.run.t[-1]),
                "main_channel": MAIN,
                "transmission": ctx.run.transmission,
            },
            gaps={
                "gap_catalogue": self.gap(diag.catalogue),
                "gap_over_noise": {
                    "catalogue": diag.gap_over_noise(diag.catalogue),
                    "before": diag.gap_over_noise(diag.nominal),
                    "after": diag.gap_over_noise(diag.final),
                },
            },
            nominal_refit={
                "refit_parameters": nominal_keys(ctx),
                "catalogue": diag.catalogue.model.nominal(),
                "refit": diag.nominal.model.nominal(),
                "final": diag.final.model.nominal(),
            },
            noise_floor=dict(ctx.sigma),
            nrmse=channel_nrmse(diag),
            signatures={
                when: {ch: residual_signature(diag, fit, ch) for ch in ("q3", "twist")}
                for when, fit in (("before", diag.nominal), ("after", diag.final))
            },
            method={
                "replay": "closed loop: the project's simulator (native callbacks) with the "
                "recorded references and the run's controller (stated shaft and payload)",
                "channels": "q3, twist = theta_m - i_G2 q3, q2; residuals weighted by each "
                "channel's noise floor",
                "bic": "n_eff ln(W) + k ln(n_eff), W = channel-mean of MSE_c / sigma_c^2, n_eff "
                "from the weighted residual's autocorrelation time",
            },
            tail={
                "simulations": diag.extras.get("simulations"),
                "reference": diag.extras.get("reference"),
                # hysteresis elements the final step added (.arm_slip), with their BIC changes
                "slip_elements_added": diag.extras.get("slip_elements_added", []),
                "offset_moved_to": diag.extras.get("offset_moved_to") or None,
            },
        )

    def plots(self, diag: core.Diagnosis[ArmFit], folder: Path) -> list[Path]:
        return write_plots(diag, folder)

    def summary_lines(self, diag: core.Diagnosis[ArmFit]) -> list[str]:
        return [
            f"nominal refit alone: {diag.nominal.model.nominal()}",
            f"final nominal parameters: {diag.final.model.nominal()}",
            f"named effects: {diag.named or 'none'}",
            *(f"  {e.label}: {e.params}" for e in diag.final.model.effects()),
            f"held-out NRMSE of q3: nominal {100 * diag.gap_before:.4f} % -> final "
            f"{100 * diag.gap_after:.4f} %; residual / noise floor "
            f"{diag.gap_over_noise(diag.nominal):.3g} -> {diag.gap_over_noise(diag.final):.3g}",
            diag.verdict,
            *interval_lines(diag.extras.get("confidence_intervals")),
            *self.dataset.column_notes(),
            f"runtime {diag.runtime_s:.1f} s ({diag.extras.get('simulations')} closed-loop runs)",
        ]


def diagnose_arm(ds: Dataset, *, max_effects: int = MAX_EFFECTS) -> core.Diagnosis[ArmFit]:
    """Replay an arm record closed loop, refit the nominal model, name and fit what is missing."""
    t0 = time.perf_counter()
    return core.diagnose(
        ArmSetup(ds), max_effects, started=t0, joint=JOINT_SEARCH, restart=JOINT_SEARCH
    )


def residual_signature(
    diag: core.Diagnosis[ArmFit], fit: ArmFit, channel: str = MAIN
) -> dict[str, Any]:
    """Residual signatures of one channel against joint-3 speed, the twist and the bend."""
    ctx = diag.ctx
    h = ctx.run.h
    q3 = replay_inputs.smooth(ctx.y["q3"], h)
    twist = replay_inputs.smooth(ctx.y["twist"], h)
    return signature(
        ctx.y[channel],
        fit.pred[channel],
        twist,
        replay_inputs.derivative(q3, h),
        ctx.y["q2"],
        ctx.run.t,
        ctx.sigma[channel],
    ).as_dict()


def _channel(ctx: ArmContext, fit: ArmFit, ch: str) -> tuple[core.FloatArray, core.FloatArray]:
    if ch in RAW:
        return ctx.raw[ch], fit.raw[ch]
    return ctx.y[ch], fit.pred[ch]


def channel_nrmse(diag: core.Diagnosis[ArmFit]) -> dict[str, dict[str, float]]:
    """Held-out NRMSE per channel (q3, theta_m, q2, twist): catalogue / nominal / final."""
    out: dict[str, dict[str, float]] = {}
    for ch in CHANNELS:
        out[ch] = {}
        for name, fit in (
            ("catalogue", diag.catalogue),
            ("nominal", diag.nominal),
            ("final", diag.final),
        ):
            y, yhat = _channel(diag.ctx, fit, ch)
            out[ch][name] = nrmse(y, yhat, diag.ctx.held)
    return out


def write_plots(diag: core.Diagnosis[ArmFit], folder: str | Path) -> list[Path]:
    """Time series before/after (held-out window), twist-q3 loops, NRMSE per channel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    ctx = diag.ctx
    t = ctx.run.t
    files: list[Path] = []
    idx = np.flatnonzero(ctx.held)
    i0 = int(idx[0]) if idx.size else 0
    i1 = min(t.size, i0 + round(4.0 / ctx.run.h))
    sl = slice(i0, i1)
    nom, fin = diag.nominal, diag.final

    fig, ax = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    ax[0].plot(t[sl], ctx.y["q3"][sl], color="k", lw=1, label="q3 measured")
    ax[0].plot(t[sl], ctx.ds.columns["q3_ref"][sl], color="grey", lw=0.8, ls=":", label="q3_ref")
    ax[0].set_ylabel("q3 [rad]")
    ax[0].set_title(f"{ctx.ds.path.name}: held-out window")
    ax[0].legend(loc="upper right", fontsize=8)
    for a, ch, unit in ((ax[1], "q3", "rad"), (ax[2], "twist", "rad"), (ax[3], "q2", "rad")):
        a.plot(t[sl], (ctx.y[ch] - nom.pred[ch])[sl], color="tab:red", lw=0.8, label="before")
        a.plot(t[sl], (ctx.y[ch] - fin.pred[ch])[sl], color="tab:blue", lw=0.8, label="after")
        for k in (-2, 2):
            a.axhline(k * ctx.sigma[ch], color="grey", ls=":", lw=0.8)
        a.set_ylabel(f"{ch} residual [{unit}]")
        a.legend(loc="upper right", fontsize=8)
    ax[3].set_xlabel("t [s]")
    fig.tight_layout()
    files.append(out / "timeseries.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    step = max(1, t.size // 8000)
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    for a, fit, title in ((axs[0], nom, "before (nominal refit)"), (axs[1], fin, "after")):
        a.plot(
            ctx.y["q3"][::step], ctx.y["twist"][::step], ".", ms=1.5, color="k", label="measured"
        )
        a.plot(
            fit.pred["q3"][::step],
            fit.pred["twist"][::step],
            ".",
            ms=1.5,
            color="tab:blue" if fit is fin else "tab:red",
            label="replay",
        )
        a.set_title(title)
        a.set_xlabel("q3 [rad]")
        a.legend(loc="upper left", fontsize=8, markerscale=6)
    axs[0].set_ylabel("shaft twist theta_m - i_G2 q3 [rad] (~ shaft torque / K)")
    fig.tight_layout()
    files.append(out / "loops.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    sig = diag.extras.get("residual_signature")
    if sig is not None:  # what the final model leaves, on the channel highest above its noise
        s = arm_expert.signal_set(ctx, fin, str(sig["channel"]))
        files.append(plot_signature(sig, s, out / "residual_signature.png"))

    files.append(plot_channel_nrmse(channel_nrmse(diag), out / "nrmse.png", log=True))
    return files
