"""The bad-input battery (``tests/bad_input_battery.py``, issue 33): every case across the
commands, the library, files, overwrites, faults, encodings, special files and names ends as
expected - a named error or a correct run; no traceback, silent wrong answer, refused valid
input, hang or lost work. (``python tests/bad_input_battery.py`` prints every case.)"""

from __future__ import annotations

from pathlib import Path

import bad_input_battery as battery


def test_battery_has_only_named_errors_and_correct_runs(tmp_path: Path) -> None:
    results = battery.run_battery(tmp_path)
    counts = battery.counts(results)
    bad = [
        f"{r.outcome}: {r.case.category} / {r.case.name}: {r.detail}"
        for r in results
        if r.outcome not in ("named error", "correct run")
    ]
    assert not bad, "\n".join(bad)
    assert len(counts) >= 10  # every category ran (all + 10 categories)
    assert counts["all"]["named error"] >= 100 and counts["all"]["correct run"] >= 10


def test_battery_classifies_what_goes_wrong(tmp_path: Path) -> None:
    """The battery can fail: accepted nonsense, a refused valid input, a traceback and a lost
    file are each seen as such."""

    def boom(t: Path) -> None:
        raise KeyError("not a named error")

    def clobber(t: Path) -> tuple[int, str, str]:
        (t / "m.csv").write_text("gone\n")
        return 2, "", "error: pretended refusal\n"

    cases = [
        battery.Case("x", "nonsense accepted", args=["scenarios"]),
        battery.Case("x", "valid refused", args=["run", "nope"], expect="ok"),
        battery.Case("x", "traceback", call=boom),
        battery.Case("x", "lost", call=clobber),
        battery.Case("x", "wrong words", args=["run", "nope"], words="something else"),
    ]
    got = [battery.run_case(c, tmp_path).outcome for c in cases]
    assert got == ["silent wrong", "refused valid", "traceback", "lost work", "silent wrong"]
