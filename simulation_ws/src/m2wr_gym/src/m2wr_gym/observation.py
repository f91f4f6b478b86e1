"""Observations from a laser scan, shared by the environments and the ROS node
motion_plan/learned_avoidance.py (numpy only: no ROS, no pybullet, no torch).

- "regions": episode 4's five regions exactly as reading_laser.py computes them from m2wr's
  720 beams: min(min(ranges[a:b]), 10) over [0:143], [144:287], [288:431], [432:575],
  [576:713] (right, front-right, front, front-left, left) [m]; +inf (no return) gives 10.
- "scan": the ranges [m] with +inf (no return, REP 117) replaced by range_max, optionally
  downsampled by taking the minimum of each group of `downsample` consecutive beams (the
  nearest thing in each sector is kept, never skipped over).
- goal_in_robot_frame(): the goal (x, y) [m] in the robot's frame (x forward, y left)
  (goal_offset(): the same as two Python floats).
"""
import math

import numpy as np

REGION_SLICES = ((0, 143), (144, 287), (288, 431), (432, 575), (576, 713))  # reading_laser.py
REGION_CAP = 10.0           # [m] reading_laser.py's min(..., 10)
SCAN_BEAMS = 720            # m2wr's laser
KINDS = ("regions", "scan")
_REGION_BOUNDS = np.array([i for bounds in REGION_SLICES for i in bounds], dtype=np.intp)


def regions(ranges):
    """Episode 4's five regions [m], float32 (5,)."""
    ranges = np.asarray(ranges, dtype=np.float32)
    if ranges.shape != (SCAN_BEAMS,):
        raise ValueError("a scan of %d beams is needed for the five regions (m2wr's laser); "
                         "got %s" % (SCAN_BEAMS, ranges.shape))
    # one reduceat over the bounds [a0, b0, a1, b1, ...]: its even entries are the slices' minima
    return np.minimum(np.minimum.reduceat(ranges, _REGION_BOUNDS)[::2], np.float32(REGION_CAP))


def scan(ranges, range_max, downsample=1):
    """The scan [m], +inf -> range_max, min over groups of `downsample` beams, float32."""
    ranges = np.asarray(ranges, dtype=np.float32)
    if len(ranges) % downsample:
        raise ValueError("downsample=%d does not divide the scan's %d beams"
                         % (downsample, len(ranges)))
    # (a copy with putmask: the same array as np.where(np.isfinite(...), ranges, range_max),
    # ~3 us cheaper per step right after Bullet's physics has run)
    features = ranges.copy()
    np.putmask(features, ~np.isfinite(ranges), np.float32(range_max))
    return features if downsample == 1 else features.reshape(-1, downsample).min(axis=1)


def size(kind, downsample=1):
    """Length of the laser part of an observation."""
    return 5 if kind == "regions" else SCAN_BEAMS // downsample


def upper_bound(kind, range_max):
    return REGION_CAP if kind == "regions" else range_max


def laser_features(kind, ranges, range_max, downsample=1):
    """The laser part of an observation: float32, a new array on each call."""
    if kind == "regions":
        return regions(ranges)
    return scan(ranges, range_max, downsample)


def goal_in_robot_frame(goal, x, y, yaw):
    """(x, y) [m] of the goal in the frame of a robot at (x, y, yaw), float32 (2,)."""
    return np.array(goal_offset(goal, x, y, yaw), dtype=np.float32)


def goal_offset(goal, x, y, yaw):
    """goal_in_robot_frame as two Python floats (before the float32 rounding)."""
    dx, dy = goal[0] - x, goal[1] - y
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx + s * dy, -s * dx + c * dy
