#!/usr/bin/env bash
# The tutorial's episode 5 in one command (the Docker image's default command):
#   scripts/demo.sh [--world world02] [--x 0 --y 8 --yaw 0] [--duration 120] [--seed 0]
#                   [--gui] [--realtime] [--bag] [--output output/]
# Runs scripts/setup.sh first unless the project is already set up (then silently), sources
# scripts/env.sh, and hands over to m2wr_tools.demo (scripts/m2wr_tools/demo.py; see its
# docstring, or --help).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

source "$ROOT/scripts/ensure_ready.sh" demo
exec python -m m2wr_tools.demo "$@"
