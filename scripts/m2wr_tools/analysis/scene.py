"""The demo's world, offline: the engine loads the world file and the robot's URDF into a
pybullet client in DIRECT mode (no ROS), to draw the obstacles at scan height and to measure
how close the robot came to them.

- `outlines(z)`: each obstacle's collision shapes cut by the horizontal plane at height z [m]
  (boxes, at any rotation, give convex polygons - rotated rectangles when upright; upright
  cylinders give circles; spheres give circles; tilted cylinders give polygons).
- `clearance(poses)`: for each pose of the robot's model frame (link_chassis, as /odom
  reports it), the smallest distance [m] between the robot's collision shapes and any
  model other than the ground (negative = penetration), with pybullet's getClosestPoints.
  The wheels' ground-contact spheres the engine adds (they touch only the ground) are left
  out. `nearest(poses)`: the closest pose alone, measuring only the poses that could be it
  (a bound from the bodies' and the robot's bounding boxes prunes the rest).
- `frame_pose(robot_pose, link)`: world pose of a robot link (e.g. the laser's frame) when
  the robot's model frame is at `robot_pose`.
"""
from dataclasses import dataclass
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np
import pybullet
from pybullet_gazebo.engine.client import Client

from pybullet_gazebo.engine import wheel_contact
from pybullet_gazebo.engine.planar import convex_hull
from pybullet_gazebo.engine.sdf_world import load_world
from pybullet_gazebo.engine.transforms import Pose, rotation_matrix
from pybullet_gazebo.engine.world import World

from ..names import ROBOT

SCAN_HEIGHT = 0.15           # [m] m2wr's laser plane above the ground, where obstacles are cut
_PRISM_SIDES = 48            # a tilted cylinder is cut as this many-sided prism
_FAR = 1.0e3                 # [m] the robot waits here until placed
_BOUND_SLACK = 0.02          # [m] bounds are lowered by this much (rounding; the boxes
                             # Bullet gives already hold its collision margins)


@dataclass(frozen=True)
class Outline:
    """An obstacle's cut at one height: a circle (center, radius) or a convex polygon."""
    model: str
    kind: str                                   # "circle" | "polygon"
    center: Tuple[float, float] = (0.0, 0.0)    # [m], circles
    radius: float = 0.0                         # [m], circles
    points: Tuple[Tuple[float, float], ...] = ()  # [m], polygons, counter-clockwise


@dataclass(frozen=True)
class Clearance:
    distance: float          # [m] smallest robot-obstacle distance; < 0 = penetration
    model: str               # the obstacle it was to ("" when none within max_distance)
    index: int               # which pose


def cut_convex(vertices, z) -> List[Tuple[float, float]]:
    """The cut of the convex hull of 3-D `vertices` (n, 3) by the plane at height z: a
    counter-clockwise polygon, or [] when the plane misses it. Every segment between two
    vertices is intersected with the plane; the edges' crossings span the cut and the other
    segments' crossings lie inside it, so the hull of all crossings is the cut."""
    v = np.asarray(vertices, dtype=float).reshape(-1, 3)
    i, j = np.triu_indices(len(v), k=1)
    a, b = v[i], v[j]
    da, db = a[:, 2] - z, b[:, 2] - z
    crossing = (da * db <= 0.0) & (da != db)
    t = da[crossing] / (da[crossing] - db[crossing])
    hits = a[crossing, :2] + t[:, None] * (b[crossing, :2] - a[crossing, :2])
    on_plane = v[np.abs(v[:, 2] - z) < 1e-12, :2]
    hull = convex_hull(np.vstack([hits, on_plane]) if len(on_plane) else hits)
    return hull if len(hull) >= 3 else []


def box_vertices(position, rotation, size):
    """The 8 corners (8, 3) of a box with full extents `size` at a world pose."""
    half = np.asarray(size, dtype=float) / 2.0
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return np.asarray(position) + (signs * half) @ np.asarray(rotation).T


def cut_cylinder(position, rotation, radius, length, z, model) -> Optional[Outline]:
    """A cylinder (axis = its local z) cut at height z: a circle when upright, else the cut
    of a prism with _PRISM_SIDES sides around the axis; None when the plane misses it."""
    rotation = np.asarray(rotation, dtype=float)
    axis = rotation[:, 2]
    if abs(axis[2]) > 1.0 - 1e-9:                   # upright: a circle or nothing
        if abs(z - position[2]) <= length / 2.0:
            return Outline(model, "circle", (float(position[0]), float(position[1])),
                           float(radius))
        return None
    angles = np.linspace(0.0, 2.0 * math.pi, _PRISM_SIDES, endpoint=False)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros_like(angles)], 1)
    local = np.vstack([ring + [0, 0, -length / 2.0], ring + [0, 0, length / 2.0]])
    polygon = cut_convex(np.asarray(position) + local @ rotation.T, z)
    return Outline(model, "polygon", points=tuple(polygon)) if polygon else None


def cut_sphere(position, radius, z, model) -> Optional[Outline]:
    dz = z - position[2]
    if abs(dz) >= radius:
        return None
    return Outline(model, "circle", (float(position[0]), float(position[1])),
                   math.sqrt(radius * radius - dz * dz))


class Scene:
    """A world file and the robot, loaded by the engine in a DIRECT pybullet client."""

    def __init__(self, world_path, model_path, urdf_xml, robot=ROBOT):
        self.spec = load_world(world_path, model_path)
        self.client = Client(connection_mode=pybullet.DIRECT)
        self.warnings = []
        self.world = World(self.client, self.spec, self.spec.physics.max_step_size or 0.001,
                           warn=self.warnings.append)
        self.robot_name = robot
        self.robot = self.world.spawn_urdf(robot, urdf_xml, Pose((0.0, 0.0, _FAR)))
        self._contact_links = {index for name, index in self.robot.links.items()
                               if name.endswith(wheel_contact.SUFFIX)}
        self._corners = None

    @classmethod
    def of_world(cls, world, urdf_xml=None):
        """The scene of `world` (world01, world02 or a .world path) with m2wr (the URDF
        xacro makes from m2wr_description, unless `urdf_xml` is given)."""
        from .. import paths
        return cls(paths.world_path(world), paths.model_path(),
                   urdf_xml if urdf_xml is not None else paths.robot_urdf())

    def close(self):
        try:
            self.client.disconnect()
        except pybullet.error:
            pass

    def obstacles(self):
        """Names of the models other than the ground and the robot."""
        return [name for name, e in self.world.entities.items()
                if not e.is_ground and e.robot is None]

    def set_model_poses(self, poses):
        """Moves world models to {name: Pose} (e.g. where the simulator left them); names the
        scene does not have are returned, not raised."""
        unknown = []
        for name, pose in poses.items():
            if name in self.world.entities and name != self.robot_name:
                self.world.set_model_state(name, pose)
            elif name != self.robot_name:
                unknown.append(name)
        return unknown

    # --- drawing ----------------------------------------------------------------------
    def outlines(self, z=0.15) -> List[Outline]:
        """Every obstacle's collision shapes cut at height z [m]."""
        result = []
        client = self.client
        for name in self.obstacles():
            entity = self.world.entities[name]
            for body, shapes in zip(entity.body_ids, entity.shapes):
                base_position, base_orientation = client.getBasePositionAndOrientation(body)
                base = Pose(tuple(base_position), tuple(base_orientation))
                for geometry, dims, local_position, local_orientation in shapes:
                    shape = base.compose(Pose(tuple(local_position), tuple(local_orientation)))
                    position, rotation = np.asarray(shape.position), rotation_matrix(shape.orientation)
                    outline = None
                    if geometry == pybullet.GEOM_BOX:
                        polygon = cut_convex(box_vertices(position, rotation, dims[:3]), z)
                        if polygon:
                            outline = Outline(name, "polygon", points=tuple(polygon))
                    elif geometry == pybullet.GEOM_CYLINDER:
                        outline = cut_cylinder(position, rotation, dims[1], dims[0], z, name)
                    elif geometry == pybullet.GEOM_SPHERE:
                        outline = cut_sphere(position, dims[0], z, name)
                    if outline is not None:
                        result.append(outline)
        return result

    # --- the robot ----------------------------------------------------------------------
    def place_robot(self, pose: Pose):
        self.world.set_model_state(self.robot_name, pose)

    def frame_pose(self, robot_pose: Pose, link: str) -> Pose:
        """World pose of the robot's link `link` with its model frame at robot_pose."""
        self.place_robot(robot_pose)
        if link not in self.robot.links:
            raise KeyError("the robot has no link '%s'; links: %s"
                           % (link, ", ".join(sorted(self.robot.links))))
        index = self.robot.links[link]
        if index == -1:
            return robot_pose
        state = self.client.getLinkState(self.robot.body_id, index, computeForwardKinematics=True)
        return Pose(tuple(state[4]), tuple(state[5]))

    def clearance(self, poses: Sequence[Pose], max_distance=5.0) -> List[Clearance]:
        """Per pose, the robot's smallest distance to an obstacle [m] (see the module's
        docstring); distance inf and model "" when nothing is within max_distance [m]."""
        bodies, bounds = self._bounds(poses)
        return [self._pose_clearance(pose, index, bodies, bounds[index], max_distance)
                for index, pose in enumerate(poses)]

    def nearest(self, poses: Sequence[Pose], max_distance=5.0) -> Optional[Clearance]:
        """The pose of `poses` where the robot came closest to an obstacle: the same answer
        as min(clearance(poses)) by (distance, index), measured only at the poses whose
        lower bound could beat the best found so far (most of a track is far from
        everything). None when `poses` is empty."""
        if not len(poses):
            return None
        bodies, bounds = self._bounds(poses)
        lowest = bounds.min(axis=1) if bounds.shape[1] else np.full(len(poses), np.inf)
        best = None
        for index in np.lexsort((np.arange(len(poses)), lowest)):
            if best is not None and lowest[index] > min(best.distance, max_distance):
                break
            found = self._pose_clearance(poses[index], int(index), bodies, bounds[index],
                                         max_distance)
            if best is None or (found.distance, found.index) < (best.distance, best.index):
                best = found
        return best

    def _bounds(self, poses):
        """(obstacle bodies [(body, model)], (poses, bodies) lower bounds [m] of the
        robot-body distance): the gap between each body's bounding box and a box holding
        the robot at that pose (its links' boxes at rest, turned with the pose), less
        _BOUND_SLACK."""
        client = self.client
        bodies = [(b, name) for name in self.obstacles() for b in self.world.entities[name].body_ids]
        boxes = np.array([np.concatenate(client.getAABB(b, -1)) for b, _ in bodies]) \
            if bodies else np.zeros((0, 6))
        corners = self._robot_corners()
        positions = np.array([p.position for p in poses], dtype=float).reshape(-1, 3)
        rotations = np.array([rotation_matrix(p.orientation) for p in poses]).reshape(-1, 3, 3)
        points = np.einsum("pij,cj->pci", rotations, corners) + positions[:, None, :]
        low, high = points.min(axis=1), points.max(axis=1)               # (poses, 3)
        gap = np.maximum(0.0, np.maximum(boxes[None, :, :3] - high[:, None, :],
                                         low[:, None, :] - boxes[None, :, 3:]))
        return bodies, np.sqrt((gap * gap).sum(axis=2)) - _BOUND_SLACK

    def _robot_corners(self):
        """(n, 3) corners [m] of the robot's links' bounding boxes (those whose closest
        points count) at rest, in its model frame."""
        if self._corners is None:
            self.place_robot(Pose((0.0, 0.0, _FAR)))
            corners = []
            for link in [-1] + [i for i in self.robot.links.values()
                                if i >= 0 and i not in self._contact_links]:
                low, high = self.client.getAABB(self.robot.body_id, link)
                corners += [(x, y, z - _FAR) for x in (low[0], high[0]) for y in (low[1], high[1])
                            for z in (low[2], high[2])]
            self._corners = np.array(corners)
        return self._corners

    def _pose_clearance(self, pose, index, bodies, bound, max_distance):
        """Clearance at one pose, asking Bullet only about bodies whose bound can beat the
        best distance found so far (nearest bound first)."""
        client, robot_body = self.client, self.robot.body_id
        self.place_robot(pose)
        best, best_k = math.inf, None          # a tie goes to the body listed first
        for k in np.argsort(bound, kind="stable"):
            if bound[k] > min(best, max_distance):
                break
            body, _ = bodies[k]
            for point in client.getClosestPoints(robot_body, body, distance=max_distance):
                if point[3] in self._contact_links:
                    continue
                if (point[8], k) < (best, best_k if best_k is not None else len(bodies)):
                    best, best_k = point[8], k
        return Clearance(float(best), bodies[best_k][1] if best_k is not None else "", index)
