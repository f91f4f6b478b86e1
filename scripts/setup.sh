#!/usr/bin/env bash
# One-command set-up on a fresh Debian 12 machine (root, or a user with sudo).
#
#   scripts/setup.sh          install what is missing, then build both catkin workspaces
#   scripts/setup.sh --help   this text; installs and builds nothing
#
# Steps: Debian's ROS 1 packages -> .venv from /usr/bin/python3 (--system-site-packages, so
# Debian's rospy stays importable) -> pinned PyPI packages and the tools package (scripts/,
# editable) -> catkin_make simulation_ws, then catkin_ws on top of it, and beside them the
# ray caster compiled (numba) -> the project byte-compiled. Idempotent: on a ready machine
# it only re-checks and re-runs the (incremental) catkin builds.
#
# Exit status: 0 when the project is ready; 1 when a step failed (the step is named); 2 for an
# unknown option.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage() { sed -n '2,/^set /{/^set /d;s/^# \{0,1\}//p}' "${BASH_SOURCE[0]}"; }
for arg in "$@"; do
  case "$arg" in
    -h|--help) usage; exit 0 ;;
    *) printf 'scripts/setup.sh: unknown option %s\n\n' "$arg" >&2; usage >&2; exit 2 ;;
  esac
done
VENV="$ROOT/.venv"
SYSTEM_PYTHON=/usr/bin/python3
STEP="start"

say()  { printf '[setup] %s\n' "$*"; }
fail() { printf '[setup] FAILED at step "%s": %s\n' "$STEP" "$*" >&2; exit 1; }
# what runs in the background (the catkin builds, numba's compile), stopped by PID with all
# its children when the set-up ends early (a failed step, Ctrl-C)
kernel_pid="" catkin_pid=""
stop_tree() { local child; for child in $(pgrep -P "$1"); do stop_tree "$child"; done; kill "$1" 2>/dev/null || true; }
trap 'rc=$?; for pid in $kernel_pid $catkin_pid; do stop_tree "$pid"; done; rm -f "${kernel_log:-}"; [ $rc -eq 0 ] || printf "[setup] FAILED at step \"%s\" (exit %d); see the output above\n" "$STEP" "$rc" >&2' EXIT

# Debian's ROS 1 packages (Noetic-era ros_comm 1.15) the project needs at run, build and test time.
APT_PACKAGES=(
  python3-venv python3-pip cmake g++ make
  catkin python3-catkin-pkg ros-message-generation ros-message-runtime python3-genpy
  ros-std-msgs libstd-msgs-dev python3-std-msgs ros-geometry-msgs libstd-srvs-dev python3-std-srvs
  libgeometry-msgs-dev python3-geometry-msgs libsensor-msgs-dev python3-sensor-msgs
  libnav-msgs-dev python3-nav-msgs python3-rosgraph-msgs python3-tf2-ros python3-tf2-msgs
  python3-rospy python3-rostest python3-rosunit librostest-dev python3-roslaunch
  python3-rosmaster rosout rosbash python3-rostopic python3-rosservice python3-rosnode
  python3-rosparam python3-rosmsg python3-rosbag ros-robot-state-publisher
  # what programs written for Gazebo import or run beside it: tf (the series' later
  # programs: `from tf import transformations`), joint_state_publisher, tf2_tools (view_frames)
  python3-tf joint-state-publisher tf2-tools
  # gazebo_msgs' SetJointTrajectory; Gazebo's physics dynamic_reconfigure server
  ros-trajectory-msgs libtrajectory-msgs-dev python3-trajectory-msgs python3-dynamic-reconfigure
  # a real window for the GUI's tests on a machine with no display (Xvfb)
  xvfb
  # rviz on m2wr (m2wr_description's rviz.launch, launch_world.launch rviz:=true), and its
  # Python bindings, through which the rviz rostest reads the Displays panel (RobotModel OK)
  rviz python3-rviz
  # the grader's report opened in a real browser by its test (headless, through Playwright)
  chromium
  # the browser view (web:=true, replays): three.js r111 with its classic-script loaders and
  # OrbitControls (a replay opens from file://, where ES modules cannot load), and aiohttp,
  # the HTTP + WebSocket server of the simulator's page
  libjs-three python3-aiohttp
)

STEP="check machine"
[ -x "$SYSTEM_PYTHON" ] || fail "$SYSTEM_PYTHON not found; this script is for Debian 12 (bookworm)"
command -v dpkg-query >/dev/null || fail "dpkg-query not found; this script is for Debian 12 (bookworm)"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || fail "run as root or install sudo"
  SUDO="sudo"
fi

STEP="Debian packages"
# one dpkg-query for all of them (one per package took ~5 s); a package it does not know
# is missing too. dpkg-query exits 1 when any package was never installed, which is what a
# fresh machine has: its status is not a failure here (pipefail would make it one)
installed=" $( { dpkg-query -W -f='${Package} ${Status}\n' "${APT_PACKAGES[@]}" 2>/dev/null || true; } \
  | awk '$NF == "installed" && $(NF-1) == "ok" {printf "%s ", $1}')"
missing=()
for pkg in "${APT_PACKAGES[@]}"; do
  [[ "$installed" == *" $pkg "* ]] || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
  say "1/4 Debian packages: all ${#APT_PACKAGES[@]} present"
else
  say "1/4 Debian packages: installing ${#missing[@]} missing: ${missing[*]}"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

STEP="virtual environment"
if [ -x "$VENV/bin/python" ] && grep -q "^home = /usr/bin$" "$VENV/pyvenv.cfg" 2>/dev/null \
   && grep -q "^include-system-site-packages = true$" "$VENV/pyvenv.cfg"; then
  say "2/4 virtual environment: $VENV ready"
else
  say "2/4 virtual environment: creating $VENV from $SYSTEM_PYTHON (--system-site-packages)"
  rm -rf "$VENV"
  "$SYSTEM_PYTHON" -m venv --system-site-packages "$VENV"
fi

export PATH="$VENV/bin:$PATH"        # catkin_make must find the venv's python3, not pyenv's
unset PYTHONPATH CMAKE_PREFIX_PATH ROS_PACKAGE_PATH

STEP="PyPI packages"
stamp="$VENV/.requirements.sha256"
want="$(sha256sum "$ROOT/requirements.txt" | cut -d' ' -f1)"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  say "3/4 PyPI packages: requirements.txt unchanged since last install"
else
  say "3/4 PyPI packages: installing requirements.txt (pybullet is a ~100 MB wheel)"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r "$ROOT/requirements.txt"
  "$VENV/bin/python" -c "import rospy, pybullet, numpy, numba, xacro" \
    || fail "the venv cannot import rospy, pybullet, numpy, numba and xacro together"
  echo "$want" > "$stamp"
fi

STEP="tools package"
# m2wr_tools (scripts/m2wr_tools) installed editable, so every venv python imports it; checked
# from / so that the current folder cannot stand in for the installed package
tools_at="$(cd / && "$VENV/bin/python" -c \
  "import os, m2wr_tools; print(os.path.dirname(os.path.abspath(m2wr_tools.__file__)))" 2>/dev/null || true)"
if [ "$tools_at" = "$ROOT/scripts/m2wr_tools" ]; then
  say "3/4 tools package: m2wr_tools installed (editable)"
else
  say "3/4 tools package: installing scripts/ (m2wr_tools) editable into the venv"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps \
    --no-build-isolation -e "$ROOT/scripts" \
    || fail "pip could not install scripts/ (m2wr_tools) into the venv"
fi

STEP="lockstep hook"
# Every interpreter of the venv loads lockstep's handshake into rospy once a program imports it
# (simulation_ws/src/pybullet_gazebo/src/pybullet_gazebo/ros/lockstep/autoload.py): the
# tutorial's and the series' programs report to the simulator unchanged. Outside the project's
# environment (no catkin workspace on PYTHONPATH) the line does nothing.
site="$("$VENV/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")"
hook="import os; os.environ.get('LOCKSTEP_HANDSHAKE', 'on') == 'off' or exec('try:\\n import pybullet_gazebo.ros.lockstep.autoload\\nexcept ImportError:\\n pass')"
if [ "$(cat "$site/m2wr_lockstep.pth" 2>/dev/null)" != "$hook" ]; then
  say "3/4 lockstep hook: writing $site/m2wr_lockstep.pth"
  printf '%s\n' "$hook" > "$site/m2wr_lockstep.pth"
fi

# catkin builds, in the background (their failures are told when they are awaited, at STEP
# "catkin build" below). They need Debian's catkin and the venv's interpreter, none of the
# PyPI packages, but they start only once pip is done with the venv: their generators run that
# interpreter, which sees the venv's packages, and one imported while pip was still writing
# it (PyYAML, pulled in by distributed) died of a bus error in a fresh clone.
build_ws() {
  local ws="$1"
  say "3/4 catkin_make $ws"
  (cd "$ROOT/$ws" && catkin_make -DPYTHON_EXECUTABLE="$VENV/bin/python3" \
      -DCATKIN_ENABLE_TESTING=ON > "$ROOT/$ws/build.log" 2>&1) \
    || { tail -n 40 "$ROOT/$ws/build.log" >&2; say "catkin_make in $ws failed; full log: $ws/build.log" >&2; return 1; }
}
build_workspaces() {
  build_ws simulation_ws || return 1
  # catkin_ws overlays simulation_ws, as in the tutorial's environment where both are sourced.
  set +u; source "$ROOT/simulation_ws/devel/setup.bash"; set -u
  build_ws catkin_ws
}
build_workspaces &
catkin_pid=$!

# numba compiles the laser's inner loop once and caches it beside its source; doing it here
# keeps that second out of the first simulator start. It needs the engine's source and numba,
# not the build, so it may end before the builds.
kernel_log="$(mktemp)"                # removed by the EXIT trap, whichever way the set-up ends
PYTHONPATH="$ROOT/simulation_ws/src/pybullet_gazebo/src" "$VENV/bin/python" -c \
  "from pybullet_gazebo.engine import ray_kernel; print('%.1f' % ray_kernel.warm_up())" \
  > "$kernel_log" 2>&1 &
kernel_pid=$!
STEP="catkin build"
catkin_status=0; wait "$catkin_pid" || catkin_status=$?; catkin_pid=""
[ "$catkin_status" -eq 0 ] || fail "catkin_make failed (its output above)"

STEP="ray caster compile"
kernel_status=0; wait "$kernel_pid" || kernel_status=$?; kernel_pid=""
if [ "$kernel_status" -ne 0 ]; then
  cat "$kernel_log" >&2
  fail "numba could not compile pybullet_gazebo/engine/ray_kernel.py (error above)"
fi
say "4/4 ray caster compiled or loaded from numba's cache in $(tail -n 1 "$kernel_log") s"

STEP="byte-compile"
# Every node, tool and test is a new Python process that imports the simulator and the tools.
# Where PYTHONDONTWRITEBYTECODE is set (as on some CI machines), Python never keeps what it
# compiles, and each of those processes would compile ~20,000 lines again at start; so they
# are compiled once here (compileall writes whatever that variable says; a source edited
# later is simply compiled again in memory until the next set-up).
libraries=("$ROOT/scripts/m2wr_tools" "$ROOT"/simulation_ws/src/*/src "$ROOT"/catkin_ws/src/*/src
           "$ROOT"/simulation_ws/devel/lib/python3/dist-packages "$ROOT"/catkin_ws/devel/lib/python3/dist-packages)
existing=()
for dir in "${libraries[@]}"; do [ -d "$dir" ] && existing+=("$dir"); done
"$VENV/bin/python" -m compileall -q -j 0 "${existing[@]}" > /dev/null \
  || fail "byte-compiling the project's Python packages failed (a syntax error? run: $VENV/bin/python -m compileall ${existing[*]})"
say "4/4 Python packages byte-compiled (${#existing[@]} folders)"

STEP="done"
say "ready: run 'source scripts/env.sh' to use roscore, roslaunch and rosrun"
