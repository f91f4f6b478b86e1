"""Replays of recorded runs, for the browser view (pybullet_gazebo.web): the demo's run,
the batch runner's and the grader's, each written as a page that opens from file://.

A run records its robot's track (t, x, y, z, qx, qy, qz, qw: /odom or /tf at the drive's
rate). From it and the world, the offline Scene (scene.py, the engine in DIRECT mode) makes
frames every FRAME_PERIOD of sim time: the robot placed at the recorded pose, its wheels
turned by the distance each rolled, its laser cast there (the sensor's own caster and noise
model: the scan it would have taken at that pose; the world's dynamic models where the
scene has them). Frames as the live page gets them (pybullet_gazebo.web.frames).

  build(scene, urdf_xml, track, title)                 -> the replay (a JSON-able dict)
  write(folder, name, scene, urdf_xml, track, title)   -> <folder>/<name>.html

The batch runner (rig.py, RunOptions.replay) keeps a run's replay as runs/<run_id>.replay.json;
the grader's report turns each into a page beside the run's picture (grade/report.py).
"""
import numpy as np

from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.web import site
from pybullet_gazebo.web.frames import FrameBuilder, laser_hits, ray_sensors
from pybullet_gazebo.web.scene import robot_scene, world_scene

FRAME_PERIOD = 0.1          # [s] sim between two frames of a replay
REPLAY_HITS = 120           # laser returns kept per frame (every k-th beam)


def _sample(track, period):
    """Rows of `track` (sorted by t) at least `period` apart, the last row always kept."""
    keep, last = [], None
    for index, row in enumerate(track):
        if last is None or row[0] - last >= period - 1e-9:
            keep.append(index)
            last = row[0]
    if keep and keep[-1] != len(track) - 1:
        keep.append(len(track) - 1)
    return [track[i] for i in keep]


class _Wheels:
    """Each revolving joint whose child link has a cylinder visual, turned by how far its
    link's centre moved along the direction it rolls in (a x z, a the axis in the world)."""

    def __init__(self, client, robot, links):
        self.client, self.robot = client, robot
        self.wheels = []             # (joint index, child link index, axis (3,), radius)
        for name, index in robot.joints.items():
            info = client.getJointInfo(robot.body_id, index)
            if info[2] != 0:         # JOINT_REVOLUTE only (URDF continuous or revolute)
                continue
            child = index                # pybullet: a joint's child link has its index
            link_name = info[12].decode()
            radius = next((s["radius"] for s in links.get(link_name, ())
                           if s.get("kind") == "cylinder"), None)
            if radius:
                self.wheels.append((index, child, np.asarray(info[13], dtype=float), radius))
        self.angles = [0.0] * len(self.wheels)
        self.last = None

    def turn(self):
        client, body = self.client, self.robot.body_id
        now = []
        for k, (joint, link, axis, radius) in enumerate(self.wheels):
            state = client.getLinkState(body, link, computeForwardKinematics=True)
            position = state[4]
            # pybullet gives a joint's axis in its child's inertial frame (state[1]), which
            # for m2wr's wheels is turned against the URDF link frame (state[5])
            ax, ay, _ = Pose((0, 0, 0), tuple(state[1])).matrix @ axis
            if self.last is not None:          # rolls along axis x z = (ay, -ax, 0)
                before = self.last[k]
                self.angles[k] += ((position[0] - before[0]) * ay
                                   - (position[1] - before[1]) * ax) / radius
            client.resetJointState(body, joint, self.angles[k])
            now.append(position)
        self.last = now

    def straighten(self):
        """Every wheel back at angle 0 (the scene serves other measures after)."""
        for joint, _, _, _ in self.wheels:
            self.client.resetJointState(self.robot.body_id, joint, 0.0)


def frames(scene, track, robot_links, period=FRAME_PERIOD, hits=REPLAY_HITS):
    """The replay's frames from `track` rows (t, x, y, z, qx, qy, qz, qw) in `scene`;
    `robot_links`: the robot scene's {link: shapes} (the wheels' radii)."""
    robot = scene.robot
    builder = FrameBuilder(scene.world)
    wheels = _Wheels(scene.client, robot, robot_links)
    lasers = ray_sensors(robot)
    # the offline scene never steps: the world's models stay where they are for the whole
    # replay, and each frame shares their one reading
    models = builder.moving_models()
    out = []
    for row in _sample(list(track), period):
        t = float(row[0])
        scene.place_robot(Pose(tuple(float(v) for v in row[1:4]),
                               tuple(float(v) for v in row[4:8])))
        wheels.turn()
        frame = {"type": "frame", "t": round(t, 3), "rtf": None, "paused": False,
                 "models": models, "robots": {robot.name: builder.robot(robot)},
                 "hits": {}}
        points, origin = [], None
        for sensor in lasers:
            sensor_origin, flat = laser_hits(sensor, sensor.measure(t), limit=hits,
                                             decimals=2)
            origin = origin or sensor_origin
            points.extend(flat)
        if lasers:
            frame["hits"][robot.name] = {"from": origin, "points": points}
        out.append(frame)
    wheels.straighten()
    return out


def build(scene, urdf_xml, track, title):
    """The replay of `track` in `scene` (see site.py for its fields)."""
    robot = robot_scene(scene.robot.name, urdf_xml)
    return {"title": title, "scene": world_scene(scene.spec, inline_meshes=True),
            "robots": {scene.robot.name: robot},
            "frames": frames(scene, track, robot["links"])}


def write(folder, name, scene, urdf_xml, track, title):
    """Writes the replay's page and data into `folder` (site.write_replay); returns the
    page's path."""
    return site.write_replay(folder, name, build(scene, urdf_xml, track, title))
