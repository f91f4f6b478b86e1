"""/clock (rosgraph_msgs/Clock): the simulator's sim time, for every node with /use_sim_time.

Who gets which tick:
  loop nodes    nodes that publish a robot's command topic (the diff drive's commandTopic: the
                lockstep partners) or read its sensor or odometry topics (the laser's scans,
                the drive's odometryTopic: a controller, bug2's supervisor that switches
                behaviours on its rospy.Rate) get every tick the simulator sends: at
                ~pub_clock_frequency [Hz sim] and at each step that publishes readings, so
                that their rospy.Rate wakes in time.
  watchers      every other subscriber (robot_state_publisher, rviz showing only the robot and
                TF, rostopic, a node reading model_states) gets /clock as Gazebo sends it, at
                ~pub_clock_frequency in sim time, and, faster than real time, at most
                max(~watch_rate, pub_clock_frequency) ticks per wall second (watch_rate.py): as
                many per wall second as at real time, each further ahead. When the simulation
                pauses, each watcher gets the latest tick it missed (flush), so every node
                agrees on the paused time. ~watch_rate 0: every subscriber gets every tick.
So a node that reads only /tf and the watching topics (model_states, link_states,
joint_states: limited in wall time already) is a watcher; /tf itself is never limited.

Why: every message wakes its subscriber. Far faster than real time, /clock is most of the
messages an rviz-like listener wakes up for (ticks at 20 Hz of sim time become hundreds per
wall second); each wake-up costs the simulator's thread a socket write and the cores the
listener's own work, while the simulator and the controller need both. A display draws 30
frames per wall second: 600 ticks per wall second show nothing more. The listeners' cost
with and without the limit: docs/performance.md.
"""
import math
import time

from rosgraph_msgs.msg import Clock

from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.watch_rate import WallRateLimit, topic_limit


class _Watcher:
    """What /clock sent one watching subscriber: its wall-time limit and last tick."""

    def __init__(self, wall_limit, clock):
        self.limit = WallRateLimit(wall_limit, clock)
        self.last = None                    # [s] sim time of the last tick it got
        self.slot = None                    # the clock period that tick fell in


class ClockTopic:
    def __init__(self, clock_rate, watch_rate, loop_nodes, clock=time.monotonic,
                 sent_elsewhere=None):
        """`clock_rate` [Hz sim]: ~pub_clock_frequency; `watch_rate` [Hz wall]: ~watch_rate;
        `loop_nodes()`: the names of the loop nodes (see above), now;
        `sent_elsewhere(connection, stamp)`: True when lockstep sent a subscriber's tick
        another way (with word of what it follows, lockstep/tick_word.py)."""
        self.publisher = DirectPublisher("/clock", Clock)
        self._sent_elsewhere = sent_elsewhere
        self._period = 1.0 / clock_rate if clock_rate > 0 else 0.0      # [s] sim
        self._wall_limit = topic_limit(watch_rate, clock_rate)         # [Hz] wall
        self._limited = watch_rate > 0
        self._loop_nodes = loop_nodes
        self._clock = clock
        self._watchers = {}                 # node name -> _Watcher
        self._latest = None                 # the last tick sent (a Clock message)

    def publish(self, stamp, loop_nodes=True):
        """One tick at sim time `stamp` (rospy Time) to whoever is due for it; with
        `loop_nodes` false, not to the loop nodes (lockstep sends them theirs with
        publish_to_loop_nodes once they are done with the readings of that time)."""
        msg = Clock(stamp)
        self._latest = msg
        if not self._limited and loop_nodes:
            self._publish(msg)
            return
        now = stamp.to_sec()
        nodes = self._loop_nodes()
        self._forget_gone()

        def share(connection):
            node = connection.endpoint_id
            if node in nodes:
                return loop_nodes
            if not self._limited:
                return True
            watcher = self._watcher(node)
            # the first tick of each clock period of sim time (a reset: a period not seen
            # yet). Not "a period since the last one": the readings' ticks come between the
            # regular ones (a second robot's scans at their own phase), and a tick one step
            # after the last would then be refused and the next regular one too, 80 of 100
            # a sim second for a watcher
            slot = self._slot(now)
            if slot != watcher.slot and watcher.limit.allow():
                watcher.last, watcher.slot = now, slot
                return True
            return False

        self._publish(msg, share)

    def publish_to_loop_nodes(self, stamp, nodes=None):
        """The tick at `stamp` to the loop nodes only, or to those of them named in `nodes`
        (lockstep: one at a time)."""
        nodes = self._loop_nodes() if nodes is None else nodes
        if nodes:
            self._publish(Clock(stamp), lambda c: c.endpoint_id in nodes)

    def flush(self):
        """The latest tick to each watcher that has not had it (call while paused)."""
        if self._latest is None or not self._watchers:
            return
        now = self._latest.clock.to_sec()
        behind = {node for node, w in self._watchers.items() if w.last != now}
        if not behind:
            return

        def share(connection):
            if connection.endpoint_id in behind:
                watcher = self._watchers[connection.endpoint_id]
                watcher.last, watcher.slot = now, self._slot(now)
                return True
            return False

        self._publish(self._latest, share)

    def _publish(self, msg, share=None):
        """Writes a tick to the subscribers `share` picks (all: None), but for those whose
        tick lockstep sends another way."""
        elsewhere = self._sent_elsewhere
        if elsewhere is None:
            self.publisher.publish(msg, share)
            return

        def share_here(connection):
            return (share is None or share(connection)) and \
                not elsewhere(connection, msg.clock)
        self.publisher.publish(msg, share_here)

    def _slot(self, sim_time):
        """The number of the clock period `sim_time` [s] falls in (a millionth of a period's
        slack for float sums of the step); every tick its own with no period."""
        if self._period <= 0:
            return sim_time
        return math.floor(sim_time / self._period + 1e-6)

    def _watcher(self, node):
        watcher = self._watchers.get(node)
        if watcher is None:
            watcher = self._watchers[node] = _Watcher(self._wall_limit, self._clock)
        return watcher

    def _forget_gone(self):
        """Drops the records of subscribers that left (anonymous nodes come and go)."""
        if len(self._watchers) > 2 * self.publisher.get_num_connections() + 8:
            impl = self.publisher.publisher.impl
            present = {c.endpoint_id for c in impl.connections} if impl is not None else set()
            self._watchers = {n: w for n, w in self._watchers.items() if n in present}

    def get_num_connections(self):
        return self.publisher.get_num_connections()

    def unregister(self):
        self.publisher.unregister()
