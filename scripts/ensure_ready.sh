# Sourced by every entry script but test.sh (demo, evaluate, grade, bench, train; test.sh
# always runs setup.sh): sets the project up when it is not yet
# (the venv with the current requirements and the tools package, both workspaces built) by
# running scripts/setup.sh, then sources scripts/env.sh. Needs ROOT; $1 names the caller in
# messages.
_ready() {
  [ -x "$ROOT/.venv/bin/python" ] \
    && (cd / && "$ROOT/.venv/bin/python" -c "import m2wr_tools" 2>/dev/null) \
    && [ -f "$ROOT/simulation_ws/devel/setup.bash" ] && [ -f "$ROOT/catkin_ws/devel/setup.bash" ] \
    && [ "$(cat "$ROOT/.venv/.requirements.sha256" 2>/dev/null)" = \
         "$(sha256sum "$ROOT/requirements.txt" | cut -d' ' -f1)" ]
}
if ! _ready; then
  echo "$1: the project is not set up yet; running scripts/setup.sh" >&2
  bash "$ROOT/scripts/setup.sh" || { echo "$1: scripts/setup.sh failed (see above)" >&2; exit 1; }
fi
unset -f _ready
set +u
source "$ROOT/scripts/env.sh"
set -u
