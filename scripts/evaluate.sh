#!/usr/bin/env bash
# Evaluates a controller over many runs in parallel on Dask (see m2wr_tools.batch.evaluate,
# scripts/m2wr_tools/batch/evaluate.py, or --help):
#   scripts/evaluate.sh [--controller CMD|PATH] [--task wander|goal|wall] [--world W ...]
#                       [--start X Y YAW ... | --grid STEP | --random N] [--seeds S ...]
#                       [--duration 60] [--workers N | --scheduler tcp://HOST:PORT] [--bench]
# Runs scripts/setup.sh first unless the project is already set up, sources scripts/env.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

source "$ROOT/scripts/ensure_ready.sh" evaluate
exec python -m m2wr_tools.batch.evaluate "$@"
