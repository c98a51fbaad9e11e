"""A bad-input battery across the ``fsarm`` commands and the library (issue 33).

Each case is a command line (run in this process, as ``tests/conftest.py:run_fsarm`` does), a
library call, or - only where a process of its own is needed (standard output on ``/dev/full``,
a deleted working directory) - a shell command. Every case says what it expects: a named error
(exit code 2, one line ``error: ...``) or a correct run (exit code 0, and a check of what it
wrote). Its outcome is one of:

* ``named error``  - refused with one named line, as expected;
* ``correct run``  - ran and wrote what it should, as expected;
* ``traceback``    - an exception other than a named one reached the user;
* ``silent wrong`` - nonsense accepted (exit 0 where a refusal was due) or a run whose output
  fails its check;
* ``refused valid``- a named error where a correct run was due;
* ``hang``         - still running after :data:`HANG_S` seconds;
* ``lost work``    - a file that existed before was changed or removed, or a file the case must
  leave behind is missing.

``python tests/bad_input_battery.py`` prints every case and the counts per category and
outcome; ``tests/test_bad_input_battery.py`` runs it and asserts that only the two expected
outcomes occur.
"""

from __future__ import annotations

import contextlib
import errno
import io
import json
import math
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from conftest import FailingStdout

HANG_S = 30.0
RESCUE = "fsarm-rescue-"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "data"
LONG = "n" * 300  # longer than the 255 bytes a file name may have
DEEP = 5000  # nesting depth of the deep files (beyond Python's recursion limit)
OUTCOMES = (
    "named error",
    "correct run",
    "traceback",
    "silent wrong",
    "refused valid",
    "hang",
    "lost work",
)
Check = Callable[[Path], str | None]  # what a case left behind: None when right, else why not


@dataclass
class Case:
    category: str
    name: str
    args: list[str] | None = None  # an `fsarm` command line; {t} = the case's folder
    call: Callable[[Path], Any] | None = None  # or a library call (or a command under a fault)
    shell: str | None = None  # or a shell command; {fsarm} = the installed command
    expect: str = "error"  # "error" or "ok"
    words: str = ""  # what the error line must contain ({t} expanded)
    check: Check | None = None  # what must exist afterwards (both kinds)
    may_change: tuple[str, ...] = ()  # files of the setup the case may rewrite


@dataclass
class Result:
    case: Case
    outcome: str
    detail: str
    seconds: float


# ------------------------------------------------------------------------------------ setup


def setup(t: Path) -> None:
    """The files every case may use (each case gets its own fresh copy)."""
    shutil.copy(EXAMPLES / "series_null.csv", t / "m.csv")
    shutil.copy(EXAMPLES / "series_null.json", t / "m.json")
    for name in ("loop", "lt.csv", "ls.toml"):
        (t / name).symlink_to(name)
    shutil.copy(EXAMPLES / "series_null.csv", t / "ls.csv")
    (t / "ls.json").symlink_to("ls.json")  # a sidecar that is a loop
    head, *rows = (EXAMPLES / "series_null.csv").read_text().splitlines()[:200]
    i = head.split(",").index("tau_s")
    (t / "dup.csv").write_text(
        "\n".join(
            [head + ",tau_s"] + [f"{r},{2 * float(r.split(',')[i])}" for r in rows]
        )  # tau_s twice, the second twice the first
        + "\n"
    )
    shutil.copy(EXAMPLES / "series_null.json", t / "dup.json")
    shutil.copy(EXAMPLES / "series_null.csv", t / "deep.csv")
    (t / "deep.json").write_text('{"setup": "series_bench", "x": ' + "[" * DEEP + "]" * DEEP + "}")
    shutil.copy(EXAMPLES / "series_null.csv", t / "list.csv")
    (t / "list.json").write_text("[1, 2]\n")
    (t / "empty.csv").write_text("")
    shutil.copy(EXAMPLES / "series_null.json", t / "empty.json")
    (t / "head.csv").write_text("t,theta_m,theta_s,phi_b,tau_s\n")
    shutil.copy(EXAMPLES / "series_null.json", t / "head.json")
    (t / "bin.csv").write_bytes(bytes(range(256)) * 40)
    shutil.copy(EXAMPLES / "series_null.json", t / "bin.json")
    (t / "deep.toml").write_text("x = " + "[" * DEEP + "]" * DEEP + "\n")
    (t / "bad.toml").write_text("this is = = not toml\n")
    (t / "deepspec.toml").write_text("[grid]\ndiameter_mm = " + "[" * DEEP + "]" * DEEP + "\n")
    (t / "spec.toml").write_text("[grid]\ndiameter_mm = [9]\n")
    (t / "model.json").write_text('{"setup": ' + "[" * DEEP + "]" * DEEP + "}")
    tt = np.arange(0.0, 2.0, 0.001)
    (t / "in.csv").write_text(
        "t,theta_m\n" + "\n".join(f"{a:.6g},{0.01 * math.sin(a):.6g}" for a in tt) + "\n"
    )
    (t / "indup.csv").write_text("t,theta_m,t\n" + "0,0,0\n" * 20)
    (t / "afile").write_text("a file, not a folder\n")
    (t / "adir").mkdir()
    db = sqlite3.connect(t / "foreign.db")
    db.execute("CREATE TABLE customers (name TEXT)")
    db.commit()
    db.close()


def tidy_rescue(path: Path) -> None:
    """Remove the rescue folder ``path`` is (or lies in) - only a folder named
    ``fsarm-rescue-*`` directly in the temporary directory, never anything else."""
    tmp = Path(tempfile.gettempdir()).resolve()
    for p in (path, path.parent):
        if p.name.startswith(RESCUE) and p.parent.resolve() == tmp and p.is_dir():
            shutil.rmtree(p)
            return


def _snapshot(t: Path) -> dict[str, bytes]:
    out = {}
    for p in sorted(t.rglob("*")):
        with contextlib.suppress(OSError):
            if p.is_file() and not p.is_symlink():
                out[str(p.relative_to(t))] = p.read_bytes()
    return out


# ------------------------------------------------------------------------------------ running


class _Hang(BaseException):
    """Raised by the alarm: the case ran past HANG_S."""


@contextlib.contextmanager
def _alarm(seconds: float) -> Iterator[None]:
    def ring(signum: int, frame: object) -> None:
        raise _Hang

    old = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def fsarm(*args: str) -> tuple[int, str, str]:
    """``fsarm ARGS`` in this process: (exit code, stdout, stderr); exceptions propagate."""
    from fsarm_sim import cli

    out, err = io.StringIO(), io.StringIO()
    saved = sys.argv
    sys.argv = ["fsarm", *args]
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                cli.main()
                code = 0
            except SystemExit as exc:
                code = int(exc.code or 0) if not isinstance(exc.code, str) else 1
    finally:
        sys.argv = saved
    return code, out.getvalue(), err.getvalue()


def _sub(t: Path, command: str) -> tuple[int, str, str]:
    exe = Path(sys.executable).with_name("fsarm")
    done = subprocess.run(
        ["sh", "-c", command.format(fsarm=exe, t=t)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        env={**os.environ, "MUJOCO_GL": "disable"},
    )
    return done.returncode, done.stdout, done.stderr


def run_case(case: Case, root: Path) -> Result:
    t = root / case.name.replace(" ", "_").replace("/", "_")
    t.mkdir()
    setup(t)
    before = _snapshot(t)
    start = time.perf_counter()
    outcome, detail = _outcome(case, t)
    took = time.perf_counter() - start
    if outcome in ("named error", "correct run"):
        after = _snapshot(t)
        changed = [k for k, v in before.items() if after.get(k) != v and k not in case.may_change]
        missing = case.check(t) if case.check is not None else None
        if changed:
            outcome, detail = "lost work", f"changed or removed: {changed}"
        elif missing is not None:
            outcome, detail = ("lost work" if case.expect == "error" else "silent wrong"), missing
    return Result(case, outcome, detail, took)


def _outcome(case: Case, t: Path) -> tuple[str, str]:
    from fsarm_sim.errors import FsarmError

    try:
        with _alarm(HANG_S):
            if case.call is not None:
                got = case.call(t)
                if isinstance(got, tuple) and len(got) == 3 and isinstance(got[0], int):
                    code, out, err = got  # a command run under a fault
                else:
                    return (
                        ("correct run", "returned")
                        if case.expect == "ok"
                        else ("silent wrong", f"accepted, returned {type(got).__name__}")
                    )
            elif case.shell is not None:
                code, out, err = _sub(t, case.shell)
            else:
                assert case.args is not None
                code, out, err = fsarm(*(a.replace("{t}", str(t)) for a in case.args))
    except _Hang:
        return "hang", f"still running after {HANG_S:g} s"
    except subprocess.TimeoutExpired:
        return "hang", f"still running after {HANG_S:g} s"
    except FsarmError as exc:
        if case.expect == "ok":
            return "refused valid", str(exc)
        return _named(str(exc), case, t)
    except Exception as exc:  # anything else reaching the user is a traceback
        return "traceback", f"{type(exc).__name__}: {exc}"[:300]
    if "Traceback" in out + err or "Exception ignored" in err:
        return "traceback", err.strip().splitlines()[-1] if err.strip() else "in stdout"
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("warning:")]
    if case.expect == "ok":
        if code == 0:
            return "correct run", ""
        return "refused valid", " | ".join(lines)[:300]
    if code == 0:
        return "silent wrong", "accepted (exit code 0)"
    if code == 2 and "Usage: fsarm" in err and "Error" in err:  # click's usage error box
        return _named(" ".join(err.split())[:200], case, t)
    errors = [ln for ln in lines if ln.startswith("error: ")]  # (warnings may wrap)
    if code != 2 or len(errors) != 1 or lines[-1] != errors[0]:
        return "traceback", f"exit {code}: {' | '.join(lines)[:300]}"
    return _named(errors[0][len("error: ") :], case, t)


def _named(message: str, case: Case, t: Path) -> tuple[str, str]:
    if "saved to " in message and RESCUE in message:  # the rescued results: seen, tidied
        tidy_rescue(Path(message.split("saved to ")[1].split(" instead")[0]))
    words = case.words.replace("{t}", str(t))
    if words and words not in " ".join(message.split()):
        return "silent wrong", f"named, but not {words!r}: {message[:200]}"
    return "named error", message[:200]


# ------------------------------------------------------------------------------------ checks


def files(*names: str) -> Check:
    """Every name must exist under the case's folder."""

    def check(t: Path) -> str | None:
        gone = [n for n in names if not (t / n).is_file()]
        return f"missing: {gone}" if gone else None

    return check


def _bend_written(t: Path) -> str | None:
    side = json.loads((t / "b.json").read_text())
    bend = side["synthetic"]["bend_rad"]
    return None if abs(bend - math.radians(120.0)) < 1e-12 else f"bend_rad {bend}"


# ------------------------------------------------------------------------------------ faults


def _with_stdout_failing(code: int, *args: str) -> Callable[[Path], Any]:
    def call(t: Path) -> tuple[int, str, str]:
        from fsarm_sim import cli

        err = io.StringIO()
        saved = sys.argv, sys.stdout
        sys.argv = ["fsarm", *(a.replace("{t}", str(t)) for a in args)]
        sys.stdout = FailingStdout(code)
        try:
            with contextlib.redirect_stderr(err):
                try:
                    cli.main()
                    rc = 0
                except SystemExit as exc:
                    rc = int(exc.code or 0)
        finally:
            sys.argv, sys.stdout = saved
        return rc, "", err.getvalue()

    return call


@contextlib.contextmanager
def _patched(obj: Any, name: str, value: Any) -> Iterator[None]:
    old = getattr(obj, name)
    setattr(obj, name, value)
    try:
        yield
    finally:
        setattr(obj, name, old)


def _store_fills(t: Path) -> tuple[int, str, str]:
    from fsarm_sim.records.store import ResultStore

    opened = ResultStore.__init__

    def init(self: ResultStore, path: Any) -> None:
        opened(self, path)
        pages = self._db.execute("PRAGMA page_count").fetchone()[0]
        self._db.execute(f"PRAGMA max_page_count = {pages + 1}")

    with _patched(ResultStore, "__init__", init):
        return fsarm(
            "sweep",
            "--store",
            str(t / "r.sqlite"),
            "--grid",
            "diameter_mm=4:13:10",
            "--outputs",
            "relief",
            "--workers",
            "1",
            "--no-progress",
        )


def _store_kept(t: Path) -> str | None:
    from fsarm_sim.records.store import ResultStore

    with ResultStore(t / "r.sqlite") as st:
        kept = st.count()
    if kept == 0:
        return "no point kept"
    code, out, _ = fsarm(
        "sweep",
        "--store",
        str(t / "r.sqlite"),
        "--grid",
        "diameter_mm=4:13:10",
        "--outputs",
        "relief",
        "--workers",
        "1",
        "--no-progress",
    )
    done = f"{kept} already stored, {10 - kept} computed"
    return None if code == 0 and done in " ".join(out.split()) else f"resume: {out[-200:]}"


def _timeseries_enospc(t: Path) -> tuple[int, str, str]:
    from fsarm_sim.records import timeseries

    original = timeseries.write_timeseries

    def full(result: Any, out_dir: Path, fmt: str = "csv") -> Path:
        if Path(out_dir) == t / "o":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return original(result, out_dir, fmt)

    with _patched(timeseries, "write_timeseries", full):
        code, out, err = fsarm("run", "step-q3", "--duration", "0.05", "--out", str(t / "o"))
    for line in err.splitlines():  # the rescue folder the message names: kept, then tidied
        if line.startswith("error:") and "saved to " in line:
            rescued = Path(line.split("saved to ")[1].split(" instead")[0])
            ok = (rescued / "step-q3.csv").is_file()
            tidy_rescue(rescued)
            if not ok:
                return 0, "", "the rescue folder lacks the time series"
    return code, out, err


def _eacces(t: Path) -> tuple[int, str, str]:
    real = os.access

    def access(path: Any, mode: int) -> bool:
        return not (mode & os.W_OK and str(path).startswith(str(t / "adir"))) and real(path, mode)

    with _patched(os, "access", access):
        return fsarm("run", "step-q3", "--duration", "0.05", "--out", str(t / "adir"))


def _shaft_unreadable(t: Path) -> tuple[int, str, str]:
    (t / "mine.toml").write_text("")
    real = Path.read_text

    def read_text(self: Path, *a: Any, **k: Any) -> str:
        if self.name == "mine.toml":
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(self))
        return real(self, *a, **k)

    with _patched(Path, "read_text", read_text):
        return fsarm("shafts", "--shaft-file", str(t / "mine.toml"))


def _latin1(t: Path, name: str, *args: str) -> tuple[int, str, str]:
    (t / name).write_bytes("# Müller's file\nx = 1\n".encode("latin-1"))
    return fsarm(*(a.replace("{t}", str(t)) for a in args))


def _special(t: Path, name: str, device: str | None, *args: str) -> tuple[int, str, str]:
    """``name`` as a link to ``device``, or (None) as a named pipe nobody writes to."""
    if device is None:
        os.mkfifo(t / name)
    else:
        (t / name).symlink_to(device)
    if name.endswith(".json"):
        shutil.copy(EXAMPLES / "series_null.csv", t / (name[: -len(".json")] + ".csv"))
    return fsarm(*(a.replace("{t}", str(t)) for a in args))


# ------------------------------------------------------------------------------------ the cases


def _sim() -> Any:
    from fsarm_sim.engine.model import SimConfig
    from fsarm_sim.sim import scenarios
    from fsarm_sim.sim.simulation import Simulation

    return Simulation(SimConfig(), scenarios.get("step-q3").table(10, 0.001), "native")


def _checked(path: str, what: str) -> Path:
    from fsarm_sim.paths import checked_path

    return checked_path(path, what)


def _lib(fn: Callable[[], Any]) -> Callable[[Path], Any]:
    return lambda t: fn()


def cases() -> list[Case]:
    from fsarm_sim.discrepancy import synth
    from fsarm_sim.plant.shaft import load_catalogue
    from fsarm_sim.sim.batch import run_batch
    from fsarm_sim.sim.simulation import run_scenario
    from fsarm_sim.studies import magnetic_spring_selection as sel
    from fsarm_sim.studies import speed
    from fsarm_sim.studies import sweep as sw

    run = ["run", "fig14-sine", "--duration", "0.05"]
    out = [*run, "--out", "{t}/o"]
    c: list[Case] = []

    def add(category: str, name: str, **kw: Any) -> None:
        c.append(Case(category, name, **kw))

    # -- paths: what the operating system refuses, named before any work
    for opt in ("--out", "--figures"):
        add("paths", f"run {opt} loop", args=[*run, "--out", "{t}/o", opt, "{t}/loop"])
    for opt in ("--json", "--rrd", "--shaft-file"):
        add("paths", f"run {opt} loop", args=[*out, opt, "{t}/loop"], words="loop")
    add("paths", "run --json inside a loop", args=[*out, "--json", "{t}/loop/s.json"])
    add("paths", "run --json long name", args=[*out, "--json", f"{{t}}/{LONG}"], words="longer")
    add("paths", "run --out long name", args=[*run, "--out", f"{{t}}/{LONG}/o"], words="longer")
    add("paths", "run --json under a file", args=[*out, "--json", "{t}/afile/s.json"])
    add("paths", "run --json is a folder", args=[*out, "--json", "{t}/adir"])
    add("paths", "shafts loop", args=["shafts", "--shaft-file", "{t}/loop"], words="loop")
    add("paths", "shafts folder", args=["shafts", "--shaft-file", "{t}/adir"])
    add("paths", "shafts missing", args=["shafts", "--shaft-file", "{t}/none.toml"])
    add("paths", "diagnose table loop", args=["diagnose", "{t}/lt.csv"], words="loop")
    add("paths", "diagnose sidecar loop", args=["diagnose", "{t}/ls.csv"], words="loop")
    add("paths", "diagnose long name", args=["diagnose", f"{{t}}/{LONG}.csv"], words="longer")
    add("paths", "diagnose table is a folder", args=["diagnose", "{t}/adir.csv"])
    add("paths", "sweep --spec loop", args=["sweep", "--spec", "{t}/loop", "--store", "{t}/s"])
    for store in ("{t}/loop", f"{{t}}/{LONG}", "{t}/adir"):
        add("paths", f"sweep --store {store[4:12]}", args=["sweep", "--store", store, "--dry-run"])
    add(
        "paths", "sweep-report loop", args=["sweep-report", "--store", "{t}/loop", "--out", "{t}/r"]
    )
    add("paths", "synth OUT loop", args=["synth", "{t}/lt.csv"], words="loop")
    add("paths", "synth OUT long", args=["synth", f"{{t}}/{LONG}"], words="longer")
    add("paths", "synth --input-file loop", args=["synth", "{t}/s", "--input-file", "{t}/loop"])
    add("paths", "synth --model loop", args=["synth", "{t}/s", "--model", "{t}/loop"])
    add("paths", "library: NUL in a name", call=_lib(lambda: _checked("a\x00b", "--json")))
    add(
        "paths",
        "deleted working directory, relative --out",
        shell="mkdir {t}/gone && cd {t}/gone && rmdir {t}/gone && exec {fsarm} run fig14-sine "
        "--duration 0.05",
        words="working directory no longer exists",
    )
    add(
        "paths",
        "deleted working directory, absolute --out",
        shell="mkdir {t}/gone && cd {t}/gone && rmdir {t}/gone && exec {fsarm} run fig14-sine "
        "--duration 0.05 --out {t}/abs",
        expect="ok",
        check=files("abs/fig14-sine.csv", "abs/fig14-sine.json"),
    )

    # -- numbers: nonsense and sizes that scale work, refused before any work
    for value in ("nan", "-1", "0", "inf", "1e300"):
        add("numbers", f"run --duration {value}", args=["run", "fig14-sine", "--duration", value])
    for opt, value in (
        ("--payload-kg", "16"),
        ("--payload-kg", "nan"),
        ("--log-every", "0"),
        ("--log-every", "-1"),
        ("--log-every", "99999999999999999999"),
        ("--ctrl-dt", "0"),
        ("--ctrl-dt", "nan"),
        ("--timestep", "0"),
        ("--timestep", "1e-12"),
        ("--diameter-mm", "100"),
        ("--length-mm", "nan"),
        ("--rrd-rate", "-5"),
    ):
        add("numbers", f"run {opt} {value}", args=[*out, opt, value])
    for grid in ("4:13:100000000", "4:13:0", "13:4:3", "4:13:2.5", "nan", "1e400", "4:13:1e300"):
        add(
            "numbers",
            f"sweep grid {grid}",
            args=["sweep", "--store", "{t}/s", "--grid", f"diameter_mm={grid}", "--dry-run"],
        )
    million = ["--grid", "diameter_mm=4:13:1000", "--grid", "length_mm=235:535:1000"]
    add(
        "numbers",
        "sweep grid 1e6 points",
        args=["sweep", "--store", "{t}/s", "--dry-run", *million],
        words="100000 allowed",
    )
    for workers in ("0", "100000", "-1"):
        add(
            "numbers",
            f"sweep --workers {workers}",
            args=["sweep", "--store", "{t}/s", "--grid", "diameter_mm=9", "--workers", workers],
        )
    for opt, value in (("--reps", "0"), ("--reps", "-5"), ("--max-workers", "0")):
        add("numbers", f"bench-speed {opt} {value}", args=["bench-speed", opt, value, "--quick"])
    for value in ("1e9", "nan", "0", "-1"):
        add(
            "numbers",
            f"model-selection --trial-s {value}",
            args=["model-selection", "--trial-s", value],
        )
    for opt, value in (
        ("--rate", "1e9"),
        ("--duration", "1e7"),
        ("--bend-deg", "500"),
        ("--bend-deg", "nan"),
        ("--noise", "-1"),
        ("--amplitude", "0"),
        ("--stiffness-scale", "inf"),
    ):
        add("numbers", f"synth {opt} {value}", args=["synth", "{t}/s.csv", opt, value])
    add(
        "numbers",
        "diagnose --max-effects -1",
        args=["diagnose", "{t}/m.csv", "--max-effects", "-1"],
    )
    add("numbers", "qa-throws --speeds 0", args=["qa-throws", "--speeds", "0"])
    add("numbers", "check-dynamics --duration nan", args=["check-dynamics", "--duration", "nan"])
    add(
        "numbers",
        "compare-transmissions --payload-kg nan",
        args=["compare-transmissions", "--payload-kg", "nan"],
    )

    # -- library: the same checks from Python; booleans are not numbers
    lib = "library"
    add(
        lib,
        "run_scenario duration True",
        call=_lib(lambda: run_scenario("fig14-sine", duration_s=True)),
    )
    add(
        lib,
        "run_scenario duration '1'",
        call=_lib(lambda: run_scenario("fig14-sine", duration_s="1")),
    )  # type: ignore[arg-type]
    add(
        lib,
        "run_scenario payload True",
        call=_lib(lambda: run_scenario("fig14-sine", duration_s=0.05, payload_kg=True)),
    )
    add(
        lib,
        "run_scenario log_every 1e20",
        call=_lib(lambda: run_scenario("fig14-sine", duration_s=0.05, log_every_ticks=10**20)),
    )
    add(
        lib,
        "run_scenario log_every 2.0",
        call=_lib(lambda: run_scenario("fig14-sine", duration_s=0.05, log_every_ticks=2.0)),
    )  # type: ignore[arg-type]
    add(lib, "measure_speed reps 0", call=_lib(lambda: speed.measure_speed(reps=0)))
    add(lib, "measure_speed max_workers 0", call=_lib(lambda: speed.measure_speed(max_workers=0)))
    add(lib, "measure_speed reps True", call=_lib(lambda: speed.measure_speed(reps=True)))
    add(
        lib,
        "model selection trial 1e9",
        call=_lib(lambda: sel.run_study(sel.BenchConfig(trial_s=1e9))),
    )
    add(
        lib,
        "model selection trial True",
        call=_lib(lambda: sel.run_study(sel.BenchConfig(trial_s=True))),
    )  # type: ignore[arg-type]
    add(
        lib,
        "synth Recording bend True",
        call=_lib(lambda: synth.Recording(bend_rad=True).validate()),
    )  # type: ignore[arg-type]
    add(
        lib,
        "synth bend 500 deg",
        call=_lib(
            lambda: synth.synthesize_setup(
                "series_bench",
                recording=synth.Recording(duration_s=1.0, bend_rad=math.radians(500)),
            )
        ),
    )
    shaft = load_catalogue().shaft
    add(lib, "catalogue shaft D True", call=_lib(lambda: shaft(True, 450.0)))
    add(lib, "catalogue shaft D '9'", call=_lib(lambda: shaft("9", 450.0)))  # type: ignore[arg-type]
    add(lib, "bend check True", call=_lib(lambda: load_catalogue().check_bend(True)))
    for name, kw in (
        ("n_steps True", {"n_steps": True}),
        ("n_steps 1e12", {"n_steps": 10**12}),
        ("n_steps 2.0", {"n_steps": 2.0}),
        ("workers 0", {"n_steps": 1, "workers": 0}),
        ("record 3e8 steps", {"n_steps": 300_000_000, "record": True}),
    ):
        add(lib, f"run_batch {name}", call=lambda t, kw=kw: run_batch([_sim()], **kw))
    add(
        lib,
        "sweep range 1e8",
        call=_lib(lambda: sw.build_spec(grid=["diameter_mm=4:13:100000000"])),
    )
    add(
        lib,
        "sweep workers 0",
        call=lambda t: sw.run_sweep(
            sw.build_spec(grid=["diameter_mm=9"], outputs=["relief"]), t / "r.sqlite", workers=0
        ),
    )
    add(
        lib,
        "sweep workers True",
        call=lambda t: sw.run_sweep(
            sw.build_spec(grid=["diameter_mm=9"], outputs=["relief"]), t / "r.sqlite", workers=True
        ),
    )  # type: ignore[arg-type]

    # -- files: what a reader is given
    for name, words in (
        ("dup", "'tau_s' is given twice"),
        ("deep", "nest deeper than"),
        ("list", "JSON object"),
        ("empty", ""),
        ("head", ""),
        ("bin", ""),
    ):
        add("files", f"diagnose {name}.csv", args=["diagnose", f"{{t}}/{name}.csv"], words=words)
    add(
        "files",
        "shafts deep TOML",
        args=["shafts", "--shaft-file", "{t}/deep.toml"],
        words="nest deeper",
    )
    add(
        "files",
        "shafts not TOML",
        args=["shafts", "--shaft-file", "{t}/bad.toml"],
        words="not valid TOML",
    )
    add(
        "files",
        "run --shaft-file deep TOML",
        args=[*out, "--shaft-file", "{t}/deep.toml"],
        words="nest deeper",
    )
    add(
        "files",
        "sweep deep spec",
        args=["sweep", "--spec", "{t}/deepspec.toml", "--store", "{t}/s", "--dry-run"],
        words="nest deeper",
    )
    add(
        "files",
        "synth --model deep JSON",
        args=["synth", "{t}/s", "--model", "{t}/model.json"],
        words="nest deeper",
    )
    add(
        "files",
        "synth --input-file repeated column",
        args=["synth", "{t}/s", "--input-file", "{t}/indup.csv"],
        words="given twice",
    )
    add(
        "files",
        "synth --input-file header only",
        args=["synth", "{t}/s", "--input-file", "{t}/head.csv"],
        words=">= 10 finite rows",
    )
    add(
        "files",
        "sweep foreign SQLite",
        args=["sweep", "--store", "{t}/foreign.db", "--grid", "diameter_mm=9", "--dry-run"],
        words="did not create",
    )
    add(
        "files",
        "sweep-report not SQLite",
        args=["sweep-report", "--store", "{t}/m.csv", "--out", "{t}/r"],
    )

    # -- overwrites: an output on an input is refused, the input left as it was
    ow = "overwrites"
    add(
        ow,
        "synth OUT is its --input-file",
        args=["synth", "{t}/in.csv", "--input-file", "{t}/in.csv"],
        words="(an input)",
    )
    add(
        ow,
        "synth OUT (no suffix) is its --input-file",
        args=["synth", "{t}/in", "--input-file", "{t}/in.csv"],
        words="(an input)",
    )
    add(
        ow,
        "synth sidecar over --model",
        args=["synth", "{t}/model.csv", "--model", "{t}/model.json"],
        words="(an input)",
    )
    add(
        ow,
        "run --json over --shaft-file",
        args=[*out, "--shaft-file", "{t}/spec.toml", "--json", "{t}/spec.toml"],
    )
    add(ow, "diagnose --json over the table", args=["diagnose", "{t}/m.csv", "--json", "{t}/m.csv"])
    add(
        ow,
        "diagnose --model over the sidecar",
        args=["diagnose", "{t}/m.csv", "--model", "{t}/m.json"],
    )
    add(
        ow,
        "sweep --store over --spec",
        args=["sweep", "--store", "{t}/spec.toml", "--spec", "{t}/spec.toml"],
    )
    add(
        ow,
        "design-experiment --out over the table",
        args=["design-experiment", "{t}/m.csv", "--out", "{t}/m.csv"],
    )

    # -- faults: the environment fails while the command works; finished work is kept
    ft = "faults"
    if Path("/dev/full").exists():
        add(
            ft,
            "run with stdout on /dev/full",
            shell="exec {fsarm} run fig14-sine --duration 0.05 --out {t}/D --json {t}/S >/dev/full",
            words="standard output could not be written",
            check=files("D/fig14-sine.csv", "D/fig14-sine.json", "S"),
        )
        add(
            ft,
            "scenarios > /dev/full",
            shell="exec {fsarm} scenarios >/dev/full",
            words="standard output",
        )
        add(
            ft,
            "run --json /dev/full",
            args=[*out, "--json", "/dev/full"],
            words="saved to",
            check=files("o/fig14-sine.csv"),
        )
    add(
        ft,
        "stdout ENOSPC (in process)",
        call=_with_stdout_failing(errno.ENOSPC, *out, "--json", "{t}/S"),
        words="no space left",
        check=files("o/fig14-sine.csv", "S"),
    )
    add(
        ft,
        "stdout EIO (closed terminal)",
        call=_with_stdout_failing(errno.EIO, *out),
        words="input/output error",
        check=files("o/fig14-sine.csv"),
    )
    add(
        ft,
        "stdout EPIPE (| head)",
        call=_with_stdout_failing(errno.EPIPE, *out),
        expect="ok",
        check=files("o/fig14-sine.csv"),
    )
    add(ft, "sweep store fills up", call=_store_fills, words="are kept", check=_store_kept)
    add(ft, "time series write ENOSPC (rescued)", call=_timeseries_enospc, words="saved to")
    add(ft, "output folder not writable", call=_eacces, words="no permission to write")
    add(ft, "coefficient file EACCES", call=_shaft_unreadable, words="Permission denied")

    # -- encodings: files that are not UTF-8 text
    enc = "encodings"
    add(
        enc,
        "shafts latin-1 TOML",
        call=lambda t: _latin1(t, "c.toml", "shafts", "--shaft-file", "{t}/c.toml"),
        words="c.toml",
    )
    add(
        enc,
        "sweep latin-1 spec",
        call=lambda t: _latin1(
            t, "c.toml", "sweep", "--spec", "{t}/c.toml", "--store", "{t}/s", "--dry-run"
        ),
        words="c.toml",
    )
    add(
        enc,
        "diagnose latin-1 sidecar",
        call=lambda t: _latin1(t, "m.json", "diagnose", "{t}/m.csv"),
        words="m.json",
        may_change=("m.json",),
    )
    add(
        enc,
        "synth latin-1 --input-file",
        call=lambda t: _latin1(t, "c.csv", "synth", "{t}/s", "--input-file", "{t}/c.csv"),
        words="c.csv",
    )
    add(
        enc,
        "synth latin-1 --model",
        call=lambda t: _latin1(t, "c.json", "synth", "{t}/s", "--model", "{t}/c.json"),
        words="c.json",
    )

    # -- special files: devices and named pipes as inputs (a read would never end or answer)
    sp = "special"
    add(
        sp,
        "diagnose /dev/zero as the table",
        call=lambda t: _special(t, "z.csv", "/dev/zero", "diagnose", "{t}/z.csv"),
        words="not a regular file",
    )
    add(
        sp,
        "diagnose a FIFO as the table",
        call=lambda t: _special(t, "f.csv", None, "diagnose", "{t}/f.csv"),
        words="not a regular file",
    )
    add(
        sp,
        "diagnose a FIFO as the sidecar",
        call=lambda t: _special(t, "f.json", None, "diagnose", "{t}/f.csv"),
    )
    add(
        sp,
        "synth --input-file /dev/zero",
        args=["synth", "{t}/s", "--input-file", "/dev/zero"],
        words="not a regular file",
    )
    add(
        sp,
        "synth --input-file a FIFO",
        call=lambda t: _special(t, "f.csv", None, "synth", "{t}/s", "--input-file", "{t}/f.csv"),
        words="not a regular file",
    )
    add(
        sp,
        "synth --model a FIFO",
        call=lambda t: _special(t, "f.json", None, "synth", "{t}/s", "--model", "{t}/f.json"),
        words="not a regular file",
    )
    add(
        sp,
        "shafts --shaft-file a FIFO",
        call=lambda t: _special(t, "f.toml", None, "shafts", "--shaft-file", "{t}/f.toml"),
    )
    add(sp, "sweep --spec /dev/zero", args=["sweep", "--spec", "/dev/zero", "--store", "{t}/s"])
    add(
        sp,
        "sweep --store a FIFO",
        call=lambda t: _special(
            t, "f.db", None, "sweep", "--store", "{t}/f.db", "--grid", "diameter_mm=9", "--dry-run"
        ),
        words="is not a file",
    )
    add(
        sp,
        "run --json /dev/null",
        args=[*out, "--json", "/dev/null"],
        expect="ok",
        check=files("o/fig14-sine.csv"),
    )

    # -- names: paths with spaces, non-ASCII letters and Rich markup, printed as written
    nm = "names"
    add(
        nm,
        "run into a folder with spaces and umlauts",
        args=[*run, "--out", "{t}/a b/ü", "--json", "{t}/a b/[red]s.json"],
        expect="ok",
        check=files("a b/ü/fig14-sine.csv", "a b/[red]s.json"),
    )
    add(
        nm,
        "markup in a missing file's name",
        args=["shafts", "--shaft-file", "{t}/[bold]x[/bold].toml"],
        words="[bold]x[/bold].toml",
    )
    add(
        nm,
        "a file name starting with a dash",
        args=["synth", "--duration", "1", "--", "{t}/-x"],
        expect="ok",
        check=files("-x.csv", "-x.json"),
    )

    # -- valid input next to the edges: must run, and write the right thing
    ok = "valid"
    add(
        ok,
        "run with every output",
        args=[*out, "--json", "{t}/S"],
        expect="ok",
        check=files("o/fig14-sine.csv", "o/fig14-sine.json", "S"),
    )
    add(
        ok,
        "run --log-every at its cap",
        args=[*out, "--log-every", "360000000"],
        expect="ok",
        check=files("o/fig14-sine.csv"),
    )
    add(ok, "scenarios", args=["scenarios"], expect="ok")
    add(
        ok,
        "synth --bend-deg 120 (the edge)",
        args=["synth", "{t}/b", "--bend-deg", "120", "--duration", "1"],
        expect="ok",
        check=_bend_written,
    )
    add(
        ok,
        "synth other OUT with --input-file",
        args=["synth", "{t}/x.parquet", "--input-file", "{t}/in.csv", "--rate", "100"],
        expect="ok",
        check=files("x.parquet", "x.json"),
    )
    add(
        ok,
        "sweep dry run 4:13:4",
        args=["sweep", "--store", "{t}/s", "--grid", "diameter_mm=4:13:4", "--dry-run"],
        expect="ok",
    )
    add(
        ok,
        "sweep of 3 relief points",
        args=[
            "sweep",
            "--store",
            "{t}/r.sqlite",
            "--grid",
            "diameter_mm=4,9,13",
            "--outputs",
            "relief",
            "--workers",
            "1",
            "--no-progress",
        ],
        expect="ok",
        check=files("r.sqlite"),
    )
    return c


def run_battery(root: Path | None = None) -> list[Result]:
    os.environ.setdefault("MUJOCO_GL", "disable")
    with contextlib.ExitStack() as stack:
        base = root or Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="fsarm-bad-")))
        return [run_case(case, base) for case in cases()]


def counts(results: list[Result]) -> dict[str, Counter[str]]:
    """Outcome counts per category, and over all under "all"."""
    out: dict[str, Counter[str]] = {"all": Counter()}
    for r in results:
        out.setdefault(r.case.category, Counter())[r.outcome] += 1
        out["all"][r.outcome] += 1
    return out


def report(results: list[Result]) -> str:
    lines = [f"{'outcome':<14} {'s':>5}  {'category':<10} case: detail"]
    for r in results:
        lines.append(
            f"{r.outcome:<14} {r.seconds:5.1f}  {r.case.category:<10} {r.case.name}: {r.detail}"
        )
    lines.append("")
    for cat, n in counts(results).items():
        lines.append(f"{cat:<10} " + ", ".join(f"{o} {n[o]}" for o in OUTCOMES if n[o]))
    return "\n".join(lines)


if __name__ == "__main__":
    print(report(run_battery()))
