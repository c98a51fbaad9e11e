"""The package's import graph, read from the source: layers, cycles, private names, thin CLI.

Every import counts: module level, inside functions, under ``TYPE_CHECKING``, and
``importlib.import_module("fsarm_sim....")`` with a literal name. The layers are declared once,
in :mod:`fsarm_sim._layers`.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from fsarm_sim._layers import LAYERS

PACKAGE = "fsarm_sim"
REPO = Path(__file__).resolve().parents[1]
# where each importable tree lives in the repository (controllers/ installs as a subpackage)
SOURCES = {PACKAGE: REPO / "src" / PACKAGE, f"{PACKAGE}.controllers": REPO / "controllers"}
CLI_LAYER = "cli"

# Known upward imports, each to be removed by moving code down (the test fails once one is gone,
# so the list only shrinks). Add nothing here: move the code instead.
PENDING_UPWARD: dict[tuple[str, str], str] = {}
# Known uses of another module's private names (same rule: the list only shrinks).
PENDING_PRIVATE: dict[tuple[str, str, str], str] = {}


@dataclass(frozen=True)
class Import:
    source: str  # the importing module
    target: str  # the imported module
    names: tuple[str, ...]  # names taken from it (from-imports and attribute uses); () = the module
    line: int


def _module_name(root: str, base: Path, path: Path) -> str:
    parts = [*root.split("."), *path.relative_to(base).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    """Every module of the package (dotted name -> file)."""
    out: dict[str, Path] = {}
    for root, base in SOURCES.items():
        for path in sorted(base.rglob("*.py")):
            out[_module_name(root, base, path)] = path
    return out


MODULES = modules()


def _resolve(module: str, path: Path, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    anchor = package[: len(package) - node.level + 1]
    return ".".join(anchor + ([node.module] if node.module else []))


def imports_of(module: str) -> list[Import]:
    """Every import of a package module in ``module``, with the names taken from it."""
    path = MODULES[module]
    tree = ast.parse(path.read_text("utf-8"), str(path))
    out: list[Import] = []
    bound: dict[str, str] = {}  # local name -> package module it is bound to
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in MODULES:
                    out.append(Import(module, alias.name, (), node.lineno))
                    if alias.asname:
                        bound[alias.asname] = alias.name
        elif isinstance(node, ast.ImportFrom):
            target = _resolve(module, path, node)
            if target not in MODULES:
                continue
            taken = []
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                if sub in MODULES:
                    out.append(Import(module, sub, (), node.lineno))
                    bound[alias.asname or alias.name] = sub
                else:
                    taken.append(alias.name)
            if taken:
                out.append(Import(module, target, tuple(taken), node.lineno))
        elif (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "import_module"
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and node.args[0].value in MODULES
        ):
            out.append(Import(module, str(node.args[0].value), (), node.lineno))
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in bound
        ):
            out.append(Import(module, bound[node.value.id], (node.attr,), node.lineno))
    return [i for i in out if i.target != module]


IMPORTS = [i for m in MODULES for i in imports_of(m)]


def layer_of(module: str) -> int:
    """Index of ``module``'s layer in LAYERS (the deepest listed name that covers it)."""
    rel = module.removeprefix(PACKAGE).removeprefix(".") or "__init__"
    parts = rel.split(".")
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        for k, (_, names) in enumerate(LAYERS):
            if name in names:
                return k
    raise LookupError(f"{module} is in no layer: add it to fsarm_sim/_layers.py")


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _cycles(edges: dict[str, set[str]]) -> Iterator[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()

    def visit(v: str) -> Iterator[list[str]]:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                yield from visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                yield sorted(comp)

    for v in sorted(edges):
        if v not in index:
            yield from visit(v)


def test_the_graph_sees_every_kind_of_import() -> None:
    """Guards the reader itself: function-level, TYPE_CHECKING and importlib imports count."""
    seen = {(i.source, i.target) for i in IMPORTS}
    assert ("fsarm_sim.cli", "fsarm_sim.cli.speed") in seen  # importlib.import_module("...")
    assert ("fsarm_sim.cli", "fsarm_sim.sim.simulation") in seen  # inside a function
    assert (
        "fsarm_sim.kernels.physics",
        "fsarm_sim.controllers.joint3_torque",
    ) in seen  # controllers/
    assert ("fsarm_sim.studies.collision", "fsarm_sim.sim.outer_loops") in seen


def test_every_module_is_in_exactly_one_layer() -> None:
    listed = [name for _, names in LAYERS for name in names]
    assert len(listed) == len(set(listed)), "a name is listed in two layers"
    rel = {m.removeprefix(PACKAGE).removeprefix(".") or "__init__" for m in MODULES}
    stale = [n for n in listed if n not in rel and not any(r.startswith(f"{n}.") for r in rel)]
    assert not stale, f"listed in fsarm_sim/_layers.py but not a module: {stale}"
    for m in MODULES:
        layer_of(m)  # raises for a module in no layer


def test_no_import_cycles() -> None:
    edges: dict[str, set[str]] = {m: set() for m in MODULES}
    for i in IMPORTS:
        edges[i.source].add(i.target)
    cycles = list(_cycles(edges))
    assert not cycles, "import cycles: " + "; ".join(" <-> ".join(c) for c in cycles)


def test_no_upward_imports() -> None:
    names = [n for n, _ in LAYERS]
    upward = {}
    for i in IMPORTS:
        low, high = layer_of(i.source), layer_of(i.target)
        if high > low:
            upward[(i.source, i.target)] = (
                f"{i.source} ({names[low]}) imports {i.target} ({names[high]}), line {i.line}"
            )
    new = [msg for key, msg in sorted(upward.items()) if key not in PENDING_UPWARD]
    assert not new, "upward imports (move the code down instead):\n" + "\n".join(new)
    fixed = [key for key in PENDING_UPWARD if key not in upward]
    assert not fixed, f"no longer imported upward, remove from PENDING_UPWARD: {fixed}"


def test_no_module_uses_another_modules_private_names() -> None:
    found = {}
    for i in IMPORTS:
        for name in i.names:
            if _private(name):
                found[(i.source, i.target, name)] = f"{i.source}:{i.line} uses {i.target}.{name}"
    new = [msg for key, msg in sorted(found.items()) if key not in PENDING_PRIVATE]
    assert not new, "private names used across modules (make them public):\n" + "\n".join(new)
    fixed = [key for key in PENDING_PRIVATE if key not in found]
    assert not fixed, f"no longer used, remove from PENDING_PRIVATE: {fixed}"


def _is_cli(module: str) -> bool:
    try:
        return LAYERS[layer_of(module)][0] == CLI_LAYER
    except LookupError:  # reported by test_every_module_is_in_exactly_one_layer
        return False


def test_only_cli_modules_import_cli_modules() -> None:
    """A CLI module holds commands and their printing; what others need is library code."""
    bad = [
        f"{i.source}:{i.line} imports {i.target}"
        for i in IMPORTS
        if _is_cli(i.target) and not _is_cli(i.source)
    ]
    assert not bad, "move what these use from the CLI into the library:\n" + "\n".join(bad)


@pytest.mark.parametrize("module", sorted(m for m in MODULES if _is_cli(m)))
def test_cli_modules_define_no_types(module: str) -> None:
    """Result and settings types belong to the library; a CLI module only parses and prints."""
    tree = ast.parse(MODULES[module].read_text("utf-8"))
    classes = [n.name for n in tree.body if isinstance(n, ast.ClassDef)]
    assert not classes, f"{module} defines {classes}: move them into the library"


def test_top_level_api_is_lazy_and_complete() -> None:
    """``from fsarm_sim import ...`` gives the first script's names; importing the package alone
    imports none of them (the ``fsarm`` command's start-up)."""
    import subprocess
    import sys

    import fsarm_sim
    from fsarm_sim import api

    assert set(fsarm_sim.__all__) == {"__version__", *api.__all__}
    for name in api.__all__:
        assert getattr(fsarm_sim, name) is getattr(api, name)
    code = "import sys, fsarm_sim; print('fsarm_sim.api' in sys.modules, 'mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
