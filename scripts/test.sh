#!/usr/bin/env bash
# Set up .venv, then lint, format-check, type-check and run the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_env.sh
export MUJOCO_GL="${MUJOCO_GL:-disable}"
.venv/bin/ruff check .
.venv/bin/ruff format --check .
.venv/bin/mypy
# the suite on up to four cores (pytest-xdist); `-n 0` as an argument runs it in one process
workers=$(nproc 2>/dev/null || echo 2)
[ "$workers" -gt 4 ] && workers=4
.venv/bin/python -m pytest -n "$workers" "$@"
