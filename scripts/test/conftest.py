"""Makes scripts/ (demo_lib, demo.py, bench.py) and the engine importable for the tests of
scripts/test, whether or not scripts/env.sh was sourced."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
for path in (os.path.join(ROOT, "scripts"),
             os.path.join(ROOT, "simulation_ws", "src", "pybullet_gazebo", "src")):
    if path not in sys.path:
        sys.path.insert(0, path)
