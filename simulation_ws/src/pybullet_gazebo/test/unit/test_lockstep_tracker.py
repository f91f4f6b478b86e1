"""The controller's side of lockstep's handshake without ROS: when a process is done, and
what its reports say (pybullet_gazebo/ros/lockstep/tracker.py)."""
import threading
import time
import warnings

from pybullet_gazebo.ros.lockstep.tracker import Tracker

SCAN = ("/m2wr/laser/scan", "/gazebo", 50001)
CLOCK = ("/clock", "/gazebo", 50002)
MS = 1000000                                   # [ns] a millisecond of sim time


def make(reporting=True):
    reports = []
    tracker = Tracker(send=reports.append, reporting=lambda: reporting)
    return tracker, reports


def test_a_callback_is_reported_once_it_returns_with_its_counts():
    tracker, reports = make()
    tracker.callback_started()
    assert not tracker.done() and reports == []
    tracker.wrote("/cmd_vel", "/gazebo", 40000)        # the callback's command
    tracker.callback_ended(*SCAN, count=1)
    assert tracker.done()
    assert len(reports) == 1
    assert reports[0]["taken"] == {SCAN: 1}
    assert reports[0]["written"] == {("/cmd_vel", "/gazebo", 40000): 1}


def test_a_loop_thread_is_due_from_its_tick_until_it_sleeps_again():
    tracker, reports = make()
    tracker.sleep_started(tid=7, start=1000 * MS, duration=50 * MS)     # rate.sleep() at 1 s
    tracker.callback_started()
    tracker.callback_ended(*CLOCK, count=1, now=1020 * MS)             # not yet its time
    assert tracker.done() and reports == []          # a tick that wakes nobody: no news
    tracker.callback_started()
    tracker.callback_ended(*CLOCK, count=1, now=1050 * MS)             # its tick
    assert not tracker.done() and reports == []      # the loop acts first
    tracker.sleep_ended(7)
    tracker.published(7)
    tracker.wrote("/cmd_vel", "/gazebo", 40000)
    tracker.sleep_started(tid=7, start=1050 * MS, duration=50 * MS)     # back to sleep
    assert tracker.done() and len(reports) == 1
    assert reports[0]["taken"] == {CLOCK: 2}
    assert reports[0]["written"] == {("/cmd_vel", "/gazebo", 40000): 1}
    assert reports[0]["next_wake"] == 1100 * MS


def test_a_sleep_begun_before_the_first_clock_counts_from_it():
    tracker, _ = make()
    tracker.sleep_started(tid=7, start=0, duration=50 * MS)      # sim time not set yet
    tracker.time_set(5000 * MS)                                 # first /clock: 5 s
    assert tracker.done()
    tracker.time_set(5049 * MS)
    assert tracker.done()
    tracker.time_set(5050 * MS)
    assert not tracker.done()


def test_time_moving_backwards_wakes_a_sleeper():
    tracker, _ = make()
    tracker.sleep_started(tid=7, start=9000 * MS, duration=50 * MS)
    tracker.time_set(0)                                         # reset_simulation
    assert not tracker.done()


def test_a_thread_that_only_polls_is_done_and_held_until_something_happens():
    tracker, reports = make()
    tracker.sleep_started(tid=7, start=MS, duration=MS)
    tracker.callback_started()
    tracker.callback_ended(*CLOCK, count=1, now=2 * MS)
    tracker.sleep_ended(7)
    assert not tracker.done()                   # woken: due
    tracker.polled(7)                           # the loop's head: still due
    assert not tracker.done()
    released = []

    def second_poll():
        tracker.polled(7)                       # round again without doing anything
        released.append(time.monotonic())
    poller = threading.Thread(target=second_poll)
    poller.start()
    deadline = time.monotonic() + 2
    while not tracker.done() and time.monotonic() < deadline:
        time.sleep(0.001)
    assert tracker.done() and reports               # a poller is done: reported
    time.sleep(0.01)
    assert not released                              # and held, not spinning
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)            # something happened
    assert not tracker.done()                         # it must look again first
    poller.join(2)
    assert released
    tracker.polled(7)                                 # it looked: nothing for it
    assert tracker.done()


def test_a_poller_is_not_held_at_real_time():
    tracker, _ = make(reporting=False)
    tracker.polled(7)
    start = time.monotonic()
    for _ in range(1000):
        tracker.polled(7)
    assert time.monotonic() - start < 0.04           # 1000 polls, none held for POLL_CAP


def test_a_service_call_in_flight_keeps_the_process_busy():
    tracker, reports = make()
    tracker.call_started(tid=7)
    assert not tracker.done()
    tracker.call_answered("/go_to_point_switch", 41000)
    tracker.call_ended(tid=7)
    assert tracker.done()
    assert reports[-1]["called"] == [("/go_to_point_switch", 41000)]
    tracker.handler_started()
    tracker.handler_ended("/wall_follower_switch", 42000)
    assert reports[-1]["served"] == [("/wall_follower_switch", 42000)]
    assert reports[-1]["called"] == []                  # each call reported once


def test_a_message_waiting_in_a_queue_keeps_the_process_busy():
    tracker, reports = make()
    queued = [1]
    tracker.pending_writes = lambda: queued[0]
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    assert not tracker.done() and reports == []
    queued[0] = 0
    tracker.wrote("/cmd_vel", "/gazebo", 40000)
    tracker.unqueued()
    assert tracker.done() and reports[-1]["written"] == {("/cmd_vel", "/gazebo", 40000): 1}


def test_a_due_thread_that_waits_for_the_wall_clock_is_not_waited_for():
    tracker, _ = make()
    tracker.sleep_started(tid=7, start=MS, duration=MS)
    tracker.time_set(2 * MS)
    assert not tracker.done()
    tracker.wall_sleep(7)                       # time.sleep: timed by the machine
    assert tracker.done()


def test_a_sleeper_that_runs_before_its_ticks_callback_ends_is_due_until_it_sleeps():
    """rospy wakes a sleeper inside the /clock callback: the loop may leave rospy.sleep
    (and the sleepers' list) before that callback's end is told. It is at work all the
    same; its report, once it sleeps again, names its next wake-up."""
    tracker, reports = make()
    tracker.sleep_started(tid=7, start=1000 * MS, duration=50 * MS)
    tracker.callback_started()
    tracker.sleep_ended(7)                          # the loop runs first ...
    tracker.callback_ended(*CLOCK, count=1, now=1050 * MS)     # ... then the callback ends
    assert not tracker.done() and reports == []
    tracker.published(7)
    tracker.wrote("/cmd_vel", "/gazebo", 40000)
    tracker.unqueued()                              # its command leaves the queue
    assert not tracker.done() and reports == []     # still at work
    tracker.sleep_started(tid=7, start=1050 * MS, duration=50 * MS)
    assert tracker.done() and len(reports) == 1
    assert reports[0]["next_wake"] == 1100 * MS and reports[0]["taken"] == {CLOCK: 1}


def test_time_sleep_zero_in_a_loop_thread_keeps_it_due():
    """rospy's queued publish yields with time.sleep(0) after each message: a yield, not a
    wait for the wall clock (the hook in rospy_hooks.py; taken for a wait, the loop looked
    done while it was still at work, and two lockstep runs of a 50 Hz loop differed)."""
    import rospy  # noqa: F401  (the project's environment wraps it as it is imported)
    from pybullet_gazebo.ros.lockstep import rospy_hooks
    tracker = rospy_hooks.TRACKER or rospy_hooks.install(report=False)
    counting_only, tracker.counting_only = tracker.counting_only, False
    tid = threading.get_ident()
    try:
        tracker.sleep_started(tid=tid, start=MS, duration=MS)
        tracker.time_set(2 * MS)
        tracker.sleep_ended(tid)
        assert not tracker.done()
        time.sleep(0)
        assert not tracker.done()
        time.sleep(0.001)
        assert tracker.done()
    finally:
        tracker.counting_only = counting_only
        tracker.forget_thread(tid)


def test_dropped_messages_count_as_taken_in():
    tracker, reports = make()
    tracker.dropped(SCAN[0], SCAN[2], 2)        # queue_size=1 kept the newest of three
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    assert reports[-1]["taken"] == {SCAN: 3}


def test_nothing_is_sent_while_the_simulator_does_not_listen():
    tracker, reports = make(reporting=False)
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    tracker.call_started(1)
    tracker.call_answered("/s", 1)
    tracker.call_ended(1)
    assert reports == [] and tracker.done()
    # a call is kept for the simulator that connects later: it waits for word of it
    assert tracker.report_now()["called"] == [("/s", 1)]


def test_a_call_served_before_the_simulator_listens_is_in_the_report_it_gets_on_connecting():
    # the series' bug 1 switches go to point on as both start: go to point may answer before
    # the simulator has subscribed to its reports; bug 1's report names the call, so the
    # simulator waits for go to point's word of it (it waited 30 s for it in a graded run)
    tracker, reports = make(reporting=False)
    tracker.handler_started()
    tracker.handler_ended("/go_to_point_switch", 41000)
    assert reports == [] and tracker.done()
    assert tracker.report_now()["served"] == [("/go_to_point_switch", 41000)]


def test_the_first_clock_that_sets_a_sleepers_wake_up_is_news():
    tracker, reports = make()
    tracker.sleep_started(tid=7, start=0, duration=50 * MS)      # sim time not set yet
    tracker.callback_started()
    tracker.callback_ended(*CLOCK, count=1, now=5000 * MS)       # the first /clock
    assert reports and reports[-1]["next_wake"] == 5050 * MS


def test_a_report_names_the_earliest_wake_up_of_its_sleepers():
    tracker, reports = make()
    tracker.sleep_started(tid=7, start=1000 * MS, duration=50 * MS)
    tracker.sleep_started(tid=8, start=1000 * MS, duration=20 * MS)
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    assert reports[-1]["next_wake"] == 1020 * MS
    tracker.sleep_ended(7)
    tracker.sleep_ended(8)
    tracker.wall_sleep(7)                          # both now wait for the wall clock
    tracker.wall_sleep(8)
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    assert reports[-1]["next_wake"] == 0          # nobody sleeps on sim time


def test_a_thread_handed_a_message_through_a_condition_is_waited_for():
    """A callback that puts the scan in a queue the main loop reads is done with it only
    once the main loop waits again (the Gym environment's pattern)."""
    tracker, reports = make()
    condition = object()                            # stands for a queue's condition
    tracker.cond_wait_started(tid=1, condition=condition)        # main loop: queue.get()
    tracker.callback_started()
    tracker.cond_notified(condition, 1)                           # the callback's put()
    tracker.cond_wait_ended(tid=1, condition=condition)
    tracker.callback_ended(*SCAN, count=1)
    assert not tracker.done() and reports == []                  # the main loop is at work
    tracker.wrote("/cmd_vel", "/gazebo", 40000)
    tracker.cond_wait_started(tid=1, condition=condition)        # back to queue.get()
    assert tracker.done() and reports[-1]["written"] == {("/cmd_vel", "/gazebo", 40000): 1}


def test_a_wait_that_times_out_leaves_its_thread_not_due():
    tracker, _ = make()
    condition = object()
    tracker.cond_wait_started(tid=1, condition=condition)
    tracker.cond_wait_ended(tid=1, condition=condition)          # timed out
    tracker.cond_notified(condition, 1)                          # nobody waits now
    assert tracker.done()


def test_a_sim_time_sleep_counts_from_the_time_the_tracker_was_told():
    """Ticks that come after a loop told the tracker it sleeps (and its process reported
    done) but before it waits do not push its wake-up back: it wakes at the tick the
    simulator waits for (rospy_hooks.sleep_on_sim_time; rospy's own sleep looks at the
    clock again, and the run waited a time-out for a wake-up that never came)."""
    import rospy
    import rospy.rostime
    from pybullet_gazebo.ros.lockstep.rospy_hooks import sleep_on_sim_time
    def set_time(nsecs):                # as rospy's /clock callback does
        with warnings.catch_warnings():             # (rospy calls notifyAll)
            warnings.simplefilter("ignore", DeprecationWarning)
            rospy.rostime._set_rostime(rospy.Time(1, nsecs))
    saved = rospy.rostime._rostime_current, rospy.rostime._rostime_initialized
    rospy.rostime.set_rostime_initialized(True)
    try:
        set_time(0)
        told = rospy.rostime.get_rostime()           # what the tracker was told: 1.00 s
        set_time(10 * MS)                            # a tick before the wait
        woke = []
        sleeper = threading.Thread(target=lambda: woke.append(
            sleep_on_sim_time(told, rospy.Duration(0, 20 * MS)) or time.monotonic()))
        sleeper.start()
        time.sleep(0.05)
        assert woke == []                            # 1.01 s: not yet
        ticked = time.monotonic()
        set_time(20 * MS)                            # its wake-up, 1.02 s
        sleeper.join(2.0)
        assert woke and woke[0] - ticked < 0.2       # at once, not at 1.03 s nor 0.5 s later
    finally:
        rospy.rostime._rostime_current, rospy.rostime._rostime_initialized = saved


def test_a_sleep_begun_before_the_first_clock_counts_from_that_tick_as_the_tracker_does():
    """rospy.sleep before sim time is set: the tracker counts it from the first /clock. A
    second tick may come before the sleeper runs again (its process reported done with the
    wake-up the tracker knows); counted from that one it would sleep past the wake-up the
    simulator waits for."""
    import rospy
    import rospy.rostime
    from pybullet_gazebo.ros.lockstep import rospy_hooks
    def set_time(nsecs):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            rospy.rostime._set_rostime(rospy.Time(1, nsecs))
    saved = (rospy.rostime._rostime_current, rospy.rostime._rostime_initialized,
             rospy_hooks.TRACKER)
    tracker, _ = make()
    rospy_hooks.TRACKER = tracker
    rospy.rostime.set_rostime_initialized(True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        rospy.rostime._set_rostime(rospy.Time(0))              # sim time not set yet
    condition = rospy.rostime.get_rostime_cond()
    try:
        woke = []
        sleeper = threading.Thread(target=lambda: woke.append(
            rospy_hooks.sleep_on_sim_time(rospy.Time(0), rospy.Duration(0, 20 * MS))
            or time.monotonic()))
        with condition:                 # the sleeper sees no tick before the second one
            sleeper.start()
            tracker.sleep_started(sleeper.ident, 0, 20 * MS)
            set_time(0)                                                # the first tick: 1.00 s
            tracker.callback_started()
            tracker.callback_ended(*CLOCK, count=1, now=1000 * MS)    # counted from 1.00 s
            set_time(10 * MS)                                          # 1.01 s
        time.sleep(0.05)
        assert woke == []
        ticked = time.monotonic()
        set_time(20 * MS)                               # its wake-up, as the tracker has it
        sleeper.join(2.0)
        assert woke and woke[0] - ticked < 0.2          # not at 1.03 s, nor a time-out later
    finally:
        (rospy.rostime._rostime_current, rospy.rostime._rostime_initialized,
         rospy_hooks.TRACKER) = saved


def test_a_thread_that_ends_while_due_is_not_waited_for():
    """A poller held, then made due by a callback, whose loop ends instead of looking again
    (rospy's reconnect thread of a simulator that has gone): it does nothing more. Kept due,
    the process was never done again, and the next simulator waited a lockstep_timeout
    for every report of a tool's node that outlived the last one (series_runs, third run)."""
    tracker, reports = make()
    alive = {7}
    tracker.thread_alive = lambda tid: tid in alive
    tracker.polled(7)
    tracker.callback_started()
    tracker.callback_ended(*SCAN, count=1)
    tracker.sleep_started(tid=7, start=MS, duration=MS)
    tracker.time_set(2 * MS)
    tracker.sleep_ended(7)                     # due: at work until it sleeps or polls
    assert not tracker.done()
    alive.clear()                              # it ended instead
    assert tracker.done()
    tracker.call_started(tid=8)
    tracker.call_answered("/gazebo/spawn_urdf_model", 41000)
    tracker.call_ended(tid=8)
    assert reports[-1]["called"] == [("/gazebo/spawn_urdf_model", 41000)]


def test_rospys_own_reconnect_loop_is_not_taken_for_a_busy_loop():
    """rospy's subscriber (re)connect loops call rospy.is_shutdown() between a connection
    attempt and a wall-clock sleep: not the program's loop. The program's own calls are."""
    import rospy
    from rospy.impl import tcpros_pubsub
    from pybullet_gazebo.ros.lockstep import rospy_hooks
    tracker = rospy_hooks.TRACKER or rospy_hooks.install(report=False)
    counting_only, tracker.counting_only = tracker.counting_only, False
    tid = threading.get_ident()

    class Connection:                          # connects at the second attempt
        socket, done, attempts = None, False, 0

        def connect(self, *args, **kwds):
            self.attempts += 1
            if self.attempts == 2:
                self.socket = object()

        def receive_loop(self, callback):
            pass
    tracker.forget_thread(tid)
    try:
        tcpros_pubsub.robust_connect_subscriber(Connection(), "localhost", 1, "http://x:1/",
                                                None, "/odom")
        assert tracker._last.get(tid) is None       # rospy's two polls: not counted
        rospy.is_shutdown()
        assert tracker._last.get(tid) == "poll"     # the program's: counted
    finally:
        tracker.counting_only = counting_only
        tracker.forget_thread(tid)


def test_a_callback_asleep_in_sim_time_has_taken_its_message_in_and_parks_its_connection():
    """rospy.sleep inside a scan callback: the process is done (the simulator would otherwise
    wait for the callback, and the callback for its next tick), the scan counts as taken in,
    and the connection is parked (what comes on it waits until the thread is back)."""
    tracker, reports = make()
    tracker.callback_started(tid=3, key=SCAN, count=1)
    tracker.sleep_started(tid=3, start=1000 * MS, duration=100 * MS)
    assert tracker.done()
    assert reports[-1]["taken"] == {SCAN: 1} and reports[-1]["parked"] == [SCAN]
    assert reports[-1]["next_wake"] == 1100 * MS
    assert tracker.parked() == {SCAN}
    tracker.callback_started()
    tracker.callback_ended(*CLOCK, count=1, now=1100 * MS)            # its wake-up
    tracker.sleep_ended(tid=3)
    assert not tracker.done() and tracker.parked() == set()           # back at work
    tracker.wrote("/cmd_vel", "/gazebo", 40000)
    tracker.callback_ended(*SCAN, count=1, tid=3)                      # the callback returns
    assert tracker.done()
    assert tracker.counts_taken()[SCAN] == 1                           # counted once
    assert reports[-1]["parked"] == []
