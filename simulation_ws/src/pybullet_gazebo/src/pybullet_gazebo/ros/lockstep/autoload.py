"""Loads lockstep's rospy hooks (rospy_hooks.py) into a Python process as rospy is imported,
and quick_exit's (rospy's shutdown without its half-second wait: runs start and stop many
controllers).

scripts/setup.sh puts a .pth file into the project's venv that imports this module at every
interpreter start (`source scripts/env.sh`, roslaunch, rosrun, the batch runner, the grader's
users all run that interpreter). Until a program imports rospy it costs one entry on
sys.meta_path: programs that never use ROS are not touched, and a controller's own code is
never changed. LOCKSTEP_HANDSHAKE=off leaves rospy alone (the process is then waited for as
an uninstrumented one).
"""
import importlib.util
import os
import sys


class _AfterRospy:
    """Finds rospy with the other finders and installs the hooks once it has loaded (a
    finder on sys.meta_path needs only find_spec)."""

    def find_spec(self, name, path=None, target=None):
        if name != "rospy":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None:
            return spec
        load = spec.loader.exec_module

        def exec_module(module):
            load(module)
            try:
                from pybullet_gazebo.ros.lockstep import rospy_hooks
                rospy_hooks.install()
            except ImportError:         # a workspace without lockstep_msgs built: no hooks
                pass
            from pybullet_gazebo.ros import quick_exit
            quick_exit.install()
        spec.loader.exec_module = exec_module
        return spec


if os.environ.get("LOCKSTEP_HANDSHAKE", "on") != "off" and "rospy" not in sys.modules:
    sys.meta_path.insert(0, _AfterRospy())
