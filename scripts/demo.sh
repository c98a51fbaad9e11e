#!/usr/bin/env bash
# Newcomer's main job: set up .venv, then run the fig14-sine tracking scenario and print metrics.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_env.sh --no-browser  # the browser is for the tests' viewer check only
export MUJOCO_GL="${MUJOCO_GL:-disable}"
exec .venv/bin/fsarm run fig14-sine --out runs --json runs/fig14-sine-summary.json "$@"
