"""Moved: the in-process comparison of a policy with obstacle_avoidance.py is a tool now,
`python -m m2wr_tools.batch.gym_evaluate` (scripts/m2wr_tools/batch/gym_evaluate.py, the same
options). This module only says so."""
import sys

if __name__ == "__main__":
    sys.exit("python -m m2wr_gym.evaluate has moved: run "
             "python -m m2wr_tools.batch.gym_evaluate with the same options")
