#!/usr/bin/env bash
# Create .venv (Python 3.11) and install fsarm-sim with the pinned, known-good versions.
# Idempotent: re-installs only when pyproject.toml or requirements.lock changed.
# --no-browser: skip Debian's chromium, which only the viewer check of the test suite needs (the
# demo passes it).
set -euo pipefail
browser=1
[ "${1:-}" = "--no-browser" ] && browser=0
cd "$(dirname "$0")/.."
PY="${PYTHON:-python3.11}"
command -v "$PY" >/dev/null 2>&1 || PY=python3
"$PY" -c 'import sys; sys.exit(0 if (3, 11) <= sys.version_info[:2] < (3, 13) else 1)' \
  || { echo "fsarm-sim needs Python 3.11 or 3.12 (found: $("$PY" --version 2>&1))" >&2; exit 1; }
# The installer: uv (an installer several times faster than pip: with warm caches the pinned
# environment installs in ~10 s instead of ~60-90 s) when it is on PATH or can be put in the user's
# cache with pip (a pinned version, once per machine); pip otherwise, and whenever uv fails (e.g. an
# index only pip is configured for). FSARM_NO_UV=1 forces pip.
uv_pin=0.13.9
uv_home="${XDG_CACHE_HOME:-$HOME/.cache}/fsarm-sim/uv-$uv_pin"
find_uv() {
  [ -n "${FSARM_NO_UV:-}" ] && return 1
  if command -v uv >/dev/null 2>&1; then UV=$(command -v uv); return 0; fi
  UV="$uv_home/bin/uv"
  [ -x "$UV" ] && return 0
  "$PY" -m pip install -q --disable-pip-version-check --target "$uv_home" "uv==$uv_pin" \
    >/dev/null 2>&1 && [ -x "$UV" ]
}
stamp=$(cat pyproject.toml requirements.lock | sha256sum | cut -c1-16)
if [ ! -x .venv/bin/python ] || [ "$(cat .venv/.setup-stamp 2>/dev/null)" != "$stamp" ]; then
  echo "Setting up .venv with the pinned packages (first run: ~10-40 s with uv, 1-2 minutes with pip; log: .venv/setup.log) ..."
  log=$(mktemp)
  done_with=""
  if find_uv; then
    made=0
    [ -x .venv/bin/python ] || made=1
    if { [ "$made" = 0 ] || "$UV" venv --seed --python "$(command -v "$PY")" .venv; } >"$log" 2>&1 \
       && "$UV" pip install --python .venv/bin/python -c requirements.lock -e ".[dev]" >>"$log" 2>&1; then
      done_with=uv
    else
      echo "uv failed (see above); installing with pip" >>"$log"
      [ "$made" = 1 ] && rm -rf .venv  # made by this call: pip starts from a clean one
    fi
  fi
  if [ -z "$done_with" ]; then
    [ -x .venv/bin/python ] || "$PY" -m venv .venv >>"$log" 2>&1
    .venv/bin/python -m pip --version >/dev/null 2>&1 || .venv/bin/python -m ensurepip -q >>"$log" 2>&1 || true
    if { .venv/bin/python -m pip install --upgrade pip \
         && .venv/bin/python -m pip install -c requirements.lock -e ".[dev]"; } >>"$log" 2>&1; then
      done_with=pip
    fi
  fi
  mkdir -p .venv && mv "$log" .venv/setup.log
  if [ -z "$done_with" ]; then
    tail -n 30 .venv/setup.log >&2
    echo "setup failed; full log in .venv/setup.log" >&2
    exit 1
  fi
  echo "installed with $done_with" >> .venv/setup.log
  echo "$stamp" > .venv/.setup-stamp
fi
# Bytecode of the package, written now: an editable install does not compile it, and where
# Python may not write it (PYTHONDONTWRITEBYTECODE) every command would compile ~100 modules
# from source at start (~60 ms of a ~0.4 s `fsarm run`). Python rewrites a file's bytecode
# after an edit where it may write; elsewhere it compiles that file in memory.
.venv/bin/python -m compileall -q -j 0 src controllers models >/dev/null 2>&1 || true
# The viewer check (tests/test_viewer_check.py) opens recordings in Rerun's web viewer in headless
# Chromium (Playwright drives the system's browser; it cannot download its own). Install Debian's
# package when it is missing and we may (root, apt-get); otherwise that test fails and says how.
if [ "$browser" = 1 ] && [ -z "${FSARM_CHROMIUM:-}" ] && [ ! -x /usr/bin/chromium ] && [ "$(id -u)" = 0 ] \
   && command -v apt-get >/dev/null 2>&1; then
  echo "Installing Debian's chromium for the viewer check (log: .venv/setup.log) ..."
  if ! { apt-get install -y chromium || { apt-get update && apt-get install -y chromium; }; } \
       >>.venv/setup.log 2>&1; then
    echo "could not install chromium (see .venv/setup.log): the viewer check will fail" >&2
  fi
fi
# The native callbacks as a prebuilt library (fsarm_sim.engine.native_lib): built once per kernel
# source and machine (about a minute), so later runs start without importing Numba. A failure
# leaves the Numba path in place.
if ! .venv/bin/python -c 'import sys; from fsarm_sim.engine import native_lib; sys.exit(native_lib.load() is None)' 2>/dev/null; then
  echo "Building the native callbacks library (once; log: .venv/setup.log) ..."
  MUJOCO_GL=disable .venv/bin/python -m fsarm_sim.engine.native_lib >>.venv/setup.log 2>&1 \
    || echo "note: the native callbacks library was not built (see .venv/setup.log); runs use Numba" >&2
fi
