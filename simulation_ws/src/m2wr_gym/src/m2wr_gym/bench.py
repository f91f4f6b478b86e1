"""Moved: the environments' speed figures are a tool now, `python -m m2wr_tools.bench.gym`
(scripts/m2wr_tools/bench/gym.py, the same options). This module only says so."""
import sys

if __name__ == "__main__":
    sys.exit("python -m m2wr_gym.bench has moved: run "
             "python -m m2wr_tools.bench.gym with the same options")
