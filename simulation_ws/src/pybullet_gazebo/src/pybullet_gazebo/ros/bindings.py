"""How each robot part meets ROS: one Binding class per part KEY (the Gazebo plugin or sensor
type the part stands in for), in the table BINDINGS. A binding opens the part's publishers and
subscribers under the robot's namespace, turns its readings into messages stamped with the
step's sim time, and closes them when the robot goes. A part whose KEY has no binding is
reported by name when its robot is bound.

  ray (libgazebo_ros_laser.so)      publishes the plugin's topicName (sensor_msgs/LaserScan)
  libgazebo_ros_joint_state_publisher.so  publishes joint_states (sensor_msgs/JointState) at
                                    the part's updateRate [Hz sim] (a diff drive's wheels: its
                                    updateRate, engine/joint_states.py), only while someone
                                    listens; a watching topic: faster than real time at most
                                    max(~watch_rate, updateRate) per wall second (watch_rate.py)
  libgazebo_ros_diff_drive.so       subscribes commandTopic (geometry_msgs/Twist), publishes
                                    odometryTopic (nav_msgs/Odometry) and TF odometryFrame ->
                                    robotBaseFrame on /tf at its updateRate [Hz sim], each only
                                    while someone listens, never limited in wall time
                                    (controllers use them in lockstep)

Names as gazebo_ros gives them with several robots (robot_namespace.py): topics in the
plugin's <robotNamespace> or the spawn's namespace; the laser's frame prefixed by the
`tf_prefix` parameter found from that namespace, the drive's frames by it or, when there is
none, by the namespace itself (read once, when the robot is bound).
"""
import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Callable, Dict, List

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState, LaserScan
from tf2_msgs.msg import TFMessage

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.joint_states import JointStatePublisher
from pybullet_gazebo.engine.ray_sensor import RaySensor
from pybullet_gazebo.ros import conversions, plugin_names, robot_namespace
from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.watch_rate import WallRateLimit, topic_limit


@dataclass
class BindingContext:
    """What the simulator node lends every binding."""
    tf_publisher: Callable[[], DirectPublisher]   # the node's /tf publisher, made on first use
    debug: bool = False
    watch_rate: float = 0.0                       # [Hz wall] ~watch_rate (watch_rate.py)
    commands_by_node: Counter = field(default_factory=Counter)   # for the run summary
    # (resolved topic) -> None: lockstep's main thread reads this topic (lockstep/inbox.py)
    read_in_main_thread: Callable[[str], None] = lambda topic: None


class Binding:
    """Base class: a part's ROS side. `publish` gets each reading of the part."""

    def __init__(self, robot, part, context: BindingContext):
        self.robot = robot
        self.part = part
        self.context = context
        self.publishers: List = []                   # rospy or DirectPublisher: unregister()
        # publishers whose subscribers take part in the loop (clock_topic.py): sensors, odometry
        self.loop_publishers: List[DirectPublisher] = []
        self.subscribers: List[rospy.Subscriber] = []
        self.namespace = robot_namespace.plugin_namespace(
            robot.namespace, plugin_names.own_namespace(part.plugin_params))

    def topic(self, name):
        """A part's topic name resolved in its namespace (absolute names stay)."""
        return robot_namespace.topic_name(self.namespace, name)

    def frame(self, name, fall_back_to_namespace):
        """A part's frame with its tf prefix (see the module docstring)."""
        return robot_namespace.resolve_frame(
            robot_namespace.tf_prefix(self.namespace, fall_back_to_namespace), name)

    def publish(self, data, stamp) -> bool:
        """Publishes one reading; True when it was a scan (lockstep counts scans)."""
        return False

    def loop_nodes(self) -> set:
        """The nodes that command this part or read its sensor or odometry topics: they may
        act on what they get in sim time (a controller, bug2's supervisor), where a display
        only shows it; see clock_topic.py."""
        return {node for node, _ in self.loop_connections()}

    def impl(self) -> list:
        """The rospy topic implementations of the loop nodes' connections (their lists of
        connections are replaced whenever one comes or goes)."""
        return [s.impl for s in self.subscribers] + \
            [p.publisher.impl for p in self.loop_publishers]

    def loop_connections(self) -> list:
        """[(node name, rospy connection)] of the loop nodes' connections to this part."""
        pairs = [(c.callerid_pub, c) for s in self.subscribers if s.impl is not None
                 for c in list(s.impl.connections)]
        for publisher in self.loop_publishers:
            impl = publisher.publisher.impl
            if impl is not None:
                pairs.extend((c.endpoint_id, c) for c in list(impl.connections))
        return pairs

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()
        for publisher in self.publishers:
            publisher.unregister()


class LaserBinding(Binding):
    def __init__(self, robot, part, context):
        super().__init__(robot, part, context)
        names = plugin_names.laser_names(part.plugin_params, part.spec.link)
        self.scans = DirectPublisher(self.topic(names.topic), LaserScan)   # see its docstring
        self.publishers.append(self.scans)
        self.loop_publishers.append(self.scans)
        self.frame_id = self.frame(names.frame, fall_back_to_namespace=False)

    def publish(self, data, stamp):
        self.scans.publish(conversions.scan_to_msg(data, stamp, self.frame_id))
        return True


class DriveBinding(Binding):
    def __init__(self, robot, part, context):
        super().__init__(robot, part, context)
        self.names = plugin_names.drive_names(part.plugin_params)
        self.odometry = DirectPublisher(self.topic(self.names.odometry_topic), Odometry)
        self.publishers.append(self.odometry)
        self.loop_publishers.append(self.odometry)
        self.frames = (self.frame(self.names.odometry_frame, fall_back_to_namespace=True),
                       self.frame(self.names.robot_base_frame, fall_back_to_namespace=True))
        # /tf is advertised once a robot needs it (an empty world offers no /tf, as Gazebo)
        self.tf = context.tf_publisher() if part.publish_odom_tf else None
        # tcp_nodelay: a transport hint only (the command comes at once, not after the
        # publisher's kernel has waited for the ACK of the last one)
        command_topic = self.topic(self.names.command_topic)
        context.read_in_main_thread(rospy.resolve_name(command_topic))
        self.subscribers.append(rospy.Subscriber(command_topic, Twist,
                                                 self._on_command, queue_size=1,
                                                 tcp_nodelay=True))

    def _on_command(self, msg):
        self.context.commands_by_node[msg._connection_header.get("callerid", "?")] += 1
        if not conversions.is_finite_twist(msg):
            # all six fields, as a ROS user reads a Twist (the drive itself checks the two
            # it uses, for callers without ROS)
            rospy.logwarn_throttle(5.0, "ignored a %s command for '%s' with NaN or inf: %s"
                                   % (self.names.command_topic, self.robot.name,
                                      [msg.linear.x, msg.angular.z]))
            return
        if self.context.debug:         # a per-message hot path: no work when not asked
            rospy.logdebug_throttle(1.0, "%s for '%s': linear.x %.3f, angular.z %.3f"
                                    % (self.names.command_topic, self.robot.name, msg.linear.x,
                                       msg.angular.z))
        # Not under the world's lock: the loop holds it while it steps, and waiting for it
        # here delayed commands by whole steps when running free. Setting the command is one
        # attribute write, read by the drive at its next update.
        self.part.set_command(msg.linear.x, msg.angular.z)

    def publish(self, data, stamp):
        odometry_heard = self.odometry.get_num_connections() > 0
        tf = self.tf
        tf_heard = tf is not None and tf.get_num_connections() > 0
        if odometry_heard or tf_heard:
            odometry, transform = conversions.odometry_to_msgs(data, self.part, stamp,
                                                               self.frames)
            if odometry_heard:
                self.odometry.publish(odometry)
            if tf_heard:
                tf.publish(TFMessage([transform]))
        return False


class JointStateBinding(Binding):
    """joint_states (sensor_msgs/JointState) in the robot's namespace, built only while
    someone listens (robot_state_publisher, rviz), limited in wall time (watch_rate.py)."""

    def __init__(self, robot, part, context):
        super().__init__(robot, part, context)
        self.states = DirectPublisher(self.topic("joint_states"), JointState)
        self.publishers.append(self.states)
        self.message = JointState(name=list(part.names))
        sim_rate = 1.0 / part.period if part.period > 0 else math.inf     # [Hz sim]
        self.limit = WallRateLimit(topic_limit(context.watch_rate, sim_rate))

    def publish(self, data, stamp):
        if self.states.get_num_connections() > 0 and self.limit.allow():
            self.message.header.stamp = stamp
            self.message.position = data.positions
            self.message.velocity = data.velocities
            self.states.publish(self.message)
        return False


# part KEY -> its ROS binding
BINDINGS: Dict[str, type] = {
    RaySensor.KEY: LaserBinding,
    DiffDrive.KEY: DriveBinding,
    JointStatePublisher.KEY: JointStateBinding,
}


class RobotBindings:
    """The bindings of every part of one robot."""

    def __init__(self, robot, context: BindingContext, warn=rospy.logwarn):
        self.by_part = {}
        for part in robot.parts:
            binding_class = BINDINGS.get(part.KEY)
            if binding_class is None:
                warn("model '%s': part %s (%s) has no ROS binding; it publishes nothing"
                     % (robot.name, type(part).__name__, part.KEY))
                continue
            self.by_part[id(part)] = binding_class(robot, part, context)

    def publish(self, reading, stamp) -> bool:
        binding = self.by_part.get(id(reading.part))
        return binding.publish(reading.data, stamp) if binding is not None else False

    def loop_nodes(self) -> set:
        return set().union(*(b.loop_nodes() for b in self.by_part.values()))

    def loop_connections(self) -> list:
        return [pair for b in self.by_part.values() for pair in b.loop_connections()]

    def close(self):
        for binding in self.by_part.values():
            binding.close()
        self.by_part.clear()
