"""Gazebo's state topics, world frame, as gazebo_ros_api_plugin publishes them:
  ~model_states (gazebo_msgs/ModelStates): every model's pose (model frame) and twist
  ~link_states  (gazebo_msgs/LinkStates): every link's pose (link frame, `model::link`) and twist
Published when the simulator node says they are due (its ~model_states_rate [Hz sim]), and
built only while someone listens: for 32 models at 50 Hz, building ModelStates from scratch
halved the loop's speed (issue 16). A static model's entry is computed once (it moves only when
a service teleports it, which `World.layout_version` counts); a dynamic body's entry only when
Bullet's raw pose or velocity of it changed since the last message (resting bodies sleep: in
world02, 8 of the 9 moving models; 1 ms -> 0.2 ms per message); the message objects are reused
(rospy serializes a message once inside publish(), for every subscriber). Both are watching
topics (watch_rate.py): faster than real time, at most max(~watch_rate, model_states_rate)
messages per wall second each. Written in the loop's thread (direct_publisher.py).
"""
from geometry_msgs.msg import Pose as PoseMsg, Twist
from gazebo_msgs.msg import LinkStates, ModelStates

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.watch_rate import WallRateLimit


def _write(msg, index, state):
    pose, linear, angular = state
    target = msg.pose[index]
    target.position.x, target.position.y, target.position.z = map(float, pose.position)
    (target.orientation.x, target.orientation.y, target.orientation.z,
     target.orientation.w) = map(float, pose.orientation)
    twist = msg.twist[index]
    twist.linear.x, twist.linear.y, twist.linear.z = map(float, linear)
    twist.angular.x, twist.angular.y, twist.angular.z = map(float, angular)


class _StatesMessage:
    """One reusable ModelStates or LinkStates message and the rows that move."""

    def __init__(self, msg_class, topic, wall_limit):
        self.publisher = DirectPublisher(topic, msg_class)
        self.limit = WallRateLimit(wall_limit)
        self.msg = msg_class()
        self._key = None
        # rows that move: [row, state function, raw-state function or None, last raw state]
        self._moving = []

    def publish(self, key, rows):
        """rows() -> [(name, static, state function, raw-state function or None)], called
        only when `key` changed; a row is recomputed when its raw state differs from the
        last (None: every time). Nothing while no one listens, or when the wall-time limit
        says skip."""
        if not (self.heard() and self.limit.allow()):
            return
        if self._key != key:
            self._rebuild(rows())
            self._key = key
        for row in self._moving:
            index, state, raw, last = row
            if raw is not None:
                now = raw()
                if now == last:
                    continue
                row[3] = now
            _write(self.msg, index, state())
        self.publisher.publish(self.msg)

    def _rebuild(self, rows):
        msg = self.msg
        msg.name = [name for name, _, _, _ in rows]
        msg.pose = [PoseMsg() for _ in rows]
        msg.twist = [Twist() for _ in rows]
        self._moving = []
        for index, (_, static, state, raw) in enumerate(rows):
            if static:
                _write(msg, index, state())
            else:
                self._moving.append([index, state, raw, None])

    def heard(self):
        return self.publisher.get_num_connections() > 0

    def wanted(self):
        """Someone listens and the wall-time limit would let a message through now."""
        return self.heard() and self.limit.ready()


class StateTopics:
    def __init__(self, world, wall_limit=0.0):
        """`wall_limit` [Hz wall]: at most this many messages per wall second on each topic
        (0: no limit); see watch_rate.topic_limit."""
        self.world = world
        self.model_states = _StatesMessage(ModelStates, "~model_states", wall_limit)
        self.link_states = _StatesMessage(LinkStates, "~link_states", wall_limit)

    def heard(self):
        return self.model_states.heard() or self.link_states.heard()

    def wanted(self):
        """A message would go out now if one were due: someone listens to a topic whose
        wall-time limit lets one through (the loop steps up to the next due step only then;
        see SimulatorNode._steps_ahead)."""
        return self.model_states.wanted() or self.link_states.wanted()

    def publish(self):
        """Publishes the topics someone listens to. Call with the world's lock held."""
        world = self.world
        key = (world.layout_version, tuple(world.model_names()))
        self.model_states.publish(key, self._model_rows)
        self.link_states.publish(key, self._link_rows)

    def _raw_state(self, body):
        """What Bullet holds of a body's base: (position, orientation), (linear, angular)."""
        client = self.world.client
        return lambda: (client.getBasePositionAndOrientation(body), client.getBaseVelocity(body))

    def _model_rows(self):
        world = self.world
        rows = []
        for name in world.model_names():
            entity = world.entities[name]
            rows.append((name, entity.static,
                         lambda name=name: model_access.model_state(world, name),
                         self._raw_state(entity.body_ids[0])))
        return rows

    def _link_rows(self):
        world = self.world
        rows = []
        for name in world.model_names():
            static = world.entities[name].static
            for ref in model_access.links_of(world, name):
                # a robot's links below its root move with its joints: recomputed each time
                raw = self._raw_state(ref.body_id) if ref.link_index < 0 else None
                rows.append((ref.scoped, static,
                             lambda ref=ref: model_access.link_state(world, ref), raw))
        return rows

    def skipped(self):
        """Messages left out by the wall-time limit so far."""
        return self.model_states.limit.skipped + self.link_states.limit.skipped

    def close(self):
        self.model_states.publisher.unregister()
        self.link_states.publisher.unregister()
