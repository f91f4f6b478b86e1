#!/usr/bin/env bash
# Grades a class of motion_plan submissions on a spec's tasks (see m2wr_tools.grade.cli,
# scripts/m2wr_tools/grade/cli.py, or --help):
#   scripts/grade.sh CLASS_DIR [--spec SPEC] [--output DIR] [--scheduler ADDR] [--workers N]
#   scripts/grade.sh --replay STUDENT TASK RUN [--output DIR] [--gui]
# Runs scripts/setup.sh first unless the project is already set up, sources scripts/env.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

source "$ROOT/scripts/ensure_ready.sh" grade
exec python -m m2wr_tools.grade.cli "$@"
