#!/usr/bin/env bash
# Evaluates a controller over many runs in parallel on Dask (see m2wr_tools.evaluate,
# scripts/m2wr_tools/evaluate.py, or --help):
#   scripts/evaluate.sh [--controller CMD|PATH] [--task wander|goal|wall] [--world W ...]
#                       [--start X Y YAW ... | --grid STEP | --random N] [--seeds S ...]
#                       [--duration 60] [--workers N | --scheduler tcp://HOST:PORT] [--bench]
# Runs scripts/setup.sh first unless the project is already set up, sources scripts/env.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

ready() {   # the venv with the current requirements and the tools package, both workspaces built
  [ -x "$ROOT/.venv/bin/python" ] \
    && (cd / && "$ROOT/.venv/bin/python" -c "import m2wr_tools" 2>/dev/null) \
    && [ -f "$ROOT/simulation_ws/devel/setup.bash" ] && [ -f "$ROOT/catkin_ws/devel/setup.bash" ] \
    && [ "$(cat "$ROOT/.venv/.requirements.sha256" 2>/dev/null)" = \
         "$(sha256sum "$ROOT/requirements.txt" | cut -d' ' -f1)" ]
}
if ! ready; then
  echo "evaluate: the project is not set up yet; running scripts/setup.sh" >&2
  bash "$ROOT/scripts/setup.sh" || { echo "evaluate: scripts/setup.sh failed (see above)" >&2; exit 1; }
fi

set +u
source "$ROOT/scripts/env.sh"
set -u
exec python -m m2wr_tools.evaluate "$@"
