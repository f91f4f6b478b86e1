#!/usr/bin/env bash
# Train a policy for m2wr with stable-baselines3 and export it for the ROS node:
#
#   scripts/train.sh [--task avoid|goal] [--world world02] [--timesteps N] [--envs 2] [--out DIR]
#   scripts/train.sh --help
#
# On first use installs the training extra (requirements-train.txt: torch CPU + SB3) into the
# project's venv. Writes DIR/policy.npz (numpy only: `rosrun motion_plan learned_avoidance.py
# _policy:=DIR/policy.npz`), DIR/learning_curve.png, DIR/model.zip (SB3's, to go on training)
# and DIR/N.monitor.csv (episodes of environment N); prints progress as it goes.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
wants_help=false
for arg in "$@"; do
  case "$arg" in -h|--help) wants_help=true ;; esac
done
if $wants_help && [ ! -f "$ROOT/catkin_ws/devel/setup.bash" ]; then
  # nothing set up yet: this file's header, setting up nothing
  sed -n '2,/^set /{s/^# \{0,1\}//p}' "${BASH_SOURCE[0]}" | sed '/^set /d'
  exit 0
fi
source "$ROOT/scripts/ensure_ready.sh" train
# --help needs neither torch nor SB3 (train.py imports them only to train)
if ! $wants_help && ! python -c "import torch, stable_baselines3" 2>/dev/null; then
  echo "[train] installing the training extra (requirements-train.txt: torch CPU, stable-baselines3)"
  python -m pip install -q --disable-pip-version-check -r "$ROOT/requirements-train.txt"
fi
exec python -m m2wr_gym.train "$@"
