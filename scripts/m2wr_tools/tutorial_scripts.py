"""motion_plan's scripts (the tutorial's reading_laser.py and obstacle_avoidance.py, and
learned_avoidance.py) as Python modules, for code that calls their functions in this
process: gym_evaluate runs obstacle_avoidance.take_action() on each scan, and
motion_plan's unit tests call clbk_laser, take_action and the learned node's decisions.

They are scripts, not a package: each is found in motion_plan/scripts through rospkg (as
rosrun finds it; `source scripts/env.sh` first) and executed from its file as a fresh module,
registered nowhere (no sys.modules entry, no sys.path change) and without its main(): the
scripts run main() only under `if __name__ == '__main__'`. A fresh module each call, since
obstacle_avoidance keeps its publisher in a module global.
"""
import importlib.util
import os

from .paths import package_path

PACKAGE = "motion_plan"


def script_path(file_name):
    """motion_plan/scripts/`file_name`; FileNotFoundError naming the path when it is not there."""
    path = os.path.join(package_path(PACKAGE), "scripts", file_name)
    if not os.path.isfile(path):
        raise FileNotFoundError("tutorial script not found: %s" % path)
    return path


def load(file_name):
    """The script `file_name` (e.g. "obstacle_avoidance.py") executed as a new module."""
    path = script_path(file_name)
    spec = importlib.util.spec_from_file_location(os.path.splitext(file_name)[0], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
