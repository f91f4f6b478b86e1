"""The ROS face of the stand-in: runs a World and talks to ROS the way Gazebo does.

Node name `gazebo`, so its services and topics are Gazebo's: the whole API of
gazebo_ros_api_plugin (gazebo_services.py and the modules it lists), and
Topics out:
  /clock (rosgraph_msgs/Clock) when /use_sim_time, at ~pub_clock_frequency [Hz sim]; to
            nodes that only watch, faster than real time at most max(~watch_rate, that
            rate) per wall second (clock_topic.py)
  ~model_states (gazebo_msgs/ModelStates), ~link_states (gazebo_msgs/LinkStates) at
            ~model_states_rate [Hz sim], built only while someone listens (state_topics.py);
            faster than real time at most max(~watch_rate, that rate) per wall second
            (watch_rate.py), as joint_states
  ~contacts (gazebo_msgs/ContactsState) only with ~contacts true (the stand-in's own, not
            Gazebo's): the (robot, model) pairs touching, the ground excluded, each time
            that set changes (an empty list when the last touch ends)
  per robot, what its parts' bindings publish (bindings.py): the laser's topicName
  (sensor_msgs/LaserScan) at the sensor's update_rate, the diff drive's odometryTopic
  (nav_msgs/Odometry) and TF odometryFrame -> robotBaseFrame at its updateRate (/tf is
  advertised once a robot's drive needs it: an empty world has none, as Gazebo), and the
  joint states (joint_states, sensor_msgs/JointState). /clock, scans, odometry and /tf are
  written in the loop's thread (direct_publisher.py); scans, odometry and /tf are never
  limited in wall time, nor /clock to the nodes that command a robot.
Topics in: per robot, the diff drive's commandTopic (geometry_msgs/Twist); Gazebo's
~set_model_state and ~set_link_state (state_services.py). Not /clock: the node is its
source (see nodes/gazebo_world).
Parameters: see params.py. All messages of one step carry that step's sim time; wall-clock
pacing (real_time_factor: pacing.py; lockstep: lockstep/gate.py) lives in the adapter, never in the engine.
"""
import threading
import time
from collections import Counter

import pybullet
import rospy
from gazebo_msgs.msg import ContactState, ContactsState
from lockstep_msgs.msg import LockstepReport
from tf2_msgs.msg import TFMessage
from pybullet_gazebo.engine.client import Client

from pybullet_gazebo.engine.world import World
from pybullet_gazebo.gui.window import open_window
from pybullet_gazebo.ros import conversions
from pybullet_gazebo.ros.bindings import BindingContext, DriveBinding, RobotBindings
from pybullet_gazebo.ros.clock_topic import ClockTopic
from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.gazebo_services import GazeboServices
from pybullet_gazebo.ros.lockstep import REPORT_TOPIC, rospy_hooks
from pybullet_gazebo.ros.lockstep.gate import Lockstep, sort_controllers
from pybullet_gazebo.ros.lockstep.idle_threads import IdleWatch
from pybullet_gazebo.ros.lockstep import inbox as lockstep_inbox
from pybullet_gazebo.ros.lockstep.node_processes import MASTER, NodeProcesses
from pybullet_gazebo.ros.lockstep.own_receivers import OwnReceivers
from pybullet_gazebo.ros.lockstep.board import Board
from pybullet_gazebo.ros.lockstep.service_providers import ServiceProviders
from pybullet_gazebo.ros.lockstep.tick_word import TickWord
from pybullet_gazebo.ros.pacing import RealTimePacer
from pybullet_gazebo.ros.state_topics import StateTopics
from pybullet_gazebo.ros.watch_rate import topic_limit
from pybullet_gazebo.ros.web_adapter import open_web_view

MAX_STEPS_AHEAD = 50        # physics steps the loop takes at most in one World.advance


class SimulatorNode:
    """Owns the World, the loop, /clock and the per-robot bindings; offers the Gazebo
    services the narrow interface they use (the `Simulation` protocol of gazebo_services)."""

    def __init__(self, params, world_spec, model_path=()):
        self.params = params
        self.model_path = list(model_path)        # for spawn_sdf_model's model:// includes
        # Physics always in DIRECT mode; the window is a viewer process of its own (gui/)
        self.client = Client(connection_mode=pybullet.DIRECT)
        step = params.max_step_size or world_spec.physics.max_step_size
        self.world = World(self.client, world_spec, step, seed=params.seed,
                           warn=lambda m: rospy.logwarn(m),
                           command_timeout=params.cmd_vel_timeout,
                           legacy_mode=params.legacy_mode)
        self.window = open_window(self.world, fps=params.gui_fps, rays=params.gui_rays,
                                  follow=params.gui_follow, info=rospy.loginfo,
                                  warn=rospy.logwarn) if params.gui else None
        self.gui = self.window is not None
        self.lock = threading.RLock()             # guards the world: loop vs. service threads
        self.paused = params.paused
        world_rtf = world_spec.physics.real_time_factor
        self.real_time_factor = world_rtf if params.real_time_factor is None \
            else params.real_time_factor
        self.pacer = RealTimePacer(self.real_time_factor, self.world.sim_time)
        self._node_processes = NodeProcesses(rospy.get_name())
        self._busy_loops = set()            # lockstep: threads taken for busy loops (named)
        self.board = self._report_sub = self.inbox = self.tick_word = None
        if params.lockstep:
            # the main thread reads the reports and commands it waits for (inbox.py)
            self.inbox = lockstep_inbox.install(lockstep_inbox.Inbox(
                [rospy.resolve_name(REPORT_TOPIC)], warn=rospy.logwarn))
        own_receivers = OwnReceivers(
            held=(lambda: self.inbox.parked) if self.inbox is not None else frozenset)
        if params.lockstep:
            # the handshake: the simulator's own counts (never reported) against each
            # controller's reports (lockstep/)
            own = rospy_hooks.install(report=False)
            self.board = Board(rospy.get_name(), own.counts, ServiceProviders(rospy.get_name()),
                               own_inbound=rospy_hooks.inbound_connections,
                               own_answered=own.take_answered,
                               own_outbound=rospy_hooks.outbound_connections,
                               inbox=self.inbox)
            own.on_change = self.board.notify
            # a lone loop node's tick goes out with its readings and word of what it must
            # follow (lockstep/tick_word.py)
            self.tick_word = TickWord(own)
            # no Nagle on the reports: a report held back for the last one's ACK would hold
            # the simulation for the receiver's delayed ACK
            self._report_sub = rospy.Subscriber(REPORT_TOPIC, LockstepReport, self._on_report,
                                                queue_size=None, tcp_nodelay=True)
        self.lockstep = Lockstep(
            params.lockstep, params.lockstep_timeout, self.board,
            IdleWatch(own_busy=lambda: self.inbox.poll() or own_receivers.busy(),
                      own_moved=lambda: self.inbox.poll() or own_receivers.moved(),
                      on_spin=self._note_busy_loop)
            if params.lockstep else None,
            is_shutdown=rospy.is_shutdown, is_paused=lambda: self.paused,
            describe=self._describe_busy,
            on_timeout=lambda who: rospy.logwarn(
                "lockstep: %s was still at work %.2f s after it was sent a message; stepping "
                "on (lockstep_timeout; counted in the run summary)" % (who,
                                                                     params.lockstep_timeout)))
        self._loop_clock = None                   # lockstep: /clock the loop nodes are owed
        self._owed = None                         # ... the nodes still owed it, in name order
        self._handed_on = False                   # ... a tick went out inside this stretch
        self._watched_key = None                  # lockstep: the loop connections watched now
        self._watched_names = set()               # ... and their nodes
        self._leaving = set()                     # reporters whose report connection closed
        self._bindings = {}                       # robot name -> RobotBindings
        self._running = False                     # run() is stepping
        self._tf_publisher = None
        self._binding_context = BindingContext(self._tf,
                                               read_in_main_thread=self.inbox.add
                                               if self.inbox is not None else lambda topic: None,
                                               debug=params.debug, watch_rate=params.watch_rate)
        self._last_touching = []
        # publication periods in whole physics steps, so they never drift
        self._clock_every = self._steps_per_period(params.pub_clock_frequency)
        self._last_clock_step = 0
        self._model_states_every = self._steps_per_period(params.model_states_rate)

        self.clock_pub = ClockTopic(
            params.pub_clock_frequency, params.watch_rate, self._loop_nodes,
            sent_elsewhere=self.tick_word.tick if self.tick_word is not None else None) \
            if params.use_sim_time else None
        self.state_topics = StateTopics(self.world, topic_limit(params.watch_rate,
                                                                params.model_states_rate))
        self.contacts_pub = rospy.Publisher("~contacts", ContactsState, queue_size=100,
                                            latch=True) if params.contacts else None
        self.web = open_web_view(self, params) if params.web else None     # the browser page
        self.services = GazeboServices(self)
        rospy.loginfo("world '%s' loaded from %s: %d models, physics step %.4f s, "
                      "real_time_factor %s (%s)%s", world_spec.name, world_spec.source,
                      len(self.world.model_names()), step,
                      self.real_time_factor or "unlimited",
                      "the world file's" if params.real_time_factor is None else
                      "~real_time_factor; the world file says %g" % world_rtf,
                      ", paused" if self.paused else "")
        rospy.loginfo("watching topics (model_states, link_states, joint_states): %s",
                      "at most max(%g, own rate) messages per wall second each when the "
                      "simulation runs faster than real time (~watch_rate; 0 = no limit)"
                      % params.watch_rate if params.watch_rate > 0 else
                      "at their sim-time rate whatever the speed (~watch_rate 0)")
        rospy.loginfo("diff drive: %s", "Kinetic's with legacyMode true (legacy_mode:=true): "
                      "leftJoint gets v + w*sep/2; m2wr turns counter-clockwise for a positive "
                      "angular.z" if params.legacy_mode else "Noetic's, as Gazebo (legacy_mode:="
                      "false): leftJoint gets v - w*sep/2; m2wr turns clockwise for a positive "
                      "angular.z")

    def _steps_per_period(self, rate):
        return max(1, int(round(1.0 / (rate * self.world.step_size))))

    def _tf(self):
        if self._tf_publisher is None:
            self._tf_publisher = DirectPublisher("/tf", TFMessage)
        return self._tf_publisher

    # --- the Simulation interface the services use --------------------------------------
    def spawn_urdf(self, name, urdf_xml, pose, namespace=""):
        """Spawns a robot and opens its parts' topics; the world's SpawnError otherwise."""
        with self.lock:
            robot = self.world.spawn_urdf(name, urdf_xml, pose, namespace=namespace)
            self._bindings[robot.name] = RobotBindings(robot, self._binding_context)
            if self.window is not None:
                self.window.add_robot(robot, urdf_xml)
            if self.web is not None:
                self.web.add_robot(robot, urdf_xml)
        return robot

    def delete_model(self, name):
        with self.lock:
            self.world.delete_model(name)
            bindings = self._bindings.pop(name, None)
            if self.window is not None:
                self.window.remove_robot(name)
            if self.web is not None:
                self.web.remove_robot(name)
        if bindings is not None:
            bindings.close()

    def set_paused(self, paused):
        self.paused = paused
        self.pacer.restart(self.world.sim_time)

    def set_real_time_factor(self, rtf):
        """Sim seconds per wall second from now on; 0 = as fast as possible."""
        self.real_time_factor = rtf
        self.pacer.real_time_factor = rtf
        self.pacer.restart(self.world.sim_time)

    def step_size_changed(self):
        """After world.set_step_size: publication periods are whole steps, recomputed."""
        self._clock_every = self._steps_per_period(self.params.pub_clock_frequency)
        self._model_states_every = self._steps_per_period(self.params.model_states_rate)
        self._last_clock_step = self.world.step_count
        self.pacer.restart(self.world.sim_time)

    def stamp(self):
        return conversions.stamp_of_world(self.world)

    def reset(self, simulation):
        """Gazebo's reset_simulation (`simulation` true: sim time back to 0) or reset_world."""
        with self.lock:
            if simulation:
                self.world.reset_simulation()
            else:
                self.world.reset_world()
            self.pacer.restart(self.world.sim_time)
            self.lockstep.forget()
            self._loop_clock = self._owed = None
            self._handed_on = False

    # --- the loop -------------------------------------------------------------------------
    def run(self):
        self._running = True
        try:
            self._loop()
        finally:
            self._running = False
            self._log_run_summary()
            self._disconnect()

    def _log_run_summary(self):
        """One line at the end of a run: sim time, contact events, what lockstep cost."""
        rospy.loginfo("run summary: %.2f s of sim time in %d steps; %d contact event(s) (a "
                      "robot starting to touch a model)%s", self.world.sim_time,
                      self.world.step_count, self.world.contacts.event_count,
                      "; lockstep: " + self.lockstep.stats.summary()
                      if self.params.lockstep else "")
        if self._busy_loops:
            rospy.loginfo("run summary: busy loops, not waited for (a thread that ran on "
                          "without sleeping): %s", ", ".join(sorted(self._busy_loops)))
        commands = self._binding_context.commands_by_node
        if commands:
            rospy.loginfo("run summary: commands received: %s", ", ".join(
                "%d from %s" % (n, node) for node, n in commands.most_common()))
        dropped = self._dropped_commands()
        if dropped:
            rospy.loginfo("run summary: commands dropped unread (a newer one came with them: a "
                          "drive keeps the newest, queue_size 1, as Gazebo's): %s", ", ".join(
                              "%d from %s" % (n, node) for node, n in dropped.most_common()))

    def _dropped_commands(self):
        """Commands the drives' subscribers dropped unread, by node (lockstep counts them)."""
        tracker = rospy_hooks.TRACKER
        if tracker is None:
            return Counter()
        topics = {b.topic(b.names.command_topic) for bindings in self._bindings.values()
                  for b in bindings.by_part.values() if isinstance(b, DriveBinding)}
        taken, _ = tracker.counts()
        dropped = Counter()
        for (topic, node, port), count in taken.items():
            if topic in topics:
                dropped[node] += count - tracker.taken.get((topic, node, port), 0)
        return +dropped

    def _loop(self):
        lockstep = self.lockstep.enabled
        while not rospy.is_shutdown():
            if self.paused:
                if self.clock_pub is not None:
                    self.clock_pub.flush()        # displays learn the paused time
                if self.inbox is not None:
                    self.inbox.poll(0.01)         # commands and reports come while paused
                else:
                    time.sleep(0.01)
                continue
            if self.inbox is not None:
                self.inbox.poll()                 # at least once a turn, whoever waits
            if lockstep and self._command_update_next() and not self._settle_loop_nodes():
                continue                          # paused while waiting: no step now
            with self.lock:
                if self.paused:                   # paused (or reset) while we waited
                    continue
                readings = self._advance()
                now = self.world.sim_time
            # lockstep: the loop nodes are done with what they had before they get more, and
            # with a tick handed on inside the stretch before anything else happens
            if lockstep and (readings or self._handed_on
                             or self._clock_due(force=False, peek=True)) \
                    and not self._settle_loop_nodes():
                continue
            with self.lock:
                self._publish(readings)
                if self.window is not None:
                    self.window.after_step(readings)      # a frame at most gui_fps per second
                if self.web is not None:
                    self.web.after_step(readings)         # the same for the browser page
            self.pacer.pace(now)

    def _command_update_next(self):
        """True when the next step starts with a drive reading its command."""
        needed_at = self.world.next_command_time()
        return needed_at is not None and self.world.sim_time >= needed_at

    def _advance(self):
        """Physics up to the next news (World.advance until_news) or the step before a drive
        reads its command. Call with the world's lock held.

        Lockstep, while the loop nodes are owed a /clock tick: step by step, and each loop
        node gets its tick (in name order) as soon as a look between two steps finds them all
        done with the readings. Its rospy.Rate loop then acts while physics runs on: what it
        sees is the same (nothing is published inside the stretch, the tick's sim time is
        that of the readings) and its command is read at the same drive update, as when the
        tick went out at the stretch's end. The lock stays held to the stretch's end and the
        loop settles there, so a service call the tick makes is served at that step whatever
        the machine's speed; no model_states step ends the stretch (their wall-time limit
        would make where it ends the machine's choice): they are published inside it."""
        world = self.world
        if not (self.lockstep.enabled and self._loop_clock is not None):
            return world.advance(self._steps_ahead(), until_news=True)
        ahead = self._steps_ahead(model_states=False)
        changes = world.contacts.changes
        self._watch_loop_nodes()
        for left in range(ahead, 0, -1):
            readings = world.advance(1, until_news=True, continues=left < ahead,
                                     horizon=left)
            if readings or left == 1 or world.contacts.changes != changes:
                return readings
            if self._model_states_due():
                self.state_topics.publish()
            if self._loop_clock is not None and self.lockstep.settled_now():
                if self._hand_on_tick():
                    self._handed_on = True
                    self.lockstep.stats.ticks_while_stepping += 1
        return []

    def _settle_loop_nodes(self):
        """Lockstep: waits until the loop nodes are done with what they were sent, then
        sends them the /clock tick they are still owed (that of the readings they just took
        in: after them, so that a rospy.Rate loop it wakes reads them), to one node at a
        time, waiting for each. False when physics was paused meanwhile."""
        self._watch_loop_nodes()             # (who the controllers are may change while paused)
        if not (self.lockstep.unsettled or self._loop_clock is not None):
            return True
        settled = self.lockstep.settle()
        if not settled:
            return False
        self._handed_on = False
        while self._loop_clock is not None:
            self._hand_on_tick()
            settled = self.lockstep.settle() and settled
        return settled

    def _hand_on_tick(self):
        """The owed /clock tick to the next loop node that has not had it. One node at a
        time, in the order of their names: when one node's tick acts on another (bug 2
        switching go to point on by a service call), which ticks first is then the same on
        every run, not the machine's choice. True when a tick went out."""
        if self._owed is None:
            self._owed = sorted(self._watched_names)
        sent = bool(self._owed)
        if sent:
            self.lockstep.sending()
            self.lockstep.stats.ticks += 1
            node = self._owed.pop(0)
            self.board.sent_clock((node,), self._loop_clock.to_nsec())
            self.clock_pub.publish_to_loop_nodes(self._loop_clock, {node})
        if not self._owed:
            self._loop_clock = self._owed = None
        return sent

    def _tick_goes_with_readings(self):
        """Whether the owed tick may go out now, right after the readings: its only loop node
        gets its ticks with word of what they follow (lockstep/tick_word.py), so the tick is
        set only once the readings are taken in; no report of the readings is waited for."""
        # a tick sent with the readings spares a round trip only when one node is owed each
        # tick: with several, each gets its tick once the one before is done with its own. A
        # node that said it only watches (a recorder, the benchmark's listener) is owed nothing.
        names = self._watched_names - self.board.watchers()
        if len(names) != 1 or not names <= self.lockstep.reporting or self.lockstep.watching \
                or self._leaving:
            self.tick_word.offer(())
            return False
        node, = names
        self.tick_word.offer(names)
        return self.tick_word.holding(node)

    def _watch_loop_nodes(self):
        """Lockstep waits for the loop nodes: by their reports when they send them (the
        handshake), by the /proc watch of their processes otherwise, and not at all for a
        reporter on its way out (gate.sort_controllers). Both are asked again
        whenever the loop nodes' connections change (a node restarted under the same name,
        the batch runner's next controller, is a new process) or a node starts reporting."""
        # rospy replaces a topic's list of connections whenever one comes or goes: the
        # lists themselves (compared item by item, kept alive by the key) tell whether
        # anything changed, without asking every binding for its pairs
        key = self._connection_lists()
        if key == self._watched_key:
            return
        self._watched_key = key
        connections = [pair for b in list(self._bindings.values())
                       for pair in b.loop_connections()]
        reporters = self._reporters()
        self._watched_names = names = {node for node, _ in connections}
        reporting, watched, self._leaving = sort_controllers(
            names, reporters, self.lockstep.reporting, self._leaving)
        self.lockstep.wait_for(reporting, watched)
        self.lockstep.watch.watch(self._node_processes.find(watched))
        rospy.loginfo("lockstep: waits for %s%s", ", ".join(
            ["%s (handshake)" % n for n in sorted(reporting)] +
            ["%s (pid %s, watched in /proc: it sends no lockstep report)"
             % (n, self._node_processes.pid_of(n)) for n in sorted(watched)] +
            ["%s (leaving: its report connection closed)" % n for n in sorted(self._leaving)])
            or "no controller", "; and %s (pid %s), which their service calls go through" % (
                MASTER, self._node_processes.pid_of(MASTER)) if watched else "")

    def _connection_lists(self):
        impls = [b.impl() for bindings in list(self._bindings.values())
                 for b in bindings.by_part.values()]
        impls.append(self._report_sub.impl if self._report_sub is not None else None)
        return tuple(impl.connections if impl is not None else None
                     for group in impls for impl in (group if isinstance(group, list)
                                                     else [group]))

    def _reporters(self):
        """The nodes whose lockstep reports reach the simulator now."""
        impl = self._report_sub.impl if self._report_sub is not None else None
        if impl is None:
            return frozenset()
        return frozenset(c.callerid_pub for c in list(impl.connections)) - {rospy.get_name()}

    def _on_report(self, msg):
        """A controller's report (lockstep_msgs/LockstepReport), named by its connection: a
        node speaks only for itself."""
        node = msg._connection_header.get("callerid")
        if node is None or node == rospy.get_name():
            return
        self.board.take(
            node, msg.pid, msg.seq,
            {(t, p, port): n for t, p, port, n in zip(msg.in_topics, msg.in_peers,
                                                       msg.in_ports, msg.in_counts)},
            {(t, p, port): n for t, p, port, n in zip(msg.out_topics, msg.out_peers,
                                                       msg.out_ports, msg.out_counts)},
            served=list(zip(msg.served_services, msg.served_ports)),
            called=list(zip(msg.called_services, msg.called_ports)), next_wake=msg.next_wake,
            watcher=msg.watcher,
            parked=list(zip(msg.parked_topics, msg.parked_peers, msg.parked_ports)))

    def _note_busy_loop(self, pid, tid):
        """Lockstep took thread `tid` of `pid` for a busy loop: it is not waited for."""
        what = "%s thread %d" % (self._describe_busy((pid, tid)), tid)
        if what not in self._busy_loops:
            self._busy_loops.add(what)
            rospy.loginfo("lockstep: %s runs without sleeping (a busy loop): not waited for "
                          "while it does", what)

    def _describe_busy(self, busy):
        """A name for what IdleWatch.busy() found at work (for the log and the summary)."""
        pid, _ = busy
        if pid == "self":
            return "the simulator's own reader of a message"
        if pid == "machine":
            return "another task on the machine"
        if pid == "kernel":
            return "the kernel's delivery of packets"
        names = self._node_processes.names_of(pid)
        if not names:
            return "pid %s" % pid
        return "%s%s (pid %d)" % ("node " if names[0].startswith("/") else "", names[0], pid)

    def _steps_ahead(self, model_states=True):
        """How many physics steps the loop may take in one World.advance (which stops early
        at readings or a change of touches): up to the next /clock tick, model_states
        message, or step before which lockstep may wait for an answer; one at a time when
        paced to a real-time factor or drawing a window, so both stay smooth. A
        model_states step bounds the stretch only while its wall-time limit would let the
        message out: faster than real time most of its due steps are skipped, and stopping
        at each (every 4 steps at 50 Hz) cut the loop's stretches to 4 steps whenever
        anyone listened."""
        if self.real_time_factor > 0 or self.window is not None:
            return 1
        world = self.world
        ahead = MAX_STEPS_AHEAD
        if self.clock_pub is not None:
            ahead = min(ahead, self._clock_every - (world.step_count - self._last_clock_step))
        if model_states and self.state_topics.wanted():
            ahead = min(ahead, self._model_states_every
                        - world.step_count % self._model_states_every)
        needed_at = world.next_command_time() if self.lockstep.enabled else None
        if needed_at is not None:
            steps = 1               # the steps after the first start before `needed_at`
            while steps < ahead and world.time_after(steps) < needed_at:
                steps += 1
            ahead = min(ahead, steps)
        return max(1, ahead)

    def _loop_nodes(self):
        """Nodes that command a robot or read its sensors or odometry: they get every /clock
        tick (clock_topic.py)."""
        return set().union(*(b.loop_nodes() for b in list(self._bindings.values())))

    def _publish(self, readings):
        """Publishes what is due after a step, stamped with its sim time; returns the number
        of scans published."""
        touching = self.world.touching() if self.contacts_pub is not None else []
        contacts_changed = touching != self._last_touching
        model_states_due = self._model_states_due()
        clock_due = self._clock_due(force=bool(readings))
        if not (readings or contacts_changed or model_states_due or clock_due):
            return 0
        stamp = conversions.stamp_of_world(self.world)
        lockstep = self.lockstep.enabled
        if clock_due:
            self.clock_pub.publish(stamp, loop_nodes=not lockstep)
            if lockstep:
                self._loop_clock = stamp
        if contacts_changed:
            # before the readings of the same step: a client that takes the scan for the end
            # of its step (m2wr_gym's ROS backend) then has the touch too (after them, it
            # could read the scan first and see the touch a step late: CI run 103)
            self._last_touching = touching
            self._publish_contacts(touching, stamp)
        if readings:
            self.lockstep.sending()
        scans = 0
        for reading in readings:
            bindings = self._bindings.get(reading.robot.name)
            if bindings is not None and bindings.publish(reading, stamp):
                scans += 1
        if self._loop_clock is not None and self._tick_goes_with_readings():
            self._hand_on_tick()
            self.lockstep.stats.ticks_with_readings += 1
        if model_states_due:
            self.state_topics.publish()
        return scans

    def _model_states_due(self):
        """model_states (and link_states) are due after this step and someone hears them
        (building them is costly: only then)."""
        return self.world.step_count % self._model_states_every == 0 \
            and self.state_topics.heard()

    def _clock_due(self, force, peek=False):
        """/clock every _clock_every steps and on each step with readings (`force`), counted
        from the last /clock sent: the two cadences share ticks instead of adding up (at
        20 Hz, /clock would otherwise go out at 40 Hz, its ticks between the scans').
        `peek`: only say whether it is due, without counting it as sent."""
        if self.clock_pub is None:
            return False
        since = self.world.step_count - self._last_clock_step
        if force or since >= self._clock_every or since < 0:     # < 0: after a reset
            if not peek:
                self._last_clock_step = self.world.step_count
            return True
        return False

    def _publish_contacts(self, touching, stamp):
        msg = ContactsState()
        msg.header.stamp = stamp
        msg.header.frame_id = "world"
        msg.states = [ContactState(info="%s touches %s" % pair, collision1_name=pair[0],
                                   collision2_name=pair[1]) for pair in touching]
        self.contacts_pub.publish(msg)

    def shutdown(self):
        """rospy's shutdown hook. Ctrl-C's handler runs on the main thread, the one stepping,
        possibly in the middle of a step: while run() loops, it disconnects Bullet itself once
        the loop has ended, never under a step."""
        if not self._running:
            self._disconnect()

    def _disconnect(self):
        if self.inbox is not None:
            self.inbox.close()                    # rospy's threads end their connections
        if self.window is not None:
            self.window.close()
        if self.web is not None:
            self.web.close()
        with self.lock:           # a service thread still inside the world finishes first
            try:
                self.client.disconnect()
            except pybullet.error:
                pass
