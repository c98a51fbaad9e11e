"""The fsarm app completed on first use: whole for every reader, lean for `fsarm run`."""

from __future__ import annotations

import os
import subprocess
import sys

import typer
from typer.main import get_command
from typer.testing import CliRunner

from fsarm_sim.lazy_commands import LazyTyper, command_name, preload


def _app() -> tuple[LazyTyper, list[str]]:
    calls: list[str] = []

    def register() -> None:
        calls.append("registered")

        @app.command("extra")
        def extra() -> None:
            typer.echo("extra ran")

    app = LazyTyper(register_extensions=register, no_args_is_help=True)

    @app.command("core")
    def core(x: int = 1) -> None:
        typer.echo(f"core {x}")

    @app.command("other")
    def other() -> None:
        typer.echo("other ran")

    return app, calls


def test_extensions_are_registered_on_first_read_after_ready() -> None:
    app, calls = _app()
    assert calls == []  # defining the module's own commands registers nothing
    app.ready()
    assert calls == []
    assert set(get_command(app).commands) == {"core", "other", "extra"}  # type: ignore[attr-defined]
    assert calls == ["registered"]
    get_command(app)
    assert calls == ["registered"]  # once
    res = CliRunner().invoke(app, ["extra"])
    assert res.exit_code == 0 and "extra ran" in res.output


def test_core_only_builds_the_module_commands_alone() -> None:
    app, calls = _app()
    app.ready()
    assert app.core_names() == {"core", "other"}
    with app.core_only():
        res = CliRunner().invoke(app, ["core", "--x", "3"])
        assert set(get_command(app).commands) == {"core", "other"}  # type: ignore[attr-defined]
    assert res.exit_code == 0 and "core 3" in res.output
    assert calls == []
    assert "extra" in get_command(app).commands  # type: ignore[attr-defined]  # whole again


def test_command_name() -> None:
    assert command_name(["run", "fig14-sine", "--duration", "1"]) == "run"
    assert command_name(["--help", "run"]) is None  # the group's help: the whole app
    assert command_name([]) is None


def test_preload_imports_in_the_background_and_swallows_failures() -> None:
    preload("colorsys", "fsarm_sim_no_such_module").join(timeout=30)
    assert "colorsys" in sys.modules


_PROBE = """
import sys
sys.argv = ["fsarm", *sys.argv[1:]]
from fsarm_sim import cli
try:
    cli.main()
except SystemExit:
    pass
sys.stderr.write("EXT=%s\\n" % ("fsarm_sim.cli.sweep" in sys.modules))
"""


def _probe(*args: str) -> tuple[str, str]:
    got = subprocess.run(
        [sys.executable, "-c", _PROBE, *args],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MUJOCO_GL": "disable", "COLUMNS": "200"},
        check=False,
    )
    return got.stdout, got.stderr


def test_fsarm_core_command_imports_no_extension_module() -> None:
    out, err = _probe("scenarios")
    assert "fig14-sine" in out
    assert "EXT=False" in err
    out, err = _probe("--help")  # the whole app: every command listed
    assert "bench-speed" in out and "sweep" in out and "run" in out
    assert "EXT=True" in err


def test_the_imported_app_is_whole() -> None:
    from fsarm_sim.cli import app

    names = set(get_command(app).commands)  # type: ignore[attr-defined]
    assert {"run", "scenarios", "sweep", "bench-speed", "diagnose", "collision"} <= names


def test_imports_are_frozen_only_in_a_process_that_runs_fsarm() -> None:
    import gc

    from fsarm_sim.cli import main
    from fsarm_sim.lazy_commands import freeze_imports_if_entry

    before = gc.get_freeze_count()
    assert not freeze_imports_if_entry(main)  # pytest's __main__ did not import it
    assert gc.get_freeze_count() == before
    code = (
        "import gc, sys\n"
        "from fsarm_sim.cli import main\n"
        "sys.argv = ['fsarm', 'scenarios']\n"
        "try:\n"
        "    main()\n"
        "except SystemExit:\n"
        "    pass\n"
        "sys.stderr.write('FROZEN=%d' % gc.get_freeze_count())\n"
    )
    got = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MUJOCO_GL": "disable"},
        check=False,
    )
    assert "fig14-sine" in got.stdout
    frozen = int(got.stderr.rsplit("FROZEN=", 1)[1])
    assert frozen > 10_000  # the imports' objects (typer, rich, numpy, ...)
