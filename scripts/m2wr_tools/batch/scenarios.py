"""A batch's runs: one Scenario per combination of world, start pose and seed, with the
batch's controller, task and duration, each with a stable id (resume and comparisons key on
it), and start poses from a list, a grid over free space or N random free poses.

Free space comes from the world file's geometry (scene.Scene outlines at scan height): a
start is free when the robot's centre is at least `margin` [m] from every obstacle's outline
and inside the obstacles' bounding box (the part of the world that has anything in it).
"""
from dataclasses import dataclass
import hashlib
import json
import math
from typing import List, Sequence, Tuple

import numpy as np

from ..analysis.metrics import Task

FREE_MARGIN = 0.6        # [m] m2wr's chassis and wheels reach ~0.3 m from its centre, plus room


@dataclass(frozen=True)
class Scenario:
    world: str
    x: float                 # [m]
    y: float                 # [m]
    yaw: float               # [rad]
    seed: int
    duration: float          # [s] of sim time
    controller: Tuple[str, ...]
    task: Task

    @property
    def run_id(self):
        """Readable and stable: the same scenario gets the same id on every machine."""
        digest = hashlib.sha1(json.dumps(self.as_dict(), sort_keys=True).encode()).hexdigest()
        return "%s_x%+.2f_y%+.2f_yaw%+.2f_s%d_%s" % (self.world_label, self.x, self.y, self.yaw,
                                                     self.seed, digest[:8])

    @property
    def world_label(self):
        base = self.world.rstrip("/").rsplit("/", 1)[-1]
        return base[:-len(".world")] if base.endswith(".world") else base

    def as_dict(self):
        return {"world": self.world, "x": self.x, "y": self.y, "yaw": self.yaw,
                "seed": self.seed, "duration": self.duration,
                "controller": list(self.controller), "task": self.task.as_dict()}

    @classmethod
    def from_dict(cls, data):
        return cls(world=data["world"], x=float(data["x"]), y=float(data["y"]),
                   yaw=float(data["yaw"]), seed=int(data["seed"]),
                   duration=float(data["duration"]), controller=tuple(data["controller"]),
                   task=Task.from_dict(data["task"]))


def combinations(worlds, starts_of_world, seeds, duration, controller, task) -> List[Scenario]:
    """Every (world, start, seed); `starts_of_world(world)` gives that world's (x, y, yaw)
    list. Sorted by world and seed, so a worker that gets consecutive runs can keep its
    simulator."""
    runs = []
    for world in worlds:
        for seed in seeds:
            for x, y, yaw in starts_of_world(world):
                runs.append(Scenario(world, float(x), float(y), float(yaw), int(seed),
                                     float(duration), tuple(controller), task))
    return runs


# --- free space ------------------------------------------------------------------------
def _point_polygon_distance(px, py, points):
    """Distance [m] from (px, py) to a convex polygon (0 inside)."""
    pts = np.asarray(points, dtype=float)
    a, b = pts, np.roll(pts, -1, axis=0)
    ab = b - a
    t = np.clip(((px - a[:, 0]) * ab[:, 0] + (py - a[:, 1]) * ab[:, 1])
                / np.maximum((ab * ab).sum(axis=1), 1e-12), 0.0, 1.0)
    nearest = a + t[:, None] * ab
    edge = float(np.min(np.hypot(nearest[:, 0] - px, nearest[:, 1] - py)))
    # inside a counter-clockwise convex polygon: left of every edge
    cross = ab[:, 0] * (py - a[:, 1]) - ab[:, 1] * (px - a[:, 0])
    return 0.0 if np.all(cross >= 0.0) else edge


def obstacle_distance(outlines, x, y):
    """Distance [m] from (x, y) to the nearest outline (scene.Outline), inf when none."""
    best = math.inf
    for outline in outlines:
        if outline.kind == "circle":
            d = max(0.0, math.hypot(x - outline.center[0], y - outline.center[1]) - outline.radius)
        else:
            d = _point_polygon_distance(x, y, outline.points)
        best = min(best, d)
    return best


def bounds(outlines):
    """(xmin, ymin, xmax, ymax) [m] of every outline."""
    xy = []
    for o in outlines:
        if o.kind == "circle":
            xy += [(o.center[0] - o.radius, o.center[1] - o.radius),
                   (o.center[0] + o.radius, o.center[1] + o.radius)]
        else:
            xy += list(o.points)
    xy = np.asarray(xy, dtype=float)
    return tuple(xy.min(axis=0)) + tuple(xy.max(axis=0))


def is_free(outlines, x, y, margin=FREE_MARGIN):
    box = bounds(outlines)
    inside = box[0] <= x <= box[2] and box[1] <= y <= box[3]
    return inside and obstacle_distance(outlines, x, y) >= margin


def grid_starts(outlines, step, yaw=0.0, margin=FREE_MARGIN) -> List[Tuple[float, float, float]]:
    """Free points of a grid with `step` [m] over the obstacles' bounding box, heading yaw."""
    if not step > 0:
        raise ValueError("the grid step must be > 0 m")
    x0, y0, x1, y1 = bounds(outlines)
    xs = np.arange(math.ceil(x0 / step) * step, x1 + 1e-9, step)
    ys = np.arange(math.ceil(y0 / step) * step, y1 + 1e-9, step)
    return [(round(float(x), 6), round(float(y), 6), yaw) for y in ys for x in xs
            if is_free(outlines, x, y, margin)]


def random_starts(outlines, count, seed, margin=FREE_MARGIN, attempts=None):
    """`count` free poses drawn uniformly (position over the bounding box, yaw in [-pi, pi))
    from numpy's generator seeded with `seed`: the same seed gives the same poses. At most
    `attempts` draws (default 200 a pose)."""
    rng = np.random.default_rng(seed)
    attempts = attempts or 200 * count
    x0, y0, x1, y1 = bounds(outlines)
    found = []
    for _ in range(attempts):
        if len(found) == count:
            break
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        yaw = rng.uniform(-math.pi, math.pi)
        if is_free(outlines, x, y, margin):
            found.append((round(float(x), 3), round(float(y), 3), round(float(yaw), 3)))
    if len(found) < count:
        raise ValueError("found only %d free start poses of %d asked in %d draws; ask for "
                         "fewer or a smaller margin" % (len(found), count, attempts))
    return found


def check_starts(outlines, starts: Sequence[Tuple[float, float, float]], margin=FREE_MARGIN):
    """ValueError naming the first start that is not free (inside or too close to an
    obstacle, or outside the world)."""
    for x, y, yaw in starts:
        if not is_free(outlines, x, y, margin):
            raise ValueError("start (%g, %g) is not free: %.2f m from the nearest obstacle "
                             "(at least %.2f m needed) or outside the world; pick another"
                             % (x, y, obstacle_distance(outlines, x, y), margin))
