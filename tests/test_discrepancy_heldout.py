"""The generalisation protocol of issue 28: the outside generator (tests/batteries/gen_bench.py)
imports nothing of the diagnosis, its kinds are split once, its records load."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from batteries import gen_bench as G

GEN = Path(G.__file__)


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
        "from batteries import gen_bench as G;"
        "G.make_record(G.KINDS[0], 3);"
        "bad = [m for m in sys.modules if m.startswith('fsarm_sim.discrepancy')];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    root = GEN.parent.parent.parent
    r = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_split_is_fixed_and_covers_every_category() -> None:
    sp = G.split()
    assert sp == G.split()
    assert set(sp) == {k.name for k in G.KINDS}
    for cat in ("library", "library_multi", "outside", "outside_plus", "null"):
        sets = {sp[k.name] for k in G.KINDS if k.category == cat}
        assert sets == {"dev", "heldout"}, cat
    outside = [k for k in G.KINDS if k.category == "outside"]
    assert len(outside) >= 7  # at least six new outside kinds beside the project's 50 Hz line
    nulls = [k for k in G.KINDS if k.category == "null" and sp[k.name] == "heldout"]
    assert any(k.noise != "white" for k in nulls)


@pytest.mark.parametrize("kind", ["null_pink", "mesh_ripple", "backlash+delay+sensor_offset"])
def test_records_load_in_the_measured_format(kind: str, tmp_path: Path) -> None:
    from fsarm_sim.records.measured import load_dataset

    k = next(k for k in G.KINDS if k.name == kind)
    rec = G.make_record(k, 3)  # index 3: a short record
    ds = load_dataset(G.write_record(rec, tmp_path))
    assert ds.setup == "series_bench"
    assert rec.truth["duration_s"] == G.SHORT_S
    tau = rec.columns["tau_s"]
    assert np.all(np.isfinite(tau)) and float(np.ptp(tau)) > 0
