"""Where a model may be put: the one check of a requested pose (spawn, set_model_state) and
the geometric checks of a spawned body against the models already in the world."""
import math
from typing import Iterable, List, Tuple

import numpy as np
import pybullet

from .transforms import Pose

# Bounds on what a request may ask: Bullet's state overflows to NaN for extreme values (a
# twist of 1e160 turns every touching body's pose into NaN), and far from the origin contacts
# and rays lose their precision. Nothing the tutorial does comes near them.
MAX_COORDINATE = 1.0e6          # [m] per axis, for a spawn or set_model_state position
MAX_VELOCITY = 1.0e6            # [m/s] and [rad/s] per axis, for a set_model_state twist


def checked_pose(pose: Pose, what: str, advice: str, error=ValueError,
                 linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0),
                 zero_is_identity=False) -> Pose:
    """The pose with its quaternion normalised, or `error` naming `what` (e.g. "spawn pose
    of 'm2wr'") and `advice` when a value is not finite, a position is beyond MAX_COORDINATE,
    a velocity beyond MAX_VELOCITY or the quaternion is zero. `zero_is_identity`: an all-zero
    quaternion is the identity instead (Gazebo's set_model_state normalizes it so)."""
    values = list(pose.position) + list(pose.orientation) + list(linear) + list(angular)
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise error("%s is not finite (a non-finite value in %s); %s"
                    % (what, [float(v) for v in values], advice))
    if max(abs(v) for v in pose.position) > MAX_COORDINATE:
        raise error("%s: position %s is over %g m from the origin; %s"
                    % (what, tuple(pose.position), MAX_COORDINATE, advice))
    if max(abs(v) for v in list(linear) + list(angular)) > MAX_VELOCITY:
        raise error("%s: twist (linear %s, angular %s) is over %g m/s or rad/s; %s"
                    % (what, tuple(linear), tuple(angular), MAX_VELOCITY, advice))
    norm = math.sqrt(sum(q * q for q in pose.orientation))
    if zero_is_identity and all(q == 0.0 for q in pose.orientation):
        return Pose(pose.position, (0.0, 0.0, 0.0, 1.0))
    if norm < 1e-9:          # Bullet would keep it and the robot's sensors would see NaN
        raise error("%s: orientation %s is a zero quaternion; %s"
                    % (what, tuple(pose.orientation), advice))
    return Pose(pose.position, tuple(q / norm for q in pose.orientation))


def overlapping(client, body, others: Iterable[Tuple[int, str]]) -> List[str]:
    """Names of the owners of the bodies in `others` ((body, owner) pairs) that `body`
    penetrates."""
    client.performCollisionDetection()
    names = set()
    for other_body, owner in others:
        for point in client.getClosestPoints(body, other_body, distance=0.0):
            if point[8] < -0.001:      # contact distance [m]; negative = penetration
                names.add(owner)
    return sorted(names)


def grounds_above(client, body, grounds: Iterable[Tuple[int, str]]) -> List[str]:
    """Names of the ground models ((body, owner) pairs) whose plane has the whole body (every
    corner of its links' bounding boxes) on its underside. Bullet's plane is a half-space: a
    body under it would be thrown out of the ground, not left to fall."""
    corners = []
    for link in range(-1, client.getNumJoints(body)):
        low, high = client.getAABB(body, link)
        corners += [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1])
                    for z in (low[2], high[2])]
    corners = np.array(corners)
    names = set()
    for ground, owner in grounds:
        position, orientation = client.getBasePositionAndOrientation(ground)
        frame = Pose(tuple(position), tuple(orientation))    # shapes sit in this frame
        for shape in client.getCollisionShapeData(ground, -1):
            if shape[2] != pybullet.GEOM_PLANE:
                continue
            plane = frame.compose(Pose(tuple(shape[5]), tuple(shape[6])))
            normal = plane.matrix @ np.asarray(shape[3], dtype=float)
            if np.max((corners - np.asarray(plane.position)) @ normal) < 0.0:
                names.add(owner)
    return sorted(names)
