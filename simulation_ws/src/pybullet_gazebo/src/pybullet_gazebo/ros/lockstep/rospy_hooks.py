"""rospy, told to the process's Tracker (tracker.py), and the reports sent on /lockstep/report.

install() wraps, in the rospy module of this process:
  _SubscriberImpl.receive_callback   the callbacks of each message (taken in once they return)
  TCPROSSub.read_messages            messages a subscriber's queue_size drops unread
  TCPROSTransport.write_data         messages written to a subscriber (and to a queued
                                     connection's socket: its queue empties)
  QueuedConnection.write_data        messages entering a queued connection's queue
  rospy.sleep, rospy.timer.sleep     a thread sleeping until a sim time (rospy.Rate, Timer)
  rospy.is_shutdown                  a thread polling (the program's: not rospy's own)
  time.sleep                         a thread waiting for the wall clock: not waited for
  threading.Condition.wait, notify   a thread handed work by another (queue.Queue, Event)
  ServiceProxy.call                  a service call in flight; its answer read
  ServiceImpl._handle_request        a service handler running
  rospy.init_node                    opens the report publisher, and subscribes to the ticks
                                     a simulator may send with the readings (tick_hold.py)
A process whose rospy is wrapped behaves as before: the wrappers count and return what rospy
returns. Nothing is sent until the simulator subscribes to /lockstep/report, which it does
only in lockstep.

Connections are named by the TCP port of the subscriber's end (lockstep_msgs/LockstepReport).
"""
import os
import select
import socket
import sys
import threading
import time
import weakref

from pybullet_gazebo.ros.lockstep import CLOCK_TOPIC, EXPECT_TOPIC, REPORT_TOPIC
from pybullet_gazebo.ros.lockstep.tick_hold import HOLD, TICK, TickHold
from pybullet_gazebo.ros.lockstep.tracker import Tracker

NOT_COUNTED = {"/rosout", REPORT_TOPIC}     # topics no controller acts on

TRACKER = None                              # this process's Tracker, once installed
TICK_HOLD = None                            # ... and its TickHold (controllers only)
_publisher = None
_reports = True                             # False in the simulator: it counts, never reports


def install(report=True):
    """Wraps this process's rospy (once) and returns its Tracker. `report` false: count
    only, never report (the simulator itself)."""
    global TRACKER, TICK_HOLD, _reports
    if not report:
        _reports = False
    if TRACKER is not None:
        if not report:
            TRACKER.reporting = lambda: False
            TRACKER.counting_only = True
        return TRACKER
    import genpy
    import rospy
    import rospy.core
    import rospy.rostime
    import rospy.timer
    import rospy.topics
    from rospy.impl import tcpros_base, tcpros_pubsub, tcpros_service

    tracker = TRACKER = Tracker(send=_send, reporting=_reporting if report else lambda: False)
    tracker.counting_only = not report
    hold = TICK_HOLD = TickHold(tracker.counts_taken, tracker.parked)
    tracker.on_change = hold.taken_changed      # (the simulator sets its own)
    get_ident = threading.get_ident
    in_callback = threading.local()      # .depth: callbacks and handlers this thread is in
    waiting = weakref.WeakSet()          # queued connections with messages not yet written

    def pending_writes():
        return any(not q._connection.done for q in list(waiting))
    tracker.pending_writes = pending_writes
    # (threading's table of the threads it started and has not seen end: rospy starts all
    # of a program's threads through threading)
    tracker.thread_alive = lambda tid: tid in threading._active

    def after_fork():
        """A warm interpreter's child (m2wr_tools.running.zygote): nothing of its parent's threads,
        calls, connections or report publisher is its own."""
        global _publisher
        _publisher = None
        waiting.clear()
        tracker.start_over()
        hold.start_over()
        tracker._changed._lockstep_untracked = True
    os.register_at_fork(after_in_child=after_fork)

    # --- taking in ----------------------------------------------------------------------
    receive_callback = rospy.topics._SubscriberImpl.receive_callback

    def counted_receive_callback(self, msgs, connection):
        topic = self.resolved_name
        if topic in NOT_COUNTED:
            return receive_callback(self, msgs, connection)
        tid, port = get_ident(), _local_port(connection)
        tracker.callback_started(tid, (topic, connection.callerid_pub, port), len(msgs))
        in_callback.depth = getattr(in_callback, "depth", 0) + 1
        try:
            return receive_callback(self, msgs, connection)
        finally:
            in_callback.depth -= 1
            now, news = None, None
            if topic == CLOCK_TOPIC:
                now = rospy.rostime.get_rostime().to_nsec()
            elif topic == EXPECT_TOPIC:
                # a tick sent with word (tick_hold.py) is news when it wakes a sleeper, as a
                # /clock tick; a HOLD always (the simulator counts on it from then on)
                if any(m.kind == TICK for m in msgs):
                    now = rospy.rostime.get_rostime().to_nsec()
                news = any(m.kind == HOLD for m in msgs) and \
                    connection.callerid_pub in _clock_publishers()
            tracker.callback_ended(topic, connection.callerid_pub, port, len(msgs), now, news,
                                   tid)
    rospy.topics._SubscriberImpl.receive_callback = counted_receive_callback

    read_messages = tcpros_pubsub.TCPROSSub.read_messages

    def counted_read_messages(self, b, msg_queue, sock):
        keep = self.queue_size
        if not keep or keep < 0:
            return read_messages(self, b, msg_queue, sock)
        self.queue_size = None           # read all, then drop as rospy would, counted
        try:
            read_messages(self, b, msg_queue, sock)
        finally:
            self.queue_size = keep
        extra = len(msg_queue) - keep
        if extra > 0:
            del msg_queue[:extra]
            tracker.dropped(self.resolved_name, sock.getsockname()[1], extra)
    tcpros_pubsub.TCPROSSub.read_messages = counted_read_messages

    # --- writing out ----------------------------------------------------------------------
    write_data = tcpros_base.TCPROSTransport.write_data
    publishing = tcpros_pubsub.TCPROSPub

    def written_and_counted(transport, data):
        result = write_data(transport, data)
        protocol = transport.protocol
        if isinstance(protocol, publishing) and protocol.resolved_name not in NOT_COUNTED:
            tracker.wrote(protocol.resolved_name, transport.endpoint_id, _peer_port(transport))
        return result

    def counted_write_data(self, data):
        outer = getattr(self, "_lockstep_queue", None)
        try:
            return written_and_counted(self, data)
        finally:
            if outer is not None:
                with outer._lock:            # the queue's lock: += and -= from two threads
                    outer._lockstep_pending -= 1
                    if outer._lockstep_pending <= 0:
                        waiting.discard(outer)
                tracker.unqueued()
    tcpros_base.TCPROSTransport.write_data = counted_write_data

    queued_init = tcpros_pubsub.QueuedConnection.__init__
    queued_write = tcpros_pubsub.QueuedConnection.write_data

    def tracked_queued_init(self, connection, queue_size):
        # the thread writing directly, if any (set before rospy's init, during which the
        # connection may already close and call closed_while_writing)
        self._lockstep_writer = None
        queued_init(self, connection, queue_size)
        self._lockstep_pending = 0
        # (/rosout stays queued: no controller waits for it, so its write is left to the
        # queue's thread, off the path to the next report)
        self._lockstep_at_once = getattr(connection.protocol, "resolved_name", None) \
            not in NOT_COUNTED
        connection._lockstep_queue = self

    def counted_queued_write(self, data):
        with self._lock:
            if _listening and self._lockstep_at_once and self._lockstep_pending == 0 and \
                    not self._error and \
                    _room_for(self._connection, len(data)):
                # written by the publishing thread (under the queue's lock, so the queue's
                # thread cannot start a write meanwhile), as that thread would write it: out
                # when publish() returns, so the subscriber gets it and the process is done
                # without waiting for the queue's thread to wake and take the GIL
                self._lockstep_writer = get_ident()
                try:
                    return written_and_counted(self._connection, data)
                finally:
                    self._lockstep_writer = None
            if not (self._queue_size > 0 and len(self._queue) == self._queue_size):
                self._lockstep_pending += 1     # (a full queue drops its oldest: no change)
                waiting.add(self)
        return queued_write(self, data)

    closed_callback = tcpros_pubsub.QueuedConnection._closed_connection_callback

    def closed_while_writing(self, connection):
        # a broken pipe in the write above closes the transport, which calls this back in
        # the same thread, with the queue's lock held: wake the queue's thread (it ends, the
        # transport being done) without taking the lock again, which would wait forever
        if self._lockstep_writer == get_ident():
            self._cond_data_available.notify()
            return
        closed_callback(self, connection)
    tcpros_pubsub.QueuedConnection.__init__ = tracked_queued_init
    tcpros_pubsub.QueuedConnection.write_data = counted_queued_write
    tcpros_pubsub.QueuedConnection._closed_connection_callback = closed_while_writing

    publish = rospy.topics.Publisher.publish

    def noted_publish(self, *args, **kwds):
        tracker.published(get_ident())
        return publish(self, *args, **kwds)
    rospy.topics.Publisher.publish = noted_publish

    # --- sleeping and polling -------------------------------------------------------------
    sleep = rospy.timer.sleep

    def tracked_sleep(duration):
        if rospy.rostime.is_wallclock():
            return sleep(duration)
        if not isinstance(duration, genpy.Duration):
            duration = genpy.Duration.from_sec(duration)
        length = duration.to_nsec()
        if length <= 0:
            return sleep(duration)
        tid = get_ident()
        initial = rospy.rostime.get_rostime()
        tracker.sleep_started(tid, initial.to_nsec(), length)
        try:
            return sleep_on_sim_time(initial, duration)
        finally:
            tracker.sleep_ended(tid)
    rospy.timer.sleep = rospy.sleep = tracked_sleep

    wall_sleep = time.sleep

    def noted_wall_sleep(seconds):
        # time.sleep(0) only yields the processor (rospy's queued publish does it after
        # every message): the thread is still at work
        if seconds > 0:
            tracker.wall_sleep(get_ident())
        return wall_sleep(seconds)
    time.sleep = noted_wall_sleep

    # rospy.sleep waits on rospy's time condition: its sleepers are tracked by wake-up time
    rospy.rostime.get_rostime_cond()._lockstep_untracked = True
    condition_wait = threading.Condition.wait
    condition_notify = threading.Condition.notify

    def tracked_wait(self, timeout=None):
        if getattr(self, "_lockstep_untracked", False):
            return condition_wait(self, timeout)
        tid = get_ident()
        tracker.cond_wait_started(tid, self)
        try:
            return condition_wait(self, timeout)
        finally:
            tracker.cond_wait_ended(tid, self)

    def tracked_notify(self, n=1):
        # only a callback's or a handler's notify hands a message on; a thread started or
        # woken by anything else (rospy's own threads) may block next where no hook sees it
        if getattr(in_callback, "depth", 0) and not getattr(self, "_lockstep_untracked", False):
            tracker.cond_notified(self, n)
        return condition_notify(self, n)
    threading.Condition.wait = tracked_wait
    threading.Condition.notify = tracked_notify

    is_shutdown = rospy.core.is_shutdown

    def polled_is_shutdown():
        # rospy's own connect and reconnect loops ask too (between a connection attempt
        # and a wall-clock sleep): they are not the program's loop waiting for a change,
        # and a thread of theirs held here would come back to connect 50 ms late
        if not sys._getframe(1).f_globals.get("__name__", "").startswith("rospy."):
            tracker.polled(get_ident())
        return is_shutdown()
    rospy.is_shutdown = polled_is_shutdown

    # --- services -------------------------------------------------------------------------
    call = tcpros_service.ServiceProxy.call

    def tracked_call(self, *args, **kwds):
        tid = get_ident()
        tracker.call_started(tid)
        try:
            return call(self, *args, **kwds)
        finally:
            tracker.call_ended(tid)
    tcpros_service.ServiceProxy.call = tracked_call

    read_answer = tcpros_service.TCPROSServiceClient.read_messages

    def noted_read_answer(self, b, msg_queue, sock):
        read_answer(self, b, msg_queue, sock)
        if msg_queue:
            tracker.call_answered(self.resolved_name, sock.getsockname()[1])
    tcpros_service.TCPROSServiceClient.read_messages = noted_read_answer

    handle_request = tcpros_service.ServiceImpl._handle_request

    def tracked_handle_request(self, transport, request):
        tracker.handler_started()
        in_callback.depth = getattr(in_callback, "depth", 0) + 1
        port = 0
        try:
            port = _peer_port(transport)
            return handle_request(self, transport, request)
        finally:
            in_callback.depth -= 1
            tracker.handler_ended(self.resolved_name, port,
                                  getattr(transport, "endpoint_id", None))
    tcpros_service.ServiceImpl._handle_request = tracked_handle_request

    # --- the report publisher -----------------------------------------------------------
    init_node = rospy.client.init_node

    def reporting_init_node(*args, **kwds):
        result = init_node(*args, **kwds)
        if _reports:
            try:
                _open_publisher()
                _subscribe_ticks(hold)
            except ImportError:         # lockstep_msgs not built: the process is not heard
                pass
        return result
    rospy.init_node = rospy.client.init_node = reporting_init_node
    return tracker


def sleep_on_sim_time(initial, duration):
    """rospy.timer.sleep on sim time from `initial`, the same but for two things, each
    of which held lockstep runs for a time-out and made them differ:
      - it counts from the time the tracker was told (`initial`), not from a second
        look at the clock: once told, the process may report done, and ticks may come
        before this thread waits; counted from a later tick, it would sleep past the
        wake-up the simulator waits for;
      - the time is tested under the time condition's lock: rospy tests it outside,
        and a tick that comes between its test and its wait is lost to the sleeper
        until the wait's 0.5 s (wall) run out (at real time the next tick wakes it,
        one tick late; in lockstep there is no next tick until the loop is done).
    A sleep begun before the first /clock counts from that tick, as the tracker does: once
    the tracker has it, the process may report done and more ticks may come before this
    thread runs again."""
    import genpy
    import rospy
    get_rostime = rospy.rostime.get_rostime
    condition = rospy.rostime.get_rostime_cond()
    with condition:
        while initial == genpy.Time(0) and not rospy.core.is_shutdown():
            condition.wait(0.3)                 # sim time not set yet
            initial = _counted_from(get_rostime())
        wake = initial + duration
        while initial <= get_rostime() < wake and not rospy.core.is_shutdown():
            condition.wait(0.5)
        now = get_rostime()
    if now < initial:
        raise rospy.exceptions.ROSTimeMovedBackwardsException((initial - now).to_sec())
    if rospy.core.is_shutdown():
        raise rospy.exceptions.ROSInterruptException("ROS shutdown request")


def _counted_from(now):
    """The first /clock's time, as this thread's sleep was counted from by the tracker (it
    saw that tick first); `now` (the time after it) when the tracker has none."""
    tracker = TRACKER
    start = tracker.sleep_start(threading.get_ident()) if tracker is not None else None
    return now if start is None else type(now)(0, start)     # (genpy carries the seconds)


def watch_only():
    """This process only watches (records, measures): lockstep need not wait for it, as for a
    display. Call after rospy.init_node; without the hooks it does nothing."""
    if TRACKER is None or TRACKER.watcher:
        return
    TRACKER.watcher = True
    if _reporting():
        report = TRACKER.report_now()
        if report is not None:
            _send(report)


def inbound_connections():
    """{(topic, publisher, port)} of this process's subscriber connections now (keyed as the
    Tracker counts them)."""
    from rospy.impl.registration import get_topic_manager
    keys = set()
    for topic, impl in list(get_topic_manager().subs.items()):
        if topic in NOT_COUNTED:
            continue
        for connection in list(impl.connections):
            keys.add((topic, connection.callerid_pub, _local_port(connection)))
    return keys


def outbound_connections():
    """{(topic, subscriber, port)} of this process's publisher connections now."""
    from rospy.impl.registration import get_topic_manager
    keys = set()
    for topic, impl in list(get_topic_manager().pubs.items()):
        if topic in NOT_COUNTED:
            continue
        for connection in list(impl.connections):
            keys.add((topic, connection.endpoint_id, _peer_port(connection)))
    return keys


def _local_port(connection):
    return _port(connection, "getsockname")


def _peer_port(connection):
    return _port(connection, "getpeername")


peer_port = _peer_port           # (for tick_word.py: ticks sent with the readings)


def _port(connection, end):
    """The TCP port of the connection's subscriber end, kept once known. 0 while it has no
    socket yet (rospy lists a subscriber's connection before it connects) and not kept: a 0
    kept would name the connection wrongly for good, and a report's counts on it would never
    be matched to the simulator's."""
    port = getattr(connection, "_lockstep_port", None)
    if port is None:
        try:
            port = getattr(connection.socket, end)()[1]
        except (AttributeError, OSError):
            return 0
        connection._lockstep_port = port
    return port


def _open_publisher():
    """The report publisher, written in the reporting thread (no queue: a report must leave
    before the thread goes on). A simulator that connects gets the counts as they are at once
    (or, if the process is at work, its next report); not latched: rospy would send the
    latched report again after that one, and the service calls a report names are news
    once."""
    global _publisher
    import warnings

    import rospy
    from lockstep_msgs.msg import LockstepReport

    class _OnConnect(rospy.SubscribeListener):
        def peer_subscribe(self, topic_name, topic_publish, peer_publish):
            report = TRACKER.report_now()
            if report is not None:
                peer_publish(_message(report))

    with warnings.catch_warnings():          # rospy warns when queue_size is None: on purpose
        warnings.simplefilter("ignore", SyntaxWarning)
        _publisher = rospy.Publisher(REPORT_TOPIC, LockstepReport, queue_size=None,
                                     subscriber_listener=_OnConnect())


def _subscribe_ticks(hold):
    """The ticks a simulator in lockstep sends this process with word of what they follow
    (tick_hold.py), read in a thread of rospy's; nothing comes unless one decides to."""
    import rospy
    import rospy.rostime
    from lockstep_msgs.msg import LockstepExpect

    def heard(msg):
        simulator = msg._connection_header.get("callerid")
        if simulator not in _clock_publishers():
            return              # only the node that sends this process /clock sets its time
        if msg.kind == HOLD:
            hold.heard_hold(simulator, msg.clock_port, msg.clock_count)
        elif msg.kind == TICK:
            hold.wait(simulator, {(t, port): n for t, port, n in zip(msg.topics, msg.ports,
                                                                       msg.counts)},
                      time.monotonic)
            rospy.rostime._set_rostime(msg.clock)      # what rospy's /clock subscriber does

    rospy.Subscriber(EXPECT_TOPIC, LockstepExpect, heard, queue_size=None, tcp_nodelay=True)


def _clock_publishers():
    """The nodes this process's /clock subscriber is connected to (the simulator)."""
    from rospy.impl.registration import get_topic_manager
    impl = get_topic_manager().get_subscriber_impl(CLOCK_TOPIC)
    return {c.callerid_pub for c in list(impl.connections)} if impl is not None else set()


def _room_for(connection, size):
    """Whether `size` bytes fit in the connection's socket now, so that writing them cannot
    block the publishing thread; a subscriber that does not keep up gets rospy's queue. A
    writable TCP socket has at least a few kB free: larger messages keep the queue."""
    sock = getattr(connection, "socket", None)
    if sock is None or size > 4096:
        return False
    try:
        return bool(select.select([], [sock], [], 0)[1])
    except (OSError, ValueError):
        return False


_listening = False          # the last _reporting() found a simulator listening


def _reporting():
    """Whether a simulator listens: a live connection on the report publisher. rospy keeps a
    connection whose subscriber has gone until a write to it fails, and the first write after
    the peer closed does not fail: that report, and the service calls it names (news once),
    would be lost. A process that outlives one simulator and calls the next one's service
    (a tool's node spawning the robot, run after run) then held that simulator for a
    lockstep_timeout, waiting for word of the call. So connections whose peer has closed
    are dropped first, and the report waits for the next simulator's connection."""
    global _listening
    publisher = _publisher
    if publisher is None:
        _listening = False
        return False
    impl = publisher.impl
    for connection in list(impl.connections):
        if _peer_closed(connection):
            impl.remove_connection(connection)
            connection.close()
    _listening = publisher.get_num_connections() > 0
    return _listening


def _peer_closed(connection):
    """True when the subscriber's end of a publisher connection has closed. A subscriber
    sends nothing after the connection header, so a readable socket is one at its end."""
    sock = getattr(connection, "socket", None)
    if sock is None:
        return False
    try:
        if not select.select([sock], [], [], 0)[0]:
            return False
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except BlockingIOError:
        return False
    except (OSError, ValueError):           # reset by the peer, or closed here already
        return True


def _message(report):
    from lockstep_msgs.msg import LockstepReport
    msg = LockstepReport(pid=os.getpid(), seq=report["seq"], next_wake=report["next_wake"],
                         watcher=report["watcher"])
    for key, count in report["taken"].items():
        msg.in_topics.append(key[0])
        msg.in_peers.append(key[1])
        msg.in_ports.append(key[2])
        msg.in_counts.append(count)
    for key, count in report["written"].items():
        msg.out_topics.append(key[0])
        msg.out_peers.append(key[1])
        msg.out_ports.append(key[2])
        msg.out_counts.append(count)
    for topic, peer, port in report["parked"]:
        msg.parked_topics.append(topic)
        msg.parked_peers.append(peer)
        msg.parked_ports.append(port)
    for service, port in report["served"]:
        msg.served_services.append(service)
        msg.served_ports.append(port)
    for service, port in report["called"]:
        msg.called_services.append(service)
        msg.called_ports.append(port)
    return msg


def _send(report):
    publisher = _publisher
    if publisher is not None:
        try:
            publisher.publish(_message(report))
        except Exception:       # noqa: BLE001 (shutting down: the simulator no longer waits)
            pass
