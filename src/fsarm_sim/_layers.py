"""The package's layers, bottom to top: the one place that says where each module belongs.

A module may import from its own layer or from a layer below it, never from one above, and the
imports never form a cycle; ``tests/test_imports.py`` builds the import graph from the source
(function-level and type-checking imports included) and fails on either, and on a module that is
missing here. Names are relative to ``fsarm_sim`` (``__init__``: the package itself); a
package's name covers its submodules unless a submodule is listed itself. ``controllers`` is the
top-level ``controllers/`` folder, installed as ``fsarm_sim.controllers``.

Read top-down, the layers are the package's folders:

* base - the command's fixed choices (enums), named errors, declared parameter blocks, checked paths and output paths, the strict typed-table reader, task
  executors, the lazily completed command app, the seed papers' declared claims (data: the
  calibration targets);
* laws (``plant/``, ``controllers/``) - physical laws and pure controllers: no MuJoCo,
  compilable (effects, transmissions, the shaft catalogue);
* layout (``kernels/layout``) - where parameters and states live inside a model and its data;
* kernels (``kernels/physics``) - the array kernels the callbacks run;
* engine (``engine/``) - MuJoCo glue: model building, callbacks, native compilation;
* simulation (``sim/``) - the runner, its scenarios and their outer loops, batches of runs;
* records - the record schema, measured data, written runs, the results store;
* studies - what is computed from runs: benches, sweeps, shaft selection, comparisons,
  collision detection, verification (Pinocchio, energy), speed, identification, environments,
  the seed papers' claims judged;
* review - recordings and figures;
* discrepancy - naming what a record shows that the model lacks (and synthetic records for it);
* request (``run_request``) - a run as ``fsarm run`` makes it: options checked, outputs planned;
* cli - the ``fsarm`` command: parse, call the library, print;
* api - the package's own names (``from fsarm_sim import run_scenario``), imported lazily.
"""

from __future__ import annotations

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "base",
        (
            "_layers",
            "_version",
            "choices",
            "data",
            "errors",
            "executors",
            "lazy_commands",
            "outputs",
            "paramblocks",
            "paths",
            "typed_tables",
            # the papers' claims are declared data, read by calibration code below studies
            "studies.reproduce.claims",
            "studies.reproduce.claims_file",
            "studies.reproduce.targets",
        ),
    ),
    ("laws", ("controllers", "plant")),
    ("layout", ("kernels", "kernels.layout")),
    ("kernels", ("kernels.physics",)),
    ("engine", ("engine",)),
    ("simulation", ("sim",)),
    ("records", ("records",)),
    ("studies", ("studies", "gym")),
    ("review", ("review",)),
    ("discrepancy", ("discrepancy",)),
    ("request", ("run_request",)),
    ("cli", ("cli",)),
    ("api", ("__init__", "api")),
)
