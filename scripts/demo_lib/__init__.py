"""Helpers of scripts/demo.py and scripts/bench.py, kept apart so they can be unit-tested:
processes (free port, process groups, orphan check), the ROS session both scripts run, the
run summary maths, the world's geometry at scan height and the robot's clearance, and the
top-down picture."""
