"""The ROS face of the stand-in: runs a World and talks to ROS the way Gazebo does.

Node name `gazebo`, so its services are Gazebo's:
  ~reset_simulation, ~reset_world, ~pause_physics, ~unpause_physics  (std_srvs/Empty)
  ~spawn_urdf_model (gazebo_msgs/SpawnModel), ~delete_model (gazebo_msgs/DeleteModel)
  ~spawn_sdf_model (gazebo_msgs/SpawnModel): always answers false (URDF only)
  ~get_model_state / ~set_model_state (gazebo_msgs/GetModelState / SetModelState)
  ~get_world_properties / ~get_physics_properties
Topics out:
  /clock (rosgraph_msgs/Clock) when /use_sim_time, at ~pub_clock_frequency [Hz sim]
  ~model_states (gazebo_msgs/ModelStates) at ~model_states_rate [Hz sim]
  ~contacts (gazebo_msgs/ContactsState) the (robot, model) pairs touching, the ground excluded,
            each time that set changes (an empty list when the last touch ends)
  per robot, from its <gazebo> tags: the laser's topicName (sensor_msgs/LaserScan) at the
  sensor's update_rate, the diff drive's odometryTopic (nav_msgs/Odometry) and TF
  odometryFrame -> robotBaseFrame at its updateRate.
Topics in: per robot, the diff drive's commandTopic (geometry_msgs/Twist). Not /clock: the
node is its source (see nodes/gazebo_world).
Parameters: see params.py. All messages of one step carry that step's sim time; wall-clock
pacing (real_time_factor, lockstep) lives here, never in the engine. Odometry and TF messages
are built only while someone listens (the engine computes the odometry either way).
"""
import os
import threading
import time

import pybullet
import rospy
from geometry_msgs.msg import Twist
from gazebo_msgs.msg import ContactState, ContactsState, ModelStates
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.ray_sensor import RaySensor
from pybullet_gazebo.engine.world import World
from pybullet_gazebo.ros import conversions
from pybullet_gazebo.ros.gazebo_services import GazeboServices


class SimulatorNode:
    def __init__(self, params, world_spec):
        self.params = params
        show_gui = params.gui and bool(os.environ.get("DISPLAY"))
        if params.gui and not show_gui:
            rospy.loginfo("gui requested but there is no display (DISPLAY is unset): running "
                          "headless; pass gui:=false to silence this")
        mode = pybullet.GUI if show_gui else pybullet.DIRECT
        self.client = BulletClient(connection_mode=mode)
        step = params.max_step_size or world_spec.physics.max_step_size
        self.world = World(self.client, world_spec, step, seed=params.seed,
                           warn=lambda m: rospy.logwarn(m),
                           command_timeout=params.cmd_vel_timeout)
        self.lock = threading.RLock()             # guards the world: loop vs. service threads
        self.paused = params.paused
        self.real_time_factor = params.real_time_factor
        self.commands_received = 0
        self.command_arrived = threading.Condition()
        self._robot_io = {}                       # robot name -> (publishers, subscribers)
        self._last_touching = []
        self._reset_pacing()
        # publication periods in whole physics steps, so they never drift
        self._clock_every = self._steps_per_period(params.pub_clock_frequency)
        self._last_clock_step = 0
        self._awaited = None     # lockstep: (commands counted at a scan, sim time needed by)
        self._model_states_every = self._steps_per_period(params.model_states_rate)

        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10) \
            if params.use_sim_time else None
        self.model_states_pub = rospy.Publisher("~model_states", ModelStates, queue_size=1)
        self.contacts_pub = rospy.Publisher("~contacts", ContactsState, queue_size=100, latch=True)
        self.tf_pub = rospy.Publisher("/tf", TFMessage, queue_size=100)
        self.services = GazeboServices(self)
        rospy.loginfo("world '%s' loaded from %s: %d models, physics step %.4f s, "
                      "real_time_factor %s%s", world_spec.name, world_spec.source,
                      len(self.world.model_names()), step,
                      self.real_time_factor or "unlimited", ", paused" if self.paused else "")

    def _steps_per_period(self, rate):
        return max(1, int(round(1.0 / (rate * self.world.step_size))))

    # --- robots' topics -------------------------------------------------------------------
    def attach_robot(self, robot):
        """Opens the topics a spawned robot's components publish and listen to."""
        publishers, subscribers = {}, []
        for component in robot.components:
            if isinstance(component, RaySensor):
                topic = rospy.names.ns_join(robot.namespace or "/", component.topic)
                publishers[id(component)] = rospy.Publisher(topic, LaserScan, queue_size=1)
            elif isinstance(component, DiffDrive):
                ns = robot.namespace or "/"
                publishers[id(component)] = rospy.Publisher(
                    rospy.names.ns_join(ns, component.odometry_topic), Odometry, queue_size=1)
                subscribers.append(rospy.Subscriber(
                    rospy.names.ns_join(ns, component.command_topic), Twist,
                    self._on_command, callback_args=(robot.name, component), queue_size=1))
        self._robot_io[robot.name] = (publishers, subscribers)

    def detach_robot(self, name):
        publishers, subscribers = self._robot_io.pop(name, ({}, []))
        for subscriber in subscribers:
            subscriber.unregister()
        for publisher in publishers.values():
            publisher.unregister()

    def _on_command(self, msg, args):
        name, drive = args
        if not conversions.is_finite_twist(msg):
            rospy.logwarn_throttle(5.0, "ignored a %s command for '%s' with NaN or inf: %s"
                                   % (drive.command_topic, name, [msg.linear.x, msg.angular.z]))
        else:
            if self.params.debug:          # a per-message hot path: no work when not asked
                rospy.logdebug_throttle(1.0, "%s for '%s': linear.x %.3f, angular.z %.3f"
                                        % (drive.command_topic, name, msg.linear.x, msg.angular.z))
            # Not under self.lock: the loop holds it while it steps, and waiting for it here
            # delayed commands by whole steps when running free. Setting the command is one
            # attribute write, read by the drive at its next update.
            drive.set_command(msg.linear.x, msg.angular.z)
        with self.command_arrived:
            self.commands_received += 1
            self.command_arrived.notify_all()

    # --- the loop -------------------------------------------------------------------------
    def _reset_pacing(self):
        self._pace_wall = time.monotonic()
        self._pace_sim = self.world.sim_time

    def run(self):
        while not rospy.is_shutdown():
            if self.paused:
                time.sleep(0.01)
                continue
            awaited = self._awaited
            if awaited is not None and self.world.sim_time >= awaited[1]:
                self._wait_for_command(awaited[0])
                self._awaited = None
            with self.lock:
                readings = self.world.step()
                commands_before = self.commands_received
                now = self.world.sim_time
                scans = self._publish(readings)
                needed_at = self.world.next_command_time() if scans else None
            if self.params.lockstep and needed_at is not None:
                # The drive reads its command only at its next update (Gazebo's plugin does
                # the same), so physics runs on until then while the controller thinks.
                self._awaited = (commands_before, needed_at)
            self._pace(now)

    def _publish(self, readings):
        """Publishes what is due after a step, stamped with its sim time; returns the number
        of scans published."""
        touching = self.world.touching()
        contacts_changed = touching != self._last_touching
        model_states_due = self.world.step_count % self._model_states_every == 0 \
            and self.model_states_pub.get_num_connections() > 0     # costly: only if heard
        clock_due = self._clock_due(force=bool(readings))
        if not (readings or contacts_changed or model_states_due or clock_due):
            return 0
        stamp = conversions.stamp_of(self.world.step_count, self.world.step_size)
        if clock_due:
            self.clock_pub.publish(Clock(stamp))
        scans = self._publish_readings(readings, stamp)
        if contacts_changed:
            self._last_touching = touching
            self._publish_contacts(touching, stamp)
        if model_states_due:
            self.model_states_pub.publish(self.model_states())
        return scans

    def _clock_due(self, force):
        """/clock every _clock_every steps and on each step with readings (`force`), counted
        from the last /clock sent: the two cadences share ticks instead of adding up (at
        20 Hz, /clock would otherwise go out at 40 Hz, its ticks between the scans')."""
        if self.clock_pub is None:
            return False
        since = self.world.step_count - self._last_clock_step
        if force or since >= self._clock_every or since < 0:     # < 0: after a reset
            self._last_clock_step = self.world.step_count
            return True
        return False

    def _publish_readings(self, readings, stamp):
        scans = 0
        for reading in readings:
            publishers, _ = self._robot_io.get(reading.robot.name, ({}, []))
            publisher = publishers.get(id(reading.component))
            if publisher is None:
                continue
            if isinstance(reading.component, RaySensor):
                publisher.publish(conversions.scan_to_msg(reading.data, stamp))
                scans += 1
            else:
                odometry_heard = publisher.get_num_connections() > 0
                tf_heard = (reading.component.publish_odom_tf
                            and self.tf_pub.get_num_connections() > 0)
                if not (odometry_heard or tf_heard):
                    continue
                odometry, transform = conversions.odometry_to_msgs(
                    reading.data, reading.component, stamp)
                if odometry_heard:
                    publisher.publish(odometry)
                if tf_heard:
                    self.tf_pub.publish(TFMessage([transform]))
        return scans

    def _publish_contacts(self, touching, stamp):
        msg = ContactsState()
        msg.header.stamp = stamp
        msg.header.frame_id = "world"
        msg.states = [ContactState(info="%s touches %s" % pair, collision1_name=pair[0],
                                   collision2_name=pair[1]) for pair in touching]
        self.contacts_pub.publish(msg)

    def model_states(self):
        msg = ModelStates()
        for name in self.world.model_names():
            linear, angular = self.world.model_twist(name)
            msg.name.append(name)
            msg.pose.append(conversions.pose_to_msg(self.world.model_pose(name)))
            msg.twist.append(conversions.twist_to_msg(linear, angular))
        return msg

    def _wait_for_command(self, commands_before):
        """Lockstep: hold physics until a controller has answered the last scan (if one
        listens), so the answer reaches the drive at the same sim time on every run."""
        if not any(s.get_num_connections() for _, subs in self._robot_io.values() for s in subs):
            return
        deadline = time.monotonic() + self.params.lockstep_timeout
        with self.command_arrived:
            while self.commands_received == commands_before and not rospy.is_shutdown():
                left = deadline - time.monotonic()
                if left <= 0:
                    rospy.logwarn_throttle(10.0, "lockstep: no cmd_vel within %.2f s of a scan; "
                                           "stepping on" % self.params.lockstep_timeout)
                    return
                self.command_arrived.wait(min(left, 0.1))

    def _pace(self, now):
        if self.real_time_factor <= 0:
            return
        target = self._pace_wall + (now - self._pace_sim) / self.real_time_factor
        delay = target - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        elif delay < -0.5:          # far behind (a slow machine): do not try to catch up
            self._reset_pacing()

    # --- used by the services -------------------------------------------------------------
    def set_paused(self, paused):
        self.paused = paused
        self._reset_pacing()

    def after_reset(self):
        self._reset_pacing()
        self._awaited = None

    def shutdown(self):
        try:
            self.client.disconnect()
        except pybullet.error:
            pass
