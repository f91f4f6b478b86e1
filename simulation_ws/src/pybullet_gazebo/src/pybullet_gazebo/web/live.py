"""The simulator's side of the live page: `WebView`, an observer the loop calls after each
stretch of physics, as it calls the GUI window.

Costs, by design: with no page open, `after_step` only notes the robots' path every
PATH_PERIOD of sim time (one pose read per robot); with pages open, it also keeps each
laser's latest scan and builds a frame at most `fps` times a wall second (a few link states
and one scan turned into points: well under a millisecond), which it hands to the server's
thread without waiting. While physics is paused the loop does not step: a timer of the
server's thread then sends a frame every PAUSED_PERIOD, under the world's lock, so a pause,
reset or move made meanwhile shows (and the page learns it is paused).

Step (the page's button): physics runs STEP_TIME of sim time, then pauses (`pause()`, the
adapter's, as /gazebo/pause_physics does); at most one stretch of physics (the loop's
World.advance) overshoots it.
"""
import math
import threading
import time

from .frames import FrameBuilder, ray_sensors
from .scene import robot_scene, world_scene

PATH_PERIOD = 0.1           # [s] sim between two points of a robot's path
PATH_MIN_MOVE = 0.01        # [m] a point is kept only this far from the last
PATH_JUMP = 1.0             # [m] farther than this in one period: teleported (reset): new path
PATH_MAX_POINTS = 20000     # then every other point is dropped
PAUSED_PERIOD = 0.2         # [s] wall between frames while paused
STEP_TIME = 0.05            # [s] sim run by the Step button (one m2wr drive update)


class WebView:
    def __init__(self, world, server, lock, is_paused, fps=30.0):
        self.world = world
        self.server = server
        self.lock = lock
        self.is_paused = is_paused
        self.period = 1.0 / fps if fps > 0 else 0.0
        self.builder = FrameBuilder(world)
        self._robots = {}                  # name -> Robot
        self._sensors = {}                 # name -> [RaySensor]
        self._scans = {}                   # id(sensor) -> (sensor, LaserScanData)
        self._next_frame = 0.0             # [s] monotonic
        self._next_path = 0.0              # [s] sim
        self._step_until = None            # [s] sim: Step pauses here
        self.pause = None                  # callable: pauses physics (set by the adapter)
        self._open = True
        server.scene = world_scene(world.spec, mesh_url=server.mesh_url)
        self._timer = threading.Thread(target=self._while_paused, name="web-paused",
                                       daemon=True)
        self._timer.start()

    # --- what the simulator tells it ----------------------------------------------------
    def add_robot(self, robot, urdf_xml):
        scene = robot_scene(robot.name, urdf_xml)
        missing = sorted(set(scene["links"]) - set(robot.links))
        if missing:
            scene["problems"].append("%s: links %s have no body in the simulation; not "
                                     "drawn" % (robot.name, ", ".join(missing)))
        self._robots[robot.name] = robot
        self._sensors[robot.name] = ray_sensors(robot)
        self.server.robots[robot.name] = scene
        self.server.paths[robot.name] = []
        self.server.send({"type": "robot", "robot": scene})

    def remove_robot(self, name):
        self._robots.pop(name, None)
        for sensor in self._sensors.pop(name, []):
            self._scans.pop(id(sensor), None)
        self.server.robots.pop(name, None)
        self.server.paths.pop(name, None)
        self.server.send({"type": "remove", "name": name})

    def after_step(self, readings):
        """After each stretch of physics (the world's lock held)."""
        sim = self.world.sim_time
        if sim >= self._next_path or sim < self._next_path - 2 * PATH_PERIOD:
            self._next_path = sim + PATH_PERIOD
            self._note_path()
        if self._step_until is not None and sim >= self._step_until - 1e-9:
            self._step_until = None
            if self.pause is not None:
                self.pause()
        if not self.server.watchers:
            return
        for reading in readings:
            if reading.part.KEY == "ray":
                self._scans[id(reading.part)] = (reading.part, reading.data)
        now = time.monotonic()
        if now < self._next_frame:
            return
        self._next_frame = now + self.period
        self.server.publish_frame(self._frame(now))

    def step(self):
        """Run STEP_TIME of sim time, then pause (call, then unpause physics)."""
        self._step_until = self.world.sim_time + STEP_TIME

    def close(self):
        self._open = False
        self.server.close()

    # --- inside ---------------------------------------------------------------------------
    def _frame(self, now=None):
        scans = {name: [self._scans[id(s)] for s in sensors if id(s) in self._scans]
                 for name, sensors in self._sensors.items()}
        return self.builder.frame(list(self._robots.values()), scans,
                                  paused=self.is_paused(), now=now)

    def _note_path(self):
        for name, robot in list(self._robots.items()):
            path = self.server.paths.get(name)
            if path is None or name not in self.world.entities:
                continue
            position = self.world.model_pose(name).position
            x, y = round(float(position[0]), 3), round(float(position[1]), 3)
            if path:
                moved = math.hypot(x - path[-2], y - path[-1])
                if moved > PATH_JUMP:
                    del path[:]
                elif moved < PATH_MIN_MOVE:
                    continue
            path.extend((x, y))
            if len(path) > 2 * PATH_MAX_POINTS:
                path[:] = [v for i, v in enumerate(path) if i % 4 < 2]

    def _while_paused(self):
        while self._open:
            time.sleep(PAUSED_PERIOD)
            if self.server.watchers and self.is_paused():
                with self.lock:
                    if self.is_paused():
                        self._note_path()
                        self.server.publish_frame(self._frame())
