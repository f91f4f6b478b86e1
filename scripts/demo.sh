#!/usr/bin/env bash
# The tutorial's episode 5 in one command (the Docker image's default command):
#   scripts/demo.sh [--world world02] [--x 0 --y 8 --yaw 0] [--duration 120] [--seed 0]
#                   [--gui] [--realtime] [--bag] [--output output/]
# Runs scripts/setup.sh first unless the project is already set up (then silently), sources
# scripts/env.sh, and hands over to m2wr_tools.demo (scripts/m2wr_tools/demo.py; see its
# docstring, or --help).
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
  echo "demo: the project is not set up yet; running scripts/setup.sh" >&2
  bash "$ROOT/scripts/setup.sh" || { echo "demo: scripts/setup.sh failed (see above)" >&2; exit 1; }
fi

set +u
source "$ROOT/scripts/env.sh"
set -u
exec python -m m2wr_tools.demo "$@"
