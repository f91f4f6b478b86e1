"""A batch run's metrics from plain recorded data (no ROS, no pybullet), and whether the run
met its task.

Inputs: the robot's track (sim time [s], x [m], y [m], yaw [rad]) from /odom, clipped to
the run's [0, duration]; the sets of (robot, model) pairs in contact from /gazebo/contacts
(sim time, pairs); per-pose clearances [m] from scene.Scene.clearance.

Tasks (Task.kind):
  wander  drive for the whole duration without touching anything: success = no contact and
          at least `min_distance` [m] travelled
  goal    reach (goal_x, goal_y) within `tolerance` [m] before the duration ends: success =
          reached; the time to goal is the first sim time within the tolerance
  wall    follow a wall: success = no contact, `min_distance` travelled, and at least
          `wall_fraction` of the time with the nearest obstacle between wall_near and
          wall_far [m] of the robot's body
"""
from dataclasses import asdict, dataclass
import math
from typing import Optional, Sequence, Tuple

import numpy as np

TASKS = ("wander", "goal", "wall")


@dataclass(frozen=True)
class Task:
    kind: str = "wander"
    goal: Optional[Tuple[float, float]] = None   # [m], goal task only
    tolerance: float = 0.3                       # [m] goal reached within this
    min_distance: float = 1.0                    # [m] wander/wall: a robot that stays put fails
    wall_near: float = 0.2                       # [m] wall task: band of clearance to the wall
    wall_far: float = 1.5                        # [m]
    wall_fraction: float = 0.5                   # wall task: share of time within the band

    def __post_init__(self):
        if self.kind not in TASKS:
            raise ValueError("task '%s' is unknown; pass one of %s" % (self.kind, ", ".join(TASKS)))
        if self.kind == "goal" and self.goal is None:
            raise ValueError("the goal task needs a goal: pass --goal X Y [m]")
        if self.tolerance <= 0 or self.min_distance < 0 or not 0 <= self.wall_near < self.wall_far:
            raise ValueError("task limits must be tolerance > 0, min_distance >= 0 and "
                             "0 <= wall_near < wall_far")

    def as_dict(self):
        data = asdict(self)
        data["goal"] = list(self.goal) if self.goal is not None else None
        return data

    @classmethod
    def from_dict(cls, data):
        data = dict(data)
        if data.get("goal") is not None:
            data["goal"] = tuple(data["goal"])
        return cls(**data)


def clip_track(track, duration):
    """Rows of `track` (n, k) whose sim time (column 0) lies in [0, duration]."""
    track = np.asarray(track, dtype=float)
    if track.size == 0:
        return track.reshape(0, track.shape[1] if track.ndim == 2 else 4)
    keep = (track[:, 0] >= -1e-9) & (track[:, 0] <= duration + 1e-9)
    return track[keep]


def decimate(track, period):
    """Rows of `track` at least `period` [s] of sim time apart (the first and last kept)."""
    track = np.asarray(track, dtype=float)
    if len(track) <= 2:
        return track
    keep, last = [0], track[0, 0]
    for i in range(1, len(track) - 1):
        if track[i, 0] - last >= period - 1e-9:
            keep.append(i)
            last = track[i, 0]
    keep.append(len(track) - 1)
    return track[keep]


def distance_travelled(xy) -> float:
    """Length of the polyline through the (n, 2) positions [m]: the distance a run travelled
    (the demo's summary, a batch run's record)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    return float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) >= 2 else 0.0


def contact_figures(updates: Sequence[Tuple[float, Sequence]], duration):
    """(contact events, time in contact [s]) from successive contact sets in time order: an
    event is a (robot, model) pair that starts touching; time in contact runs from a message
    with any pair to the next message (the last one to `duration`). Updates outside [0,
    duration] are ignored."""
    updates = [(t, set(map(tuple, pairs))) for t, pairs in updates if 0.0 <= t <= duration]
    events, before, touching = 0, set(), 0.0
    for i, (t, pairs) in enumerate(updates):
        events += len(pairs - before)
        before = pairs
        if pairs:
            t_next = updates[i + 1][0] if i + 1 < len(updates) else duration
            touching += max(0.0, t_next - t)
    return events, touching


def stuck_time(track, window=5.0, radius=0.2):
    """Sim time [s] the robot spent stuck: a stretch between two samples counts when every
    position of the `window` [s] before its end lies within `radius` [m] of that end (it may
    turn on the spot or rock; it does not get anywhere). track: (n, >=3) t, x, y, in time
    order. Every window at once: (samples x longest window) distances, in chunks."""
    track = np.asarray(track, dtype=float)
    if len(track) < 2:
        return 0.0
    t, xy = track[:, 0], track[:, 1:3]
    ends = np.nonzero(t - t[0] >= window - 1e-9)[0]
    ends = ends[ends >= 1]
    if not len(ends):
        return 0.0
    starts = np.searchsorted(t, t[ends] - window - 1e-9, side="left")
    longest = int((ends - starts).max()) + 1
    stuck = np.zeros(len(ends), dtype=bool)
    chunk = max(1, 2_000_000 // longest)
    for a in range(0, len(ends), chunk):
        end, start = ends[a:a + chunk], starts[a:a + chunk]
        index = end[:, None] - np.arange(longest)[None, :]       # the end first, back in time
        inside = index >= start[:, None]
        span = xy[np.maximum(index, 0)] - xy[end][:, None, :]
        far = np.hypot(span[..., 0], span[..., 1]) > radius
        stuck[a:a + chunk] = ~(far & inside).any(axis=1)
    total = 0.0
    for i in ends[stuck]:                 # summed in time order, as sample by sample
        total += t[i] - t[i - 1]
    return float(total)


def time_to_goal(track, goal, tolerance):
    """First sim time [s] the robot is within `tolerance` [m] of `goal`, or None."""
    track = np.asarray(track, dtype=float)
    if not len(track):
        return None
    near = np.hypot(track[:, 1] - goal[0], track[:, 2] - goal[1]) <= tolerance
    return float(track[np.argmax(near), 0]) if near.any() else None


def fraction_within(values, low, high):
    """Share of `values` in [low, high] (0 for none)."""
    values = np.asarray(values, dtype=float)
    return float(((values >= low) & (values <= high)).mean()) if len(values) else 0.0


def judge(task: Task, distance_m, contact_events, goal_time, wall_share):
    """(success, reason): what the run achieved against its task, in words."""
    if task.kind == "goal":
        if goal_time is None:
            return False, "did not reach the goal (%.2f, %.2f) within %.2f m" % (
                task.goal[0], task.goal[1], task.tolerance)
        return True, "reached the goal at %.2f s" % goal_time
    if contact_events:
        return False, "touched an obstacle (%d contact events)" % contact_events
    if distance_m < task.min_distance:
        return False, "travelled %.2f m, under the %.2f m asked" % (distance_m, task.min_distance)
    if task.kind == "wall" and wall_share < task.wall_fraction:
        return False, "near a wall (%.1f-%.1f m) %.0f %% of the time, under %.0f %%" % (
            task.wall_near, task.wall_far, 100 * wall_share, 100 * task.wall_fraction)
    return True, "no contact, %.2f m travelled" % distance_m


def finite_or_none(value):
    return value if value is not None and math.isfinite(value) else None
