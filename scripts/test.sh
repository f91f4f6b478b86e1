#!/usr/bin/env bash
# Runs every test suite: scripts/setup.sh (if anything is missing), the fast unit tests with
# pytest (no ROS master), then the rostest suites of both workspaces through catkin.
# Exits non-zero when any test fails or a rostest crashed without writing its results, and
# ends with one line `N passed, N failed, N skipped`.
#
#   scripts/test.sh            everything (unit, rostest, the batch runner's cluster tests)
#   scripts/test.sh --unit     only the pytest unit tests
#   scripts/test.sh --help     this text; sets up and runs nothing
#
# Exit status: 0 when every test passed; 1 when a test failed, a rostest crashed or the set-up
# failed; 2 for an unknown option.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RESULTS="$ROOT/test_results"
usage() { sed -n '2,/^set /{/^set /d;s/^# \{0,1\}//p}' "${BASH_SOURCE[0]}"; }
mode=all
for arg in "$@"; do
  case "$arg" in
    -h|--help) usage; exit 0 ;;
    --unit) mode=--unit ;;
    *) printf 'scripts/test.sh: unknown option %s\n\n' "$arg" >&2; usage >&2; exit 2 ;;
  esac
done

bash "$ROOT/scripts/setup.sh" || { echo "[test] setup failed; no test was run"; echo "0 passed, 1 failed"; exit 1; }
set +u; source "$ROOT/scripts/env.sh"; set -u
rm -rf "$RESULTS" && mkdir -p "$RESULTS"

status=0
echo "[test] unit tests (pytest, no ROS master)"
unit_dirs=()
for d in "$ROOT"/simulation_ws/src/*/test/unit "$ROOT"/catkin_ws/src/*/test/unit "$ROOT/scripts/test"; do
  [ -d "$d" ] && unit_dirs+=("$d")
done
python -m pytest -q -W error -p no:cacheprovider --import-mode=importlib --junitxml="$RESULTS/pytest-unit.xml" \
  --ignore="$ROOT/scripts/test/integration" "${unit_dirs[@]}" || status=1

if [ "$mode" != "--unit" ]; then
  for ws in simulation_ws catkin_ws; do
    echo "[test] rostest suites of $ws (catkin_make run_tests, one at a time)"
    source_ws() { source "$ROOT/$ws/devel/setup.bash"; }   # without this script's arguments
    set +u; source_ws; set -u
    export PATH="$ROOT/.venv/bin:$PATH"
    (cd "$ROOT/$ws" && rm -rf build/test_results && catkin_make run_tests -j1 2>&1) > "$RESULTS/$ws-run_tests.log"
    # one progress line per suite; the full output stays in the log
    grep -E "^-- run_tests.py: execute|^\[ROSTEST\]|^ *\[.*\]\[(passed|FAILURE|ERROR)\]|^SUMMARY|^ \* RESULT" \
      "$RESULTS/$ws-run_tests.log" | sed 's/^/    /'
    cp -r "$ROOT/$ws/build/test_results" "$RESULTS/$ws" 2>/dev/null || true
  done
  set +u; source "$ROOT/scripts/env.sh"; set -u
  echo "[test] batch runner (pytest: scripts/evaluate.sh on a real Dask scheduler and workers)"
  python -m pytest -q -W error -p no:cacheprovider --import-mode=importlib \
    --basetemp="$RESULTS/batch-tmp" --junitxml="$RESULTS/pytest-batch.xml" \
    "$ROOT/scripts/test/integration" || status=1
fi

python "$ROOT/scripts/summarize_test_results.py" "$RESULTS" || status=1
exit $status
