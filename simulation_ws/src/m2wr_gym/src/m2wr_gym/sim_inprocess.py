"""The stand-in's engine in this process, as the environments drive it: no ROS master, the
same world loading, laser, diff drive and contacts as the ROS simulator (pybullet_gazebo's
World), stepped at its fixed physics step (5 ms, the simulator's default).

Each reset builds the World afresh (about 30 ms for world02) and spawns m2wr at the start
pose resting on its wheels: Bullet keeps contact caches across teleports, so a rebuilt world
is what makes an episode depend on its seed and actions only.
"""
from dataclasses import dataclass
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
from pybullet_gazebo.engine.client import Client

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.ray_sensor import RaySensor
from pybullet_gazebo.engine.transforms import Pose, yaw_from_quaternion
from pybullet_gazebo.engine.world import SpawnError, World

from . import resources

ROBOT = "m2wr"
REST_Z = 0.1            # [m] link_chassis height when m2wr stands on its wheels (wheel radius)


@dataclass
class Snapshot:
    """What the robot senses and where it is after a step."""
    ranges: np.ndarray        # (720,) float32 [m], +inf = no return
    range_max: float          # [m]
    x: float                  # [m] model frame (link_chassis) in the world
    y: float                  # [m]
    yaw: float                # [rad]
    sim_time: float           # [s]
    touched: tuple = ()       # names of the models touched during the step (ground excluded)


def robot_urdf(laser_noise=None):
    """m2wr's URDF; laser_noise [m] replaces the laser's Gaussian stddev (None: as written)."""
    text = resources.robot_urdf()
    if laser_noise is None:
        return text
    root = ET.fromstring(text)
    for stddev in root.iter("stddev"):
        stddev.text = repr(float(laser_noise))
    return ET.tostring(root, encoding="unicode")


class InProcessSim:
    def __init__(self, world_path, physics_step=0.005, laser_noise=None, gui=False,
                 legacy_mode=False):
        self.spec = resources.world_spec(world_path)
        self.physics_step = physics_step          # [s]
        self.legacy_mode = legacy_mode            # the simulator's legacy_mode:=true
        self.urdf = robot_urdf(laser_noise)
        self.warnings = []
        self.client = Client(connection_mode=pybullet.GUI if gui else pybullet.DIRECT)
        if gui:
            self.client.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0)
        self.world = None
        self._drive = None
        self._laser = None
        self._laser_last = None
        self._ahead = None        # (steps, touched, readings) run_ahead did of the next run

    @property
    def drive(self):
        """m2wr's DiffDrive in the current world (None before the first reset)."""
        return self._drive

    def reset(self, x, y, yaw, seed):
        """A fresh world with m2wr at (x, y, yaw) at rest; ValueError naming the pose when it
        is inside an obstacle. Returns the first scan (taken at sim time 0)."""
        self.world = World(self.client, self.spec, self.physics_step, seed=seed,
                           warn=self.warnings.append, legacy_mode=self.legacy_mode)
        pose = Pose.from_xyz_rpy(x, y, REST_Z, 0.0, 0.0, yaw)
        try:
            robot = self.world.spawn_urdf(ROBOT, self.urdf, pose)
        except SpawnError as err:
            raise ValueError("start pose (x=%.3f, y=%.3f, yaw=%.3f): %s" % (x, y, yaw, err)) \
                from None
        drives = robot.parts_with(DiffDrive.KEY)
        lasers = robot.parts_with(RaySensor.KEY)
        if len(drives) != 1 or len(lasers) != 1:
            raise RuntimeError("m2wr should have one drive and one laser; it has %d and %d"
                               % (len(drives), len(lasers)))
        self._drive = drives[0]
        self._laser = lasers[0]
        self._laser_last = None
        self._ahead = None
        entity = self.world.entity(ROBOT)
        # the model frame from Bullet's centre-of-mass pose, as World.model_pose computes it
        # (a robot's model frame is its root link's: no further offset)
        assert entity.link_offsets[0] == Pose(), entity.link_offsets[0]
        self._base_pose = self.client.getBasePositionAndOrientation
        self._body = entity.body_ids[0]
        self._com_to_model = entity.inertial_offsets[0].inverse()
        readings = self.world.step()           # the laser's first scan is due at once
        return self._snapshot(readings, ())

    def run(self, linear_x, angular_z, steps):
        """Sets the drive's command and steps physics `steps` times; the command reaches the
        wheels at the drive's next update (20 Hz for m2wr), as a cmd_vel would. Only the
        laser's last scan of these steps is observed, so only that one is cast: the scans
        before it and the other parts' readings are skipped (their schedules and noise draws
        go on as if made). The steps run_ahead ran already are not run again."""
        ahead, touched, readings = self._ahead or (0, set(), [])
        self._ahead = None
        self._drive.set_command(linear_x, angular_z)
        if steps > ahead:
            readings = readings + self._advance(steps - ahead, touched, continues=ahead > 0)
        return self._snapshot(readings, tuple(sorted({other for _, other in touched})))

    def run_ahead(self, steps):
        """Runs now the first steps of the next run(..., steps): those that start before the
        drive next reads its command, which no command given meanwhile can change (the
        drive keeps a command until its next update, as Gazebo's does). A vector env's
        worker calls this while the learner chooses the next action; run() then does the
        rest, with results identical to the bit to a run() without it. Not with a
        commandTimeout (the command's arrival time would count): then nothing is run."""
        if self._ahead is not None or self.world is None or self._drive.command_timeout > 0:
            return
        world = self.world
        reads = world.next_command_time()
        times = world.times_after(steps)                 # at the end of each step to run
        starts = [world.sim_time] + times[:-1]           # at the start of each
        count = steps if reads is None else sum(1 for t in starts if t < reads)
        touched = set()
        self._ahead = (count, touched, self._advance(count, touched, times) if count else [])

    def _advance(self, count, touched, times=None, continues=False):
        """`count` physics steps of a window that ends with an observation, `times` the sim
        times at the end of each of its steps (default: world.times_after(count)): the
        laser's last scan in the window is collected if it falls in these steps, every other
        reading is skipped. The contact guard looks over the whole window; `continues`:
        these steps follow such a call's (World.advance)."""
        world = self.world
        if times is None:
            times = world.times_after(count)
        scans = self._laser.scans_at(times)
        last = scans[-1] if scans and scans[-1] < count else None
        return world.advance(count, collect=() if last is None else (self._laser,),
                             touched=touched, collect_from=last or 0, continues=continues,
                             horizon=len(times))

    def _snapshot(self, readings, touched):
        for reading in readings:
            if hasattr(reading.data, "ranges"):
                self._laser_last = reading.data
        scan = self._laser_last
        position, orientation = self._base_pose(self._body)
        pose = Pose(position, orientation).compose(self._com_to_model)
        yaw = yaw_from_quaternion(pose.orientation)
        # (the scan's own float32 array: each scan is a new one, and nothing writes to it)
        return Snapshot(scan.ranges, float(scan.range_max),
                        float(pose.position[0]), float(pose.position[1]), float(yaw),
                        float(self.world.sim_time), touched)

    def close(self):
        if self.client is not None:
            try:
                self.client.disconnect()
            except pybullet.error:
                pass
            self.client = None
