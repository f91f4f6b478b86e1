#!/usr/bin/env bash
# Train a policy for m2wr with stable-baselines3 and export it for the ROS node:
#
#   scripts/train.sh [--task avoid|goal] [--world world02] [--timesteps N] [--envs 2] [--out DIR]
#   scripts/train.sh --help
#
# On first use installs the training extra (requirements-train.txt: torch CPU + SB3) into the
# project's venv. Writes DIR/policy.npz (numpy only: `rosrun motion_plan learned_avoidance.py
# _policy:=DIR/policy.npz`) and DIR/learning_curve.png; prints progress as it goes.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ ! -f "$ROOT/catkin_ws/devel/setup.bash" ]; then
  bash "$ROOT/scripts/setup.sh"
fi
set +u; source "$ROOT/scripts/env.sh"; set -u
if ! python -c "import torch, stable_baselines3" 2>/dev/null; then
  echo "[train] installing the training extra (requirements-train.txt: torch CPU, stable-baselines3)"
  python -m pip install -q --disable-pip-version-check -r "$ROOT/requirements-train.txt"
fi
exec python -m m2wr_gym.train "$@"
