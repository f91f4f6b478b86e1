"""The simulator's side of the GUI: starts the viewer process (viewer.py) and sends it the
world, the robots as they come and go, and, at most `fps` times per wall second, a frame:
where every moving body is, the robots' joint angles, the laser beams of sensors that
visualize, sim time and real-time factor.

Why a process of its own: pybullet's GUI mode runs every API call of the simulator through
its render thread (about 190 % CPU and a slower loop). Here the simulator stays in DIRECT
mode, so the physics and what it publishes are the same with and without a window, and
the cost of the window is bounded: building a frame takes well under a millisecond of the
loop, `fps` times a second at most; pickling and writing happen in a thread of their own,
which drops frames when the viewer is behind (the scene messages are never dropped).

When the viewer ends (its window closed, or it failed to start), the simulation goes on
headless and says so once. No ROS here: messages go through `info` and `warn`.
"""
import fcntl
import os
import pickle
import subprocess
import sys
import threading
import time

import numpy as np

from ..engine.ray_sensor import RaySensor
from ..engine.transforms import Pose
from .display import display_problem

F_SETPIPE_SZ = 1031           # Linux fcntl: set a pipe's buffer size
MAX_BEAMS_SENT = 240          # beams per visualized sensor (every k-th of the scan)


VIEWER = [sys.executable, "-m", "pybullet_gazebo.gui.viewer"]


def open_window(world, fps=30.0, rays="sdf", follow=True, info=print, warn=print):
    """A GuiWindow on $DISPLAY, or None (with a warning saying why) when no window can be
    opened. `rays`: "sdf" draws the beams of sensors whose <visualize> is true (Gazebo's
    rule), "true" of every ray sensor, "false" of none. `follow`: the camera comes close to
    the first robot and follows it (else it stays on the whole world)."""
    problem = display_problem()
    if problem is not None:
        warn("gui requested but %s: running headless; pass gui:=false to silence this" % problem)
        return None
    try:
        return GuiWindow(world, fps, rays, follow, info, warn)
    except OSError as err:
        warn("the GUI viewer could not be started (%s): running headless" % err)
        return None


class GuiWindow:
    def __init__(self, world, fps, rays, follow, info, warn, viewer=VIEWER):
        self.world = world
        self.period = 1.0 / fps if fps > 0 else 0.0        # [s] wall between frames
        self.rays = rays
        self.info, self.warn = info, warn
        self._process = subprocess.Popen(
            list(viewer) + ["--fps", repr(float(fps)), "--follow", "true" if follow else "false"],
            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, env=os.environ.copy(),
            # a session of its own: a terminal's Ctrl-C goes to the simulator, which ends the
            # viewer by closing its stdin (also when the simulator is killed)
            start_new_session=True)
        try:       # a pipe of one page: at most about one frame waits in it, never a backlog
            fcntl.fcntl(self._process.stdin.fileno(), F_SETPIPE_SZ, 4096)
        except OSError:
            pass
        self._lock = threading.Condition()
        self._control = []                # messages that must all arrive, in order
        self._frame = None                # the latest frame; older ones are dropped
        self._open = True
        self._robots = {}                 # name -> (Robot, [visualized RaySensor])
        self._scans = {}                  # id(sensor) -> latest LaserScanData
        self._next_frame = 0.0            # [s] monotonic
        self._rate_mark = None            # (wall, sim) at the start of the RTF window
        self._rtf = 0.0
        self._writer = threading.Thread(target=self._write, name="gui-writer", daemon=True)
        self._writer.start()
        self._send(("world", world.spec))

    @property
    def is_open(self):
        return self._open

    # --- what the simulator tells it --------------------------------------------------
    def add_robot(self, robot, urdf_xml):
        sensors = [c for c in robot.parts_with(RaySensor.KEY)
                   if self.rays == "true" or (self.rays == "sdf" and c.spec.visualize)]
        self._robots[robot.name] = (robot, sensors)
        self._send(("robot", robot.name, urdf_xml))

    def remove_robot(self, name):
        robot, sensors = self._robots.pop(name, (None, []))
        for sensor in sensors:
            self._scans.pop(id(sensor), None)
        self._send(("remove", name))

    def after_step(self, readings):
        """Called by the loop after each step with its readings; sends a frame when one is
        due (wall clock)."""
        if not self._open:
            return
        for reading in readings:
            if reading.part.KEY == RaySensor.KEY:
                self._scans[id(reading.part)] = reading.data
        now = time.monotonic()
        if now < self._next_frame:
            return
        self._next_frame = now + self.period
        frame = self._build_frame(now)
        with self._lock:
            self._frame = frame
            self._lock.notify()

    def close(self):
        with self._lock:
            self._open = False
            self._lock.notify()
        if self._process.stdin:
            try:
                self._process.stdin.close()
            except OSError:
                pass
        # Ended at once, not left to read to the end of its stdin: a viewer still building
        # the world in software GL took seconds to get there, and the simulator, which waits
        # for it, ended that late after a Ctrl-C (over 10 s on a busy machine). SIGTERM ends
        # it at once (viewer.py), and there is nothing of it to save.
        self._process.terminate()
        try:
            self._process.wait(2.0)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()

    # --- frames -------------------------------------------------------------------------
    def _build_frame(self, now):
        world = self.world
        client = world.client
        sim = world.sim_time
        if self._rate_mark is None or sim < self._rate_mark[1]:
            self._rate_mark = (now, sim)
        elif now - self._rate_mark[0] >= 1.0:
            self._rtf = (sim - self._rate_mark[1]) / (now - self._rate_mark[0])
            self._rate_mark = (now, sim)
        moving = {}
        for entity in world.entities.values():
            if entity.static or entity.is_ground or entity.robot is not None:
                continue
            frames = []
            for body, inertial in zip(entity.body_ids, entity.inertial_offsets):
                raw = Pose(*client.getBasePositionAndOrientation(body))
                frames.append(raw.compose(inertial.inverse()))
            moving[entity.name] = frames
        robots, beams = {}, []
        for name, (robot, sensors) in self._robots.items():
            if name not in world.entities:
                continue
            joints = {joint: client.getJointState(robot.body_id, index)[0]
                      for joint, index in robot.joints.items()}
            robots[name] = (world.model_pose(name), joints)
            for sensor in sensors:
                scan = self._scans.get(id(sensor))
                if scan is not None:
                    beams.append(_beam_segments(sensor, scan))
        return ("frame", sim, self._rtf, moving, robots, beams)

    # --- the pipe -----------------------------------------------------------------------
    def _send(self, message):
        with self._lock:
            self._control.append(message)
            self._lock.notify()

    def _write(self):
        pipe = self._process.stdin
        while True:
            with self._lock:
                while self._open and not self._control and self._frame is None:
                    self._lock.wait()
                if not self._open:
                    return
                batch = self._control + ([self._frame] if self._frame is not None else [])
                self._control, self._frame = [], None
            try:
                for message in batch:
                    pickle.dump(message, pipe, protocol=pickle.HIGHEST_PROTOCOL)
                pipe.flush()
            except (OSError, ValueError):           # the viewer is gone (window closed)
                with self._lock:
                    was_open, self._open = self._open, False
                if was_open:
                    self.info("the GUI window was closed; the simulation goes on headless")
                return


def _beam_segments(sensor, scan):
    """(origin (3,), ends (k, 3)) of every k-th beam of a scan, in the world, from the
    sensor's pose now; a beam without a return is drawn to the maximum range."""
    ranges = np.asarray(scan.ranges, dtype=float)
    step = max(1, int(np.ceil(len(ranges) / MAX_BEAMS_SENT)))
    index = np.arange(0, len(ranges), step)
    lengths = np.where(np.isfinite(ranges[index]), ranges[index], scan.range_max)
    angles = scan.angle_min + scan.angle_increment * index
    local = np.stack([np.cos(angles) * lengths, np.sin(angles) * lengths,
                      np.zeros(len(index))], axis=1)
    pose = sensor.sensor_pose()
    ends = local @ pose.matrix.T + np.asarray(pose.position)
    return np.asarray(pose.position, dtype=float), ends, np.isfinite(ranges[index])
