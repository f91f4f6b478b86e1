"""/clock as clock_topic.py shares it out: a loop node (one that commands a robot or reads its
sensors or odometry) gets every tick; a watching node (robot_state_publisher, an rviz showing
the robot and TF) gets Gazebo's cadence at real time and, faster than real time, at most
max(watch_rate, pub_clock_frequency) ticks per wall second; when paused, everyone ends on the
same time. The publisher is replaced by a recorder with fake connections and the wall clock by
a counter, so no master is needed."""
import rospy

from pybullet_gazebo.ros import clock_topic

STEP = 0.005            # [s] sim


class Connection:
    def __init__(self, node):
        self.endpoint_id = node


class Recorder:
    """Stands in for DirectPublisher: keeps the sim times each subscriber node got."""

    nodes = ("/reading_laser", "/rviz", "/robot_state_publisher")

    def __init__(self, topic, data_class):
        self.connections = [Connection(n) for n in self.nodes]
        self.got = {n: [] for n in self.nodes}

    def get_num_connections(self):
        return len(self.connections)

    def publish(self, msg, share=None):
        for connection in self.connections:
            if share is None or share(connection):
                self.got[connection.endpoint_id].append(msg.clock.to_sec())


class WallClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def make_clock(monkeypatch, clock_rate=100.0, watch_rate=30.0):
    monkeypatch.setattr(clock_topic, "DirectPublisher", Recorder)
    wall = WallClock()
    clock = clock_topic.ClockTopic(clock_rate, watch_rate, lambda: {"/reading_laser"},
                                   clock=wall)
    return clock, wall, clock.publisher.got


def run(clock, wall, seconds, x_real_time, start=0.0):
    """Steps of 5 ms for `seconds` of sim time at `x_real_time`: /clock every 2 steps (100 Hz)
    and, as the simulator does, an extra tick at every 10th step (a scan between two)."""
    for k in range(int(round(seconds / STEP))):
        wall.now += STEP / x_real_time
        if k % 2 == 0 or k % 10 == 5:
            clock.publish(rospy.Time.from_sec(start + k * STEP))


def test_at_real_time_a_watcher_gets_gazebos_cadence(monkeypatch):
    clock, wall, got = make_clock(monkeypatch)
    run(clock, wall, 10.0, 1.0)
    assert len(got["/reading_laser"]) == 1000 + 200       # every tick, the extra ones too
    for node in ("/rviz", "/robot_state_publisher"):
        assert len(got[node]) == 1000                      # 100 Hz of sim time, none lost
        gaps = [b - a for a, b in zip(got[node], got[node][1:])]
        assert min(gaps) > 0.0099 and max(gaps) < 0.0101


def run_two_robots(clock, wall, seconds):
    """As the simulator's _clock_due sends /clock: every 2 steps counted from the last tick,
    and a tick at each step with readings, here two robots' scans at 20 Hz, spawned at
    different steps (phases 1 and 6 of every 10 steps). At real time."""
    last = None
    for k in range(int(round(seconds / STEP))):
        wall.now += STEP
        if k % 10 in (1, 6) or last is None or k - last >= 2:
            clock.publish(rospy.Time.from_sec(k * STEP))
            last = k


def test_with_two_robots_scanning_at_different_phases_a_watcher_still_gets_100_hz(monkeypatch):
    clock, wall, got = make_clock(monkeypatch)
    run_two_robots(clock, wall, 10.0)
    assert len(got["/reading_laser"]) == 1200              # ticks at 1, 3, 5, 6, 8, 10 of 10
    for node in ("/rviz", "/robot_state_publisher"):
        # one in each 10 ms of sim time: what Gazebo's 100 Hz gives in those 10 s
        assert 999 <= len(got[node]) <= 1001
        slots = [round(t * 1000) // 10 for t in got[node]]
        assert len(set(slots)) == len(slots)


def test_faster_than_real_time_a_watcher_is_held_to_the_wall_rate(monkeypatch):
    clock, wall, got = make_clock(monkeypatch, clock_rate=20.0, watch_rate=30.0)
    run(clock, wall, 300.0, 30.0)                          # 10 s of wall time
    assert len(got["/reading_laser"]) == 30000 + 6000      # the controller: every tick
    for node in ("/rviz", "/robot_state_publisher"):
        # at most 30 per wall second (plus the token bucket's half second's worth), and
        # never fewer than real time would give in those 10 s of wall time (20 Hz: 200)
        assert 200 <= len(got[node]) <= 30 * 10 + 15
        assert got[node] == sorted(got[node])


def test_paused_everyone_ends_on_the_same_time(monkeypatch):
    clock, wall, got = make_clock(monkeypatch, clock_rate=20.0)
    run(clock, wall, 20.0, 30.0)
    last = got["/reading_laser"][-1]
    clock.flush()
    assert got["/rviz"][-1] == got["/robot_state_publisher"][-1] == last
    assert got["/reading_laser"].count(last) == 1          # the controller had it already
    ticks = len(got["/rviz"])
    clock.flush()                                          # nothing owed any more
    assert len(got["/rviz"]) == ticks


def test_after_a_reset_a_watcher_gets_the_new_time_at_once(monkeypatch):
    clock, wall, got = make_clock(monkeypatch)
    run(clock, wall, 2.0, 1.0, start=50.0)
    run(clock, wall, 0.5, 1.0, start=0.0)                   # reset_simulation: back to 0
    assert got["/rviz"][-1] < 1.0
    assert got["/rviz"][0] == 50.0


def test_watch_rate_zero_sends_every_tick_to_everyone(monkeypatch):
    clock, wall, got = make_clock(monkeypatch, clock_rate=20.0, watch_rate=0.0)
    run(clock, wall, 30.0, 30.0)
    assert len(got["/rviz"]) == len(got["/reading_laser"]) == 3000 + 600
