"""The world seen from above, from the world file alone (no physics): each obstacle's
footprint where it can meet m2wr, the robot's own footprint, the clearance between them, and
free start poses.

- Footprints: every collision shape of a model that is not ground whose vertical extent meets
  the robot's height band [0, ROBOT_TOP] m, projected onto the ground plane: boxes (at any
  rotation) and tilted cylinders as convex polygons, upright cylinders and spheres as
  circles. Poses are the world file's (dynamic models pushed by the robot are not followed).
- The robot: m2wr's chassis and wheels, a rectangle FOOTPRINT_X x FOOTPRINT_Y [m] about its
  model frame (link_chassis); the caster is inside it.
- clearance(): smallest distance [m] between the robot's rectangle (sampled along its outline
  every ~2 cm) and the footprints; 0 when they overlap. Accurate to about 1 cm.
"""
import math

import numpy as np

from pybullet_gazebo.engine.specs import Box, Cylinder, Plane, Sphere
from pybullet_gazebo.engine.planar import convex_hull
from pybullet_gazebo.engine.transforms import rotation_matrix

ROBOT_TOP = 0.35                  # [m] top of m2wr's laser, with margin
FOOTPRINT_X = (-0.25, 0.25)       # [m] chassis, in the robot frame (x forward)
FOOTPRINT_Y = (-0.17, 0.17)       # [m] wheels' outer faces (y left)
ROBOT_RADIUS = math.hypot(0.25, 0.17)   # [m] circle around the footprint


class Footprints:
    """Obstacle footprints of a WorldSpec: `circles` (N, 3) rows x, y, r and `polygons`, a
    list of (K, 2) counter-clockwise vertex arrays, each with its model's name."""

    def __init__(self, spec):
        circles, polygons, self.circle_models, self.polygon_models = [], [], [], []
        for model in spec.models:
            for link in model.links:
                if all(isinstance(c.geometry, Plane) for c in link.collisions):
                    continue
                link_pose = model.pose.compose(link.pose)
                for collision in link.collisions:
                    shape = self._shape(link_pose.compose(collision.pose), collision.geometry)
                    if shape is None:
                        continue
                    kind, value = shape
                    if kind == "circle":
                        circles.append(value)
                        self.circle_models.append(model.name)
                    else:
                        polygons.append(np.array(value))
                        self.polygon_models.append(model.name)
        self.circles = np.array(circles, dtype=float).reshape(-1, 3)
        self.polygons = polygons
        # each polygon's bounding circle, to skip the far ones
        self._centres = np.array([p.mean(axis=0) for p in polygons]).reshape(-1, 2)
        self._radii = np.array([np.linalg.norm(p - c, axis=1).max()
                                for p, c in zip(polygons, self._centres)])
        corners = [p for p in polygons] + [np.array([[x - r, y - r], [x + r, y + r]])
                                           for x, y, r in self.circles]
        everything = np.concatenate(corners) if corners else np.zeros((1, 2))
        self.bounds = (everything.min(axis=0), everything.max(axis=0))   # [m] (x, y) low, high

    @staticmethod
    def _shape(pose, geometry):
        rotation = rotation_matrix(pose.orientation)
        centre = np.asarray(pose.position, dtype=float)
        if isinstance(geometry, Box):
            half = np.asarray(geometry.size, dtype=float) / 2.0
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            vertices = centre + (signs * half) @ rotation.T
        elif isinstance(geometry, Cylinder):
            axis = rotation[:, 2]
            if abs(axis[2]) > 0.999:                      # upright: a circle
                low, high = centre[2] - geometry.length / 2, centre[2] + geometry.length / 2
                if high < 0.0 or low > ROBOT_TOP:
                    return None
                return "circle", (centre[0], centre[1], geometry.radius)
            angles = np.linspace(0, 2 * math.pi, 24, endpoint=False)
            ring = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)
            ring = ring * geometry.radius @ rotation.T
            ends = [centre + axis * geometry.length / 2, centre - axis * geometry.length / 2]
            vertices = np.concatenate([ring + end for end in ends])
        elif isinstance(geometry, Sphere):
            if centre[2] + geometry.radius < 0.0 or centre[2] - geometry.radius > ROBOT_TOP:
                return None
            return "circle", (centre[0], centre[1], geometry.radius)
        else:                                             # meshes: not simulated either
            return None
        if vertices[:, 2].max() < 0.0 or vertices[:, 2].min() > ROBOT_TOP:
            return None
        return "polygon", convex_hull(vertices[:, :2], decimals=9)

    # --- distances ----------------------------------------------------------------------
    def distance(self, points, within=np.inf):
        """(M,) smallest distance [m] from each 2-D point to any footprint (0 inside one);
        footprints farther than `within` [m] from all the points may be skipped (inf then)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        best = np.full(len(points), np.inf)
        if len(self.circles):
            d = np.linalg.norm(points[:, None, :] - self.circles[None, :, :2], axis=2) \
                - self.circles[None, :, 2]
            best = np.minimum(best, np.maximum(d, 0.0).min(axis=1))
        centre = points.mean(axis=0)
        spread = np.linalg.norm(points - centre, axis=1).max()
        near = np.linalg.norm(self._centres - centre, axis=1) - self._radii - spread <= within
        for index in np.flatnonzero(near):
            best = np.minimum(best, _polygon_distance(points, self.polygons[index]))
        return best

    def clearance(self, x, y, yaw, within=np.inf):
        """Smallest distance [m] between m2wr's footprint at (x, y, yaw) and any obstacle
        footprint; 0 when they overlap; inf when nothing is within `within` [m]."""
        outline = robot_outline(x, y, yaw)
        inside = self._any_inside_robot(x, y, yaw)
        return 0.0 if inside else float(self.distance(outline, within).min())

    def _any_inside_robot(self, x, y, yaw):
        """An obstacle vertex or circle centre inside the robot's rectangle (an obstacle
        smaller than the robot that the outline's samples would miss)."""
        if not hasattr(self, "_vertices"):
            self._vertices = np.concatenate([p for p in self.polygons] + [self.circles[:, :2]])
        pts = self._vertices
        c, s = math.cos(yaw), math.sin(yaw)
        local = (pts - [x, y]) @ np.array([[c, -s], [s, c]])
        return bool(np.any((local[:, 0] > FOOTPRINT_X[0]) & (local[:, 0] < FOOTPRINT_X[1]) &
                           (local[:, 1] > FOOTPRINT_Y[0]) & (local[:, 1] < FOOTPRINT_Y[1])))

    def free_pose(self, rng, margin=0.5, attempts=10000):
        """A pose (x, y, yaw) drawn uniformly inside the obstacles' bounding box (shrunk by
        `margin`) whose robot circle is at least `margin` [m] from every footprint."""
        low, high = self.bounds[0] + margin, self.bounds[1] - margin
        needed = ROBOT_RADIUS + margin
        for _ in range(attempts):
            x, y = rng.uniform(low, high)
            # footprints farther than `needed` cannot refuse the pose: left out
            if self.distance([(x, y)], within=needed)[0] >= needed:
                return float(x), float(y), float(rng.uniform(-math.pi, math.pi))
        raise RuntimeError("no free start pose found in %d draws; the world is too full "
                           "for a random start: pass start=[(x, y, yaw), ...]" % attempts)


def robot_outline(x, y, yaw, spacing=0.02):
    """Points [m] every `spacing` along m2wr's footprint rectangle at pose (x, y, yaw)."""
    (x0, x1), (y0, y1) = FOOTPRINT_X, FOOTPRINT_Y
    nx, ny = int(math.ceil((x1 - x0) / spacing)), int(math.ceil((y1 - y0) / spacing))
    xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    local = np.concatenate([np.stack([xs, np.full_like(xs, y0)], 1),
                            np.stack([xs, np.full_like(xs, y1)], 1),
                            np.stack([np.full_like(ys, x0), ys], 1),
                            np.stack([np.full_like(ys, x1), ys], 1)])
    c, s = math.cos(yaw), math.sin(yaw)
    return local @ np.array([[c, s], [-s, c]]) + [x, y]


def _polygon_distance(points, polygon):
    """Distance [m] from points (M, 2) to a convex counter-clockwise polygon (K, 2); 0 inside."""
    a = polygon
    b = np.roll(polygon, -1, axis=0)
    edge = b - a                                                    # (K, 2)
    rel = points[:, None, :] - a[None, :, :]                        # (M, K, 2)
    length2 = np.maximum((edge ** 2).sum(axis=1), 1e-12)
    t = np.clip((rel * edge[None]).sum(axis=2) / length2[None], 0.0, 1.0)
    nearest = a[None] + t[..., None] * edge[None]
    d = np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)
    if len(polygon) >= 3:
        cross = edge[None, :, 0] * rel[..., 1] - edge[None, :, 1] * rel[..., 0]
        d[np.all(cross >= 0.0, axis=1)] = 0.0
    return d
