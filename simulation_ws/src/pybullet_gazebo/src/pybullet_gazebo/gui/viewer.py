"""The GUI's viewer process: a pybullet window that shows what the simulator sends on stdin
(see window.py), and nothing else. Its pybullet server only draws: no physics is stepped.

  python -m pybullet_gazebo.gui.viewer [--fps 30] [--follow true|false]   (default true)

Messages (pickled, one after another on stdin):
  ("world", WorldSpec)                  the world's models, coloured by their SDF materials
  ("robot", name, urdf_xml)             a robot, coloured as Gazebo would (engine.appearance)
  ("remove", name)
  ("frame", sim_time, real_time_factor, {model: [link frames]}, {robot: (root link frame,
   {joint: position})}, [(origin, beam ends, hit flags)])
The window: no debug panels; the camera frames the whole world on start. With --follow
true it comes close to the first robot as soon as there is one (ROBOT_VIEW) and follows it,
keeping whatever angle and distance the user gives it; `f` stops following (and `f` again
follows, keeping the user's angle and distance). The
beams of visualized lasers in blue (a return) or grey (none within range); sim time and
real-time factor at the top. pybullet renders at most `fps` frames per second
(--minGraphicsUpdateTimeMs, in microseconds despite its name). The viewer ends when stdin
closes (the simulator ended) or its window is closed; Ctrl-C ends it quietly.
"""
import signal

# Ctrl-C or SIGTERM end the viewer at once, also while it still imports: no traceback
signal.signal(signal.SIGINT, signal.SIG_DFL)
signal.signal(signal.SIGTERM, signal.SIG_DFL)

import argparse  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import pickle  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402

import pybullet  # noqa: E402
from pybullet_utils.bullet_client import BulletClient

from ..engine.appearance import DEFAULT_COLOUR, urdf_link_colours
from ..engine.robot_description import parse_robot, strip_for_bullet
from ..engine.specs import Box, Cylinder, Plane, Sphere, TriangleMesh
from ..engine.transforms import Pose

HIT_COLOUR = (0.15, 0.35, 1.0)
MISS_COLOUR = (0.6, 0.6, 0.7)
TEXT_COLOUR = (0.05, 0.05, 0.05)
LINES_DRAWN = 24                # beam lines per sensor
PLANE_THICKNESS = 0.01          # [m] the ground is drawn as a thin box just below z 0
ROBOT_VIEW = (4.0, -45.0)       # [m] distance, [deg] pitch: the camera on a followed robot at first


class Viewer:
    def __init__(self, fps, follow):
        options = "--minGraphicsUpdateTimeMs=%d --width=1200 --height=760" % int(1e6 / max(fps, 1.0))
        self.client = BulletClient(connection_mode=pybullet.GUI, options=options)
        # no panels; no shadows (they double the cost of a frame on a software renderer)
        for flag in (pybullet.COV_ENABLE_GUI, pybullet.COV_ENABLE_RGB_BUFFER_PREVIEW,
                     pybullet.COV_ENABLE_DEPTH_BUFFER_PREVIEW,
                     pybullet.COV_ENABLE_SEGMENTATION_MARK_PREVIEW, pybullet.COV_ENABLE_SHADOWS):
            self.client.configureDebugVisualizer(flag, 0)
        self.follow = follow
        self.came_close = False     # the camera came to ROBOT_VIEW of a followed robot once
        self.models = {}            # name -> [(link index, [(body, collision pose)])]
        self.robots = {}            # name -> (body, {joint: index}, base inertial offset)
        self.lines = []             # debug line ids, reused from frame to frame
        self.points = None          # debug points id: every beam's return
        self.text = None
        self.text_shown = (None, None)

    # --- the world --------------------------------------------------------------------
    def world(self, spec):
        with self._not_rendering():
            self._build_world(spec)

    def _not_rendering(self):
        """Rendering paused while bodies are added: pybullet redoes its graphics buffers
        after each one (a world of 150 shapes took over a minute on a software renderer)."""
        client = self.client

        class Paused:
            def __enter__(self):
                client.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 0)

            def __exit__(self, *_):
                client.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 1)
        return Paused()

    def _build_world(self, spec):
        low, high = [math.inf] * 2, [-math.inf] * 2
        for model in spec.models:
            links = []
            for index, link in enumerate(model.links):
                shapes = []
                colour = link.colour or DEFAULT_COLOUR
                link_pose = model.pose.compose(link.pose)
                for collision in link.collisions:
                    visual, offset = self._visual_shape(collision, colour)
                    if visual is None:
                        continue
                    local = collision.pose.compose(offset)
                    pose = link_pose.compose(local)
                    body = self.client.createMultiBody(baseMass=0, baseVisualShapeIndex=visual,
                                                       basePosition=pose.position,
                                                       baseOrientation=pose.orientation)
                    if isinstance(collision.geometry, Plane):     # no glare on the ground
                        self.client.changeVisualShape(body, -1, specularColor=[0, 0, 0])
                    shapes.append((body, local))
                    if not isinstance(collision.geometry, Plane):
                        for axis in (0, 1):
                            low[axis] = min(low[axis], pose.position[axis])
                            high[axis] = max(high[axis], pose.position[axis])
                if shapes:
                    links.append((index, shapes))
            self.models[model.name] = links
        if math.isfinite(low[0]):
            centre = [(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, 0.0]
            extent = max(high[0] - low[0], high[1] - low[1], 4.0)
            self.client.resetDebugVisualizerCamera(cameraDistance=0.85 * extent, cameraYaw=0,
                                                   cameraPitch=-60, cameraTargetPosition=centre)

    def _visual_shape(self, collision, colour):
        """(visual shape id, offset of the drawn shape in the collision frame); None for a
        geometry it cannot draw (a mesh the world file could not read is not drawn)."""
        geometry = collision.geometry
        create = self.client.createVisualShape
        if isinstance(geometry, Box):
            return create(pybullet.GEOM_BOX, halfExtents=[s / 2 for s in geometry.size],
                          rgbaColor=colour), Pose()
        if isinstance(geometry, Cylinder):
            return create(pybullet.GEOM_CYLINDER, radius=geometry.radius,
                          length=geometry.length, rgbaColor=colour), Pose()
        if isinstance(geometry, Sphere):
            return create(pybullet.GEOM_SPHERE, radius=geometry.radius,
                          rgbaColor=colour), Pose()
        if isinstance(geometry, TriangleMesh) and len(geometry.faces):
            return create(pybullet.GEOM_MESH, vertices=geometry.vertices.tolist(),
                          indices=[int(i) for i in geometry.faces.reshape(-1)],
                          rgbaColor=colour), Pose()
        if isinstance(geometry, Plane) and tuple(geometry.normal) == (0.0, 0.0, 1.0):
            half = [geometry.size[0] / 2, geometry.size[1] / 2, PLANE_THICKNESS / 2]
            return create(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=colour), \
                Pose((0.0, 0.0, -PLANE_THICKNESS / 2))
        return None, None

    # --- robots -------------------------------------------------------------------------
    def robot(self, name, urdf_xml):
        with self._not_rendering():
            self._build_robot(name, urdf_xml)

    def _build_robot(self, name, urdf_xml):
        self.remove(name)
        description = parse_robot(urdf_xml, name)     # the text's one parse in this process
        handle, path = tempfile.mkstemp(prefix="pybullet_gazebo_view_", suffix=".urdf")
        try:
            with os.fdopen(handle, "w") as out:
                out.write(strip_for_bullet(description))
            body = self.client.loadURDF(path, useFixedBase=True,
                                        flags=pybullet.URDF_USE_IMPLICIT_CYLINDER)
        finally:
            os.unlink(path)
        joints, links = {}, {}
        for index in range(self.client.getNumJoints(body)):
            info = self.client.getJointInfo(body, index)
            joints[info[1].decode()] = index
            links[info[12].decode()] = index
        root = self.client.getBodyInfo(body)[0].decode()
        links[root] = -1
        for link, colour in urdf_link_colours(description.urdf).items():
            if link in links:
                self.client.changeVisualShape(body, links[link], rgbaColor=colour)
        inertial = Pose(*self.client.getDynamicsInfo(body, -1)[3:5])
        self.robots[name] = (body, joints, inertial)

    def remove(self, name):
        if name in self.robots:
            self.client.removeBody(self.robots.pop(name)[0])

    # --- frames -------------------------------------------------------------------------
    def frame(self, sim_time, rtf, moving, robots, beams):
        # Each call waits for the render thread, which draws between calls: rendering is
        # paused while the frame's changes go in (changing shapes while the renderer reads
        # them made a frame take more than twice as long)
        with self._not_rendering():
            self._frame(sim_time, rtf, moving, robots, beams)

    def _frame(self, sim_time, rtf, moving, robots, beams):
        client = self.client
        for name, frames in moving.items():
            for (index, shapes), link_frame in zip(self.models.get(name, []), frames):
                for body, local in shapes:
                    pose = link_frame.compose(local)
                    client.resetBasePositionAndOrientation(body, pose.position, pose.orientation)
        followed = None
        for name, (root_frame, joint_positions) in robots.items():
            if name not in self.robots:
                continue
            body, joints, inertial = self.robots[name]
            base = root_frame.compose(inertial)
            client.resetBasePositionAndOrientation(body, base.position, base.orientation)
            for joint, position in joint_positions.items():
                if joint in joints:
                    client.resetJointState(body, joints[joint], position)
            if followed is None:
                followed = root_frame.position
        self._draw_beams(beams)
        for key, state in client.getKeyboardEvents().items():
            if key == ord("f") and state & pybullet.KEY_WAS_TRIGGERED:
                self.follow = not self.follow
        camera = client.getDebugVisualizerCamera()
        yaw, pitch, distance, target = camera[8], camera[9], camera[10], camera[11]
        if self.follow and followed is not None:
            if not self.came_close:
                distance, pitch = ROBOT_VIEW
                self.came_close = True
            target = (followed[0], followed[1], 0.0)
            client.resetDebugVisualizerCamera(distance, yaw, pitch, target)
        text = "sim time %.1f s   real time factor %.2f" % (sim_time, rtf)
        above = (target[0], target[1], target[2] + 0.45 * distance)
        if (text, above) == self.text_shown:
            return
        self.text_shown = (text, above)
        if self.text is None:
            self.text = client.addUserDebugText(text, above, TEXT_COLOUR, textSize=1.4)
        else:
            client.addUserDebugText(text, above, TEXT_COLOUR, textSize=1.4,
                                    replaceItemUniqueId=self.text)

    def _draw_beams(self, beams):
        """A line for every k-th beam (LINES_DRAWN per sensor) and a point at every return:
        a debug line costs a round trip to the render thread, the points one in all."""
        client = self.client
        returns = [end for _, ends, hits in beams for end, hit in zip(ends, hits) if hit]
        if returns or self.points is not None:
            kwargs = {} if self.points is None else {"replaceItemUniqueId": self.points}
            points = returns or [(0.0, 0.0, -100.0)]        # nothing to show: out of sight
            self.points = client.addUserDebugPoints(points, [HIT_COLOUR] * len(points),
                                                    pointSize=3, **kwargs)
        count = 0
        for origin, ends, hits in beams:
            step = max(1, len(ends) // LINES_DRAWN)
            for end, hit in list(zip(ends, hits))[::step]:
                colour = HIT_COLOUR if hit else MISS_COLOUR
                if count < len(self.lines):
                    client.addUserDebugLine(origin, end, colour, 1.0,
                                            replaceItemUniqueId=self.lines[count])
                else:
                    self.lines.append(client.addUserDebugLine(origin, end, colour, 1.0))
                count += 1
        while len(self.lines) > count:
            client.removeUserDebugItem(self.lines.pop())

    def connected(self):
        try:
            return self.client.getConnectionInfo()["isConnected"] == 1
        except pybullet.error:
            return False


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--follow", default="true")
    args = parser.parse_args(argv)
    viewer = Viewer(args.fps, args.follow.lower() in ("true", "1"))
    source = sys.stdin.buffer
    handlers = {"world": viewer.world, "robot": viewer.robot, "remove": viewer.remove,
                "frame": viewer.frame}
    while viewer.connected():
        try:
            message = pickle.load(source)
        except (EOFError, OSError, pickle.UnpicklingError):
            break                               # the simulator ended
        try:
            handlers[message[0]](*message[1:])
        except pybullet.error:
            break                               # the window was closed
    if viewer.connected():
        viewer.client.disconnect()
    return 0


if __name__ == "__main__":
    sys.exit(main())
