#!/usr/bin/env bash
# Runs every test suite: scripts/setup.sh (if anything is missing), then in the background the
# rostest suites of both workspaces through catkin and, beside them, the comparisons of
# lockstep with real-time runs followed by the batch runner's failure and cluster cases and
# the grader's fixture class; in the foreground the unit tests (pytest, no ROS master) and
# then the other integration tests (pytest: the batch runner, the grader, lockstep, the
# browser view). Results and logs go to test_results/.
# Exits non-zero when any test fails or a rostest crashed without writing its results, and
# ends with one line `N passed, N failed, N skipped`.
#
#   scripts/test.sh            everything (unit, rostest, integration)
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

# The rostests run at real time: they wait on the wall clock far more than they compute. The
# unit and batch tests are mostly lockstep runs, exact whatever the load, and compute all the
# time. So the rostests run in the background beside them, and the computing side runs at a
# lower priority (nice 10), so that the rostests' real-time simulators get the CPU when they
# need it. (Two computing streams side by side do not pay on 2 cores, and the real-time
# tests fail under that load.) The integration tests that compare lockstep with real-time runs
# wait on the wall clock too: a third stream, beside the rostests. It is done long before the
# other two, so the batch runner's failure and cluster cases and one of the grader's classes
# follow it there (niced as the foreground, so the real-time simulators still come first).
WALL_BOUND="$ROOT/scripts/test/integration/test_series_lockstep_vs_real_time.py"
BESIDE=(test_evaluate_failures.py test_evaluate_worker_lost.py test_evaluate_cluster.py
        test_grade_class.py::test_the_fixture_class_gets_the_grades_a_teacher_expects)
BESIDE=("${BESIDE[@]/#/$ROOT/scripts/test/integration/}")
# the foreground leaves them out: a file by --ignore, a single test by its (unique) name
NOT_IN_FOREGROUND=(--ignore="$WALL_BOUND")
single_tests=()
for t in "${BESIDE[@]}"; do
  case "$t" in *::*) single_tests+=("${t##*::}") ;; *) NOT_IN_FOREGROUND+=(--ignore="$t") ;; esac
done
if [ ${#single_tests[@]} -gt 0 ]; then
  expression="${single_tests[*]}"
  NOT_IN_FOREGROUND+=(-k "not (${expression// / or })")
fi
PYTEST=(python -m pytest -q -W error -p no:cacheprovider --import-mode=importlib)
# Each stream's ROS graphs on a loopback address of their own (m2wr_tools.running.session's
# loopback_host): a master calls the address of a node that was killed without unregistering
# when that node's topics change, and on one address the port may by then be another
# stream's node, which would connect to the wrong graph's publishers.
run_rostests() {
  export ROS_HOSTNAME=127.0.0.2
  for ws in simulation_ws catkin_ws; do
    echo "[rostest] $ws (catkin_make run_tests, one at a time)"
    (
      set +u; source "$ROOT/$ws/devel/setup.bash"; set -u
      export PATH="$ROOT/.venv/bin:$PATH"
      cd "$ROOT/$ws" && rm -rf build/test_results && catkin_make run_tests -j1 2>&1
    ) > "$RESULTS/$ws-run_tests.log"
    cp -r "$ROOT/$ws/build/test_results" "$RESULTS/$ws" 2>/dev/null || true
  done
}
run_wall_bound() {
  export ROS_HOSTNAME=127.0.0.3
  echo "[integration, real time] $WALL_BOUND"
  "${PYTEST[@]}" --basetemp="$RESULTS/wall-bound-tmp" --junitxml="$RESULTS/pytest-wall-bound.xml" \
    "$WALL_BOUND" > "$RESULTS/pytest-wall-bound.log" 2>&1
  local status=$?
  echo "[integration, beside] ${BESIDE[*]##*/}"
  nice -n 10 "${PYTEST[@]}" --basetemp="$RESULTS/beside-tmp" --junitxml="$RESULTS/pytest-beside.xml" \
    "${BESIDE[@]}" > "$RESULTS/pytest-beside.log" 2>&1 || status=1
  echo $status > "$RESULTS/pytest-wall-bound.status"
}
# one progress line per suite; the full output stays in the logs
rostest_lines() {
  for ws in simulation_ws catkin_ws; do
    [ -f "$RESULTS/$ws-run_tests.log" ] || continue
    echo "[test] rostest suites of $ws (log: test_results/$ws-run_tests.log)"
    grep -E "^-- run_tests.py: execute|^\[ROSTEST\]|^ *\[.*\]\[(passed|FAILURE|ERROR)\]|^SUMMARY|^ \* RESULT" \
      "$RESULTS/$ws-run_tests.log" | sed 's/^/    /'
  done
}

status=0
background_pids=()
stop_background() {
  for pid in "${background_pids[@]}"; do
    if kill -0 "$pid" 2>/dev/null; then
      kill -TERM -- "-$pid" 2>/dev/null
      wait "$pid" 2>/dev/null
    fi
  done
}
trap 'stop_background; echo; echo "[test] interrupted: every process it started is stopped"; exit 130' INT TERM

# each in its own process group (setsid), so that an interrupt stops all of it by its PID
start_background() {
  local fn="$1"
  setsid bash -c "$(declare -p ROOT RESULTS WALL_BOUND BESIDE PYTEST); $(declare -f "$fn"); $fn" \
    > "$RESULTS/background-$fn.log" 2>&1 < /dev/null &
  background_pids+=($!)
}
if [ "$mode" != "--unit" ]; then
  # catkin_make run_tests is called with other CMake arguments than setup.sh's build, so it
  # runs CMake again, which rewrites each workspace's devel/_setup_util.py and setup files:
  # done here, before the streams start, and not under a test that sources the workspace
  # (a batch test once failed on "can't open file .../catkin_ws/devel/_setup_util.py")
  for ws in simulation_ws catkin_ws; do
    (
      set +u; source "$ROOT/$ws/devel/setup.bash"; set -u
      export PATH="$ROOT/.venv/bin:$PATH"
      cd "$ROOT/$ws" && catkin_make -j1 tests 2>&1
    ) > "$RESULTS/$ws-configure.log" || { echo "[test] catkin_make in $ws failed: test_results/$ws-configure.log"; status=1; }
  done
  echo "[test] in the background (started now): the rostest suites of both workspaces; beside them $(basename "$WALL_BOUND")"
  start_background run_rostests
  start_background run_wall_bound
fi

echo "[test] unit tests (pytest, no ROS master)"
unit_dirs=()
for d in "$ROOT"/simulation_ws/src/*/test/unit "$ROOT"/catkin_ws/src/*/test/unit "$ROOT/scripts/test"; do
  [ -d "$d" ] && unit_dirs+=("$d")
done
nice -n 10 "${PYTEST[@]}" --junitxml="$RESULTS/pytest-unit.xml" \
  --ignore="$ROOT/scripts/test/integration" "${unit_dirs[@]}" || status=1

if [ "$mode" != "--unit" ]; then
  echo "[test] batch runner, grader, lockstep, browser (pytest: real Dask scheduler and workers, chromium)"
  nice -n 10 "${PYTEST[@]}" --basetemp="$RESULTS/batch-tmp" --junitxml="$RESULTS/pytest-batch.xml" \
    "${NOT_IN_FOREGROUND[@]}" "$ROOT/scripts/test/integration" || status=1
  for pid in "${background_pids[@]}"; do
    if kill -0 "$pid" 2>/dev/null; then
      echo "[test] waiting for the background tests (rostests, real-time comparisons)"
      break
    fi
  done
  for pid in "${background_pids[@]}"; do wait "$pid" 2>/dev/null; done
  background_pids=()
  rostest_lines
  echo "[test] $(basename "$WALL_BOUND") (log: test_results/pytest-wall-bound.log)"
  tail -n 3 "$RESULTS/pytest-wall-bound.log" 2>/dev/null | sed 's/^/    /'
  echo "[test] ${BESIDE[*]##*/} (log: test_results/pytest-beside.log)"
  tail -n 3 "$RESULTS/pytest-beside.log" 2>/dev/null | sed 's/^/    /'
  [ "$(cat "$RESULTS/pytest-wall-bound.status" 2>/dev/null)" = 0 ] || status=1
fi

python "$ROOT/scripts/summarize_test_results.py" "$RESULTS" || status=1
exit $status
