#!/usr/bin/env bash
# Create .venv (Python 3.11) and install fsarm-sim with the pinned, known-good versions.
# Idempotent: re-installs only when pyproject.toml or requirements.lock changed.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-python3.11}"
command -v "$PY" >/dev/null 2>&1 || PY=python3
"$PY" -c 'import sys; sys.exit(0 if (3, 11) <= sys.version_info[:2] < (3, 13) else 1)' \
  || { echo "fsarm-sim needs Python 3.11 or 3.12 (found: $("$PY" --version 2>&1))" >&2; exit 1; }
[ -x .venv/bin/python ] || "$PY" -m venv .venv
stamp=$(cat pyproject.toml requirements.lock | sha256sum | cut -c1-16)
if [ "$(cat .venv/.setup-stamp 2>/dev/null)" != "$stamp" ]; then
  echo "Setting up .venv with the pinned packages (first run: 1-2 minutes; log: .venv/setup.log) ..."
  if ! { .venv/bin/python -m pip install --upgrade pip \
         && .venv/bin/python -m pip install -c requirements.lock -e ".[dev]"; } >.venv/setup.log 2>&1; then
    tail -n 30 .venv/setup.log >&2
    echo "setup failed; full log in .venv/setup.log" >&2
    exit 1
  fi
  echo "$stamp" > .venv/.setup-stamp
fi
