"""``fsarm reproduce``: the seed papers' claims checked on the simulator (issue 12).

Leads with the predictions (the claims nothing in the model was chosen from): per paper, how
many claims are predictions, calibrations and consistency checks, and the verdicts of the
predictions; then, per claim (predictions first), its role, where it is in the paper, the
paper's value, ours, the tolerance and the verdict. It is a report: exit code 0 whatever the verdicts,
2 on bad input, 1 when an experiment itself failed to run, 130 on Ctrl-C (the JSON report then
holds every finished claim).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from fsarm_sim.cli.console import make_console
from fsarm_sim.errors import FsarmError
from fsarm_sim.outputs import OutputPlan, SafeWriter

console = make_console()
err_console = make_console(stderr=True)

STYLE = {
    "reproduced": "green",
    "partly": "yellow",
    "contradicted": "bold red",
    "not_implemented": "cyan",
    "uncheckable": "magenta",
}


def parse_papers(values: list[str] | None) -> list[str]:
    """``--paper`` values -> the papers' ids (000..004), in the order given, without repeats."""
    from fsarm_sim.studies.reproduce.claims import PAPERS

    out: list[str] = []
    for v in values or []:
        key = v.strip()
        if key.isdigit() and len(key) <= 3:
            key = key.zfill(3)
        if key not in PAPERS:
            raise FsarmError(
                f"--paper must be one of {', '.join(PAPERS)} (a seed paper), got {v!r}"
            )
        if key not in out:
            out.append(key)
    return out


def _paper_table(paper: str, results: list[object]) -> Table:
    from fsarm_sim.studies.reproduce.claims import PAPERS, Result

    table = Table(title=f"seed {paper}: {PAPERS[paper]}", show_lines=False, expand=True)
    table.add_column("claim", ratio=4, overflow="fold")
    table.add_column("role", ratio=2, overflow="fold")
    table.add_column("where", ratio=2, overflow="fold")
    table.add_column("paper", ratio=3, overflow="fold")
    table.add_column("ours", ratio=4, overflow="fold")
    table.add_column("tolerance", ratio=3, overflow="fold")
    table.add_column("verdict", ratio=2)
    for r in results:
        assert isinstance(r, Result)
        c = r.claim
        ours = r.ours_text if r.verdict not in ("not_implemented", "uncheckable") else r.why
        style = STYLE[r.verdict]
        role = c.role if c.role != "calibration" else "calibration: " + ", ".join(c.calibrates)
        table.add_row(
            escape(c.id),
            escape(role),
            escape(c.locator),
            escape(c.paper_text),
            escape(ours),
            escape(c.tolerance.text(c.unit)),
            f"[{style}]{r.verdict}[/]",
        )
    return table


CAUSE_MARK = "Where ours departs:"


def _causes(results: list[object]) -> list[str]:
    """One line per contradicted prediction: its id and the cause its note names (the part from
    "Where ours departs:" on, else the whole note)."""
    from fsarm_sim.studies.reproduce.claims import Result

    lines = []
    for r in results:
        assert isinstance(r, Result)
        if r.claim.role != "prediction" or r.verdict != "contradicted":
            continue
        note = r.note.strip()
        cause = note[note.index(CAUSE_MARK) + len(CAUSE_MARK) :] if CAUSE_MARK in note else note
        lines.append(f"{r.claim.id}: {cause.strip() or 'no cause named'}")
    return lines


def _prediction_table(summary: dict[str, dict[str, Any]]) -> Table:
    """The headline: per paper the roles' counts and the predictions' verdicts."""
    from fsarm_sim.studies.reproduce.claims import VERDICTS

    table = Table(title="fsarm reproduce: predictions by paper (the evidence)")
    table.add_column("paper")
    for role in ("calibration", "prediction", "consistency"):
        table.add_column(role, justify="right")
    for v in VERDICTS:
        table.add_column(f"[{STYLE[v]}]prediction {v}[/]", justify="right")
    table.add_column("post-hoc (not evidence)", justify="right")
    for paper, entry in summary.items():
        pred = entry["prediction"]
        late = entry.get("post_hoc", {})
        table.add_row(
            paper,
            *(str(entry["roles"][r]) for r in ("calibration", "prediction", "consistency")),
            *(str(pred[v]) for v in VERDICTS),
            ", ".join(f"{n} {v}" for v, n in late.items() if v != "total" and n) or "-",
            end_section=paper == list(summary)[-2] if len(summary) > 1 else False,
        )
    return table


def _support_table(summary: dict[str, dict[str, Any]]) -> Table:
    """Calibrations and consistency checks: do the fits and transcriptions hold (not evidence)."""
    from fsarm_sim.studies.reproduce.claims import VERDICTS

    table = Table(
        title="calibration and consistency claims (not evidence: the model was made from them)"
    )
    table.add_column("paper")
    table.add_column("role")
    for v in VERDICTS:
        table.add_column(f"[{STYLE[v]}]{v}[/]", justify="right")
    for paper, entry in summary.items():
        for role in ("calibration", "consistency"):
            row = entry[role]
            table.add_row(paper, role, *(str(row[v]) for v in VERDICTS))
    return table


def _print_bands(
    n: int, results: list[Any], quick: bool, path: Path | None, writes: SafeWriter
) -> None:
    """The --uncertainty hook: bands of the judged claims (a report beside the verdicts)."""
    from fsarm_sim.outputs import write_text
    from fsarm_sim.studies import reproduce_bands

    err_console.print(f"sampling the coefficient ranges ({n} samples) for the bands ...")
    data = reproduce_bands.claim_bands(results, n, quick=quick)
    table = Table(
        title=f"5-95 % bands over the coefficient ranges ({n} samples; not used by any verdict)"
    )
    for col in ("claim", "paper", "unit", "ours", "5 %", "50 %", "95 %"):
        table.add_column(col, justify="left" if col in ("claim", "paper") else "right")
    for cid, entry in data["claims"].items():
        ours = entry["ours"] if isinstance(entry["ours"], list) else [entry["ours"]]
        for i, (value, b) in enumerate(zip(ours, entry["band"], strict=True)):
            table.add_row(
                escape(cid if i == 0 else ""),
                escape(entry["paper_text"] if i == 0 else ""),
                escape(entry["unit"]),
                f"{value:.4g}",
                *(f"{b[k]:.4g}" for k in ("p05", "p50", "p95")),
            )
    console.print(table)
    console.print(
        f"{len(data['claims'])} claims banded ({data.get('failed', 0)} samples failed, "
        f"{data.get('wall_s', 0.0):.1f} s); {len(data['not_banded'])} measured claims have no "
        "band (not a simulation of the arm's shaft)",
        markup=False,
    )
    if path is not None:
        import json

        text = json.dumps(data, indent=2, ensure_ascii=False)
        if writes.write(path, lambda p_: write_text(p_, text + "\n"), "the bands") is not None:
            console.print(f"bands: {path}", markup=False)


# the options of `reproduce_cmd`
ReproducePaper = Annotated[
    list[str] | None,
    typer.Option(
        "--paper",
        help="only this seed paper: 000, 001, 002, 003 or 004 (repeatable; default all)",
    ),
]
ReproduceJson = Annotated[
    Path | None,
    typer.Option("--json", help="write the report here (rewritten as each claim finishes)"),
]
ReproduceQuick = Annotated[
    bool, typer.Option(help="a subset with shorter experiments (well under a minute)")
]
ReproduceUncertainty = Annotated[
    int,
    typer.Option(
        help="also sample the coefficient file's [uncertainty] ranges N times and show "
        "the 5-95 % band beside the paper value of each claim simulated on the arm "
        "(never used by a verdict; --json: also <name>.uncertainty.json); 0: off"
    ),
]


def _on_result(json_file: Path | None) -> Callable[[Any, Any], None]:
    """Per finished claim: a progress line, and the --json report rewritten (a failed write
    warns once; the final write rescues the report)."""
    from fsarm_sim.studies.reproduce import runner

    write_failed = [False]

    def on_result(rep: runner.Report, res: Any) -> None:
        err_console.print(
            f"[{len(rep.results)}/{rep.planned}] {escape(res.claim.id)}: "
            f"[{STYLE[res.verdict]}]{res.verdict}[/] ({res.seconds:.1f} s)",
            highlight=False,
        )
        if json_file is not None and not write_failed[0]:
            try:
                runner.write_json(json_file, rep)
            except OSError as exc:  # keep running; the final write rescues the report
                write_failed[0] = True
                err_console.print(
                    f"warning: cannot write {json_file} ({exc}); the report is written at the end",
                    markup=False,
                )

    return on_result


def _headline(report: Any, summary: dict[str, dict[str, Any]]) -> str:
    """The last line of the report: the predictions' verdicts and the calibrations' share."""
    from fsarm_sim.studies.reproduce.runner import checkable

    pred = summary["all"]["prediction"]
    late = summary["all"].get("post_hoc", {"total": 0})
    cal = checkable(summary["all"], "calibration")
    fitted_or_predicted = checkable(summary["all"], "calibration", "prediction", "post_hoc")
    every = checkable(summary["all"], "calibration", "prediction", "post_hoc", "consistency")
    total = f"{len(report.results)} of {report.planned} claims in {report.elapsed_s:.1f} s"
    return (
        f"{total}{' (quick)' if report.quick else ''}: blind predictions reproduced "
        f"{pred['reproduced']} of {pred['total']} ({pred['partly']} partly, "
        f"{pred['contradicted']} contradicted, {pred['not_implemented']} not implemented, "
        f"{pred['uncheckable']} uncheckable); {late['total']} post-hoc prediction(s) not "
        f"counted; calibration {cal} of {every} checkable claims "
        f"({100 * cal / max(every, 1):.0f} %), {cal} of {fitted_or_predicted} without the "
        f"consistency checks ({100 * cal / max(fitted_or_predicted, 1):.0f} %)"
    )


def _print_report(report: Any) -> None:
    """The tables: predictions by paper, per paper its claims, the contradicted predictions'
    causes, calibrations and consistency checks, and the headline."""
    from fsarm_sim.studies.reproduce.runner import by_paper

    grouped = by_paper(report.results)
    summary = report.summary()
    console.print(_prediction_table(summary))
    for p in report.papers:
        if p in grouped:
            console.print(_paper_table(p, list(grouped[p])))
    causes = _causes(list(report.results))
    if causes:
        console.print("contradicted predictions and their causes:", markup=False)
        for line in causes:
            console.print(f"- {line}", markup=False)
    console.print(_support_table(summary))
    console.print(_headline(report, summary), markup=False)


def _exit_code(report: Any) -> None:
    """Ctrl-C: 130; an experiment that failed to run: 1 (after naming them); else 0."""
    if report.interrupted:
        raise typer.Exit(130)
    if report.failed:
        err_console.print(
            f"[bold red]{len(report.failed)} experiment(s) failed to run[/]: "
            + escape(", ".join(report.failed))
        )
        raise typer.Exit(1)


def reproduce_cmd(
    paper: ReproducePaper = None,
    json_file: ReproduceJson = None,
    quick: ReproduceQuick = False,
    uncertainty: ReproduceUncertainty = 0,
) -> None:
    """Check the seed papers' claims on the simulator with the papers' own procedures.

    Leads with the predictions (claims nothing in the model was chosen from): per paper the
    counts of predictions, calibrations and consistency checks, and the predictions'
    verdicts. Per claim: its role, where it is in the paper, the paper's value, ours, the
    tolerance and a verdict (reproduced, partly, contradicted, not_implemented,
    uncheckable). Calibration and consistency claims never count as reproduced. Exit code 0 whatever the verdicts (it is a report), 1 if an experiment
    failed to run, 2 on bad input, 130 on Ctrl-C (--json keeps every finished claim).
    """
    from fsarm_sim.studies.reproduce import runner
    from fsarm_sim.studies.reproduce.claims import Context

    papers = parse_papers(paper)
    bands_file = None
    if uncertainty:
        from fsarm_sim.studies.uncertainty import check_samples

        check_samples(uncertainty)
        if json_file is not None:
            bands_file = json_file.with_name(json_file.stem + ".uncertainty.json")
    OutputPlan().file("--json", json_file).file("the bands", bands_file).check()
    claims, report = runner.start(papers, quick)
    writes = SafeWriter(lambda msg: err_console.print(f"warning: {msg}", markup=False))
    runner.run(claims, Context(quick=quick, backend="native"), report, _on_result(json_file))
    _print_report(report)
    if json_file is not None:
        where = writes.write(
            json_file, lambda p_: runner.write_json(p_, report), "the report (--json)"
        )
        if where is not None:
            console.print(f"report: {where}", markup=False)
    if uncertainty and not report.interrupted:
        _print_bands(uncertainty, report.results, quick, bands_file, writes)
    if report.interrupted:
        err_console.print(
            "[bold yellow]interrupted[/]: the report holds the claims finished so far"
        )
    writes.finish()
    _exit_code(report)


def register(app: typer.Typer) -> None:
    app.command("reproduce")(reproduce_cmd)
