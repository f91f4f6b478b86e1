# Source me: `source scripts/env.sh`
# Puts the project's venv (Debian's /usr/bin/python3 + pybullet) first on PATH and sources
# catkin_ws (which overlays simulation_ws), so roscore, roslaunch, rosrun and the tutorial's
# `#! /usr/bin/env python` scripts all run with Debian's rospy plus pybullet.
_m2wr_root="$(cd "$(dirname "${BASH_SOURCE[0]:-$0}")/.." && pwd)"
if [ ! -f "$_m2wr_root/catkin_ws/devel/setup.bash" ]; then
  echo "env.sh: $_m2wr_root/catkin_ws/devel/setup.bash not found; run scripts/setup.sh first" >&2
  return 1 2>/dev/null || exit 1
fi
# sourced from a function called without arguments: catkin's setup.sh would otherwise take
# the caller's own arguments (e.g. a script's --help) as its own
_m2wr_source() { source "$_m2wr_root/catkin_ws/devel/setup.bash"; }
_m2wr_source
unset -f _m2wr_source
export PATH="$_m2wr_root/.venv/bin:$PATH"
export VIRTUAL_ENV="$_m2wr_root/.venv"
# this checkout's tools first, whatever checkout the venv's editable install points to
export PYTHONPATH="$_m2wr_root/scripts${PYTHONPATH:+:$PYTHONPATH}"
# ROS stays on this machine unless the user already chose otherwise.
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://localhost:11311}"
export ROS_PYTHON_VERSION=3
export M2WR_ROOT="$_m2wr_root"
unset _m2wr_root
