"""World.advance runs quiet stretches of physics steps in one Bullet call: everything a user
sees (poses, scans with their noise, odometry, contact events, sim time) is bit for bit what
stepping one step at a time gives, and the stretches really are batched."""
import math
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import batching, registry
from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.part import SCHEDULE_SLACK, Part, next_period_time
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
STEP = 0.005          # [s]
CONTROL = 20          # physics steps per command, as the Gym environment's 10 Hz
# world02: m2wr on its wheels heading -y, row A's face ~1.7 m ahead (0.5 m/s reaches it)
FACING_ROW_A = Pose.from_xyz_rpy(0, 7.0, 0.1, 0, 0, -math.pi / 2)


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture(scope="module")
def world02():
    return load_world(os.path.join(SRC, "my_worlds", "worlds", "world02.world"),
                      model_path_from_env(MODELS))


@pytest.fixture
def make_world():
    clients = []

    def make(spec, seed=3):
        client = BulletClient(connection_mode=pybullet.DIRECT)
        clients.append(client)
        return World(client, spec, STEP, seed=seed, warn=lambda message: None)
    yield make
    for client in clients:
        client.disconnect()


class Calls:
    """Counts the Bullet calls of a World and the steps they made."""

    def __init__(self, world):
        self.calls, self.steps = 0, 0
        step = world.stepper.batcher.step

        def counted(step_size, k):
            self.calls += 1
            self.steps += k
            step(step_size, k)
        world.stepper.batcher.step = counted


def state(world, robot):
    client = world.client
    return (world.step_count, world.sim_time, client.getBasePositionAndOrientation(robot.body_id),
            client.getBaseVelocity(robot.body_id),
            tuple(s[:2] for s in client.getJointStates(robot.body_id,
                                                       range(client.getNumJoints(robot.body_id)))))


def readings_record(readings):
    """What each reading says, comparable bit for bit."""
    out = []
    for r in readings:
        data = r.data
        if hasattr(data, "ranges"):
            out.append(("scan", data.stamp, data.ranges.tobytes()))
        elif hasattr(data, "pose"):
            out.append(("odom", data.pose.position, data.pose.orientation,
                        tuple(data.linear), tuple(data.angular)))
        else:
            out.append(("joints", tuple(data.positions), tuple(data.velocities)))
    return out


def drive(world, robot, commands, batched, between=None):
    """Each command held for CONTROL steps, by advance (batched) or by step; returns the
    state and the readings after each, and the contact events."""
    drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
    trace = []
    for index, command in enumerate(commands):
        if between is not None:
            between(index)
        drive_part.set_command(*command)
        if batched:
            touched = set()
            readings = world.advance(CONTROL, touched=touched)
        else:
            readings, touched = [], set()
            for _ in range(CONTROL):
                readings += world.step()
                touched.update(world.touching())
        trace.append((state(world, robot), readings_record(readings), sorted(touched)))
    return trace, list(world.contact_events)


COMMANDS = [(0.0, 0.0), (0.5, 0.0), (0.5, 0.6), (0.0, 0.0), (-0.3, -0.8), (0.6, 0.2),
            (0.0, 1.0), (0.3, 0.0)] * 2


def test_driving_and_turning_in_world02_is_bit_identical_and_batched(make_world, world02,
                                                                     m2wr_urdf):
    runs = {}
    for batched in (False, True):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.1, 0, 0, -0.4))
        calls = Calls(world)
        runs[batched] = drive(world, robot, COMMANDS, batched), calls
    (single, _), single_calls = runs[False]
    (trace, _), calls = runs[True]
    assert trace == single                        # poses, velocities, joints, readings
    assert single_calls.calls == single_calls.steps == calls.steps == len(COMMANDS) * CONTROL
    assert calls.calls < calls.steps / 3          # most of it in stretches of 9 steps
    scans = [r for _, readings, _ in trace for r in readings if r[0] == "scan"]
    assert len(scans) == len(COMMANDS) * 2        # 20 Hz: every scan read, noise and all


def test_driving_into_a_barrier_gives_the_same_contact_events(make_world, world02, m2wr_urdf):
    """Row A's face is ~1.7 m ahead: the robot drives into it at 0.5 m/s and pushes on."""
    runs = {}
    for batched in (False, True):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
        calls = Calls(world)
        runs[batched] = drive(world, robot, [(0.5, 0.0)] * 30 + [(-0.5, 0.0)] * 5, batched), calls
    (single, single_events), _ = runs[False]
    (trace, events), calls = runs[True]
    assert events and events[0].other.startswith("jersey_barrier")
    assert events == single_events                # same onsets, same sim times
    assert trace == single                        # touched sets step by step too
    assert any(touched for _, _, touched in trace)
    assert calls.calls < calls.steps / 2          # batched while clear of the barrier


def test_until_news_stops_at_each_reading_and_each_change_of_touches(make_world, world02,
                                                                     m2wr_urdf):
    """The ROS loop's way (advance(n, until_news=True), publishing after each call): every
    call ends at the step that brought readings or changed the touches, never later, so
    each is published at its own sim time; and the run is bit for bit single stepping's."""
    commands = [(0.5, 0.0)] * 30 + [(-0.5, 0.0)] * 5         # into row A's face and back
    single_world = make_world(world02)
    single_robot = single_world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
    world = make_world(world02)
    robot = world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
    calls = Calls(world)
    parts = [next(p for p in r.parts if isinstance(p, DiffDrive)) for r in (single_robot, robot)]
    news_steps, single_news = [], []
    for command in commands:
        for part in parts:
            part.set_command(*command)
        start = world.step_count
        for _ in range(CONTROL):
            touching = single_world.touching()
            readings = single_world.step()
            if readings or single_world.touching() != touching:
                single_news.append((single_world.step_count, readings_record(readings),
                                    single_world.touching()))
        while world.step_count < start + CONTROL:
            touching = world.touching()
            readings = world.advance(start + CONTROL - world.step_count, until_news=True)
            if readings or world.touching() != touching:
                news_steps.append((world.step_count, readings_record(readings),
                                   world.touching()))
            else:
                assert world.step_count == start + CONTROL     # no news: it ran them all
        assert state(world, robot) == state(single_world, single_robot)
    assert news_steps == single_news              # the same news at the same steps
    assert any(touching for _, _, touching in news_steps)
    assert list(world.contact_events) == list(single_world.contact_events)
    assert calls.calls < calls.steps / 2          # still batched between the news


def test_pressed_on_a_barrier_it_steps_one_by_one_and_reads_contacts_after_each(
        make_world, world02, m2wr_urdf):
    """Pushing on a barrier the guard refuses every batch: each step is one Bullet call and
    the contacts are read after each (the events match single stepping: test above), but
    the parts' hooks run only at their own times, not at every step."""
    world = make_world(world02)
    robot = world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
    drive(world, robot, [(0.5, 0.0)] * 30, batched=True)          # on the barrier by now
    assert world.touching()
    calls, counts = Calls(world), {"reads": 0, "hooks": 0}
    update = world.contacts.update
    drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
    hook = drive_part.before_step

    def read(*args):
        counts["reads"] += 1
        return update(*args)

    def counted_hook(*args):
        counts["hooks"] += 1
        hook(*args)
    world.contacts.update, drive_part.before_step = read, counted_hook
    guard = world.stepper.batcher.safe_time

    def counted_guard(*args, **kwargs):
        counts["guard"] = counts.get("guard", 0) + 1
        return guard(*args, **kwargs)
    world.stepper.batcher.safe_time = counted_guard
    touched = set()
    world.advance(100, touched=touched)
    assert touched and all(other.startswith("jersey_barrier") for _, other in touched)
    assert calls.calls == calls.steps == 100
    assert counts["reads"] == 100
    assert counts["hooks"] < 30                   # the drive's 20 Hz, not every step
    assert "guard" not in counts                  # touching: the guard is not even asked


def test_a_wrench_and_a_reset_in_between_stay_identical(make_world, world02, m2wr_urdf):
    """A body wrench on the chassis for 0.3 s (applied per step: no batch while it is
    scheduled), and reset_simulation half way."""
    runs = {}
    for batched in (False, True):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(-2, 0, 0.1, 0, 0, 1.0))

        def between(index, world=world, robot=robot):
            if index == 3:
                world.wrenches.add_body_wrench("m2wr::link_chassis", robot.body_id, -1,
                                               (0.0, 8.0, 0.0), (0.0, 0.0, 1.5),
                                               world.sim_time + 0.02, 0.3, world.sim_time)
            if index == 8:
                world.reset_simulation()
        runs[batched] = drive(world, robot, COMMANDS, batched, between)
    assert runs[True] == runs[False]


class EveryStep(Part):
    """A part that says nothing of when it acts: the World must step one step at a time."""
    KEY = "libtest_every_step.so"

    def __init__(self):
        self.calls = 0

    @classmethod
    def build(cls, context, plugin):
        return cls()

    def before_step(self, now, dt):
        self.calls += 1


def test_a_part_without_a_schedule_keeps_single_steps(make_world, world02, m2wr_urdf,
                                                      monkeypatch):
    monkeypatch.setitem(registry.PLUGIN_PARTS, EveryStep.KEY, EveryStep)
    urdf = m2wr_urdf.replace("</robot>", '<gazebo><plugin name="every" '
                             'filename="libtest_every_step.so"/></gazebo></robot>')
    world = make_world(world02)
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 8, 0.1))
    calls = Calls(world)
    world.advance(100)
    part = next(p for p in robot.parts if isinstance(p, EveryStep))
    assert calls.calls == calls.steps == part.calls == 100


def test_damped_joints_keep_single_steps(make_world, world02, m2wr_urdf):
    """pybullet applies joint damping once per call: a batch would not be identical."""
    urdf = m2wr_urdf.replace('<limit effort="10000" velocity="1000"/>',
                             '<limit effort="10000" velocity="1000"/>'
                             '<dynamics damping="0.05"/>')
    assert urdf != m2wr_urdf
    world = make_world(world02)
    world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 8, 0.1))
    calls = Calls(world)
    world.advance(100)
    assert calls.calls == 100


def test_bullet_is_left_at_one_step_per_call(make_world, world02, m2wr_urdf):
    """After advance, Bullet steps one step of the World's size per stepSimulation, as
    World.step, set_step_size and anyone's direct call expect."""
    world = make_world(world02)
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.1))
    calls = Calls(world)
    world.advance(40)
    assert calls.calls < 40
    parameters = world.client.getPhysicsEngineParameters()
    assert parameters["fixedTimeStep"] == STEP and parameters["numSubSteps"] == 1


@pytest.mark.parametrize("k, exact", [(2, True), (9, True), (10, True), (29, False)])
def test_exact_substeps_follow_bullets_arithmetic(k, exact):
    """Bullet counts int(k dt / (k dt / k)) internal steps of k dt / k: 29 x 5 ms is not
    exactly 29 steps of 5 ms in doubles, so it is never batched that way."""
    assert batching.exact_substeps(STEP, k) is exact


def test_safe_time_shrinks_near_an_obstacle(make_world, world02, m2wr_urdf):
    """The contact guard: far from everything the whole horizon is safe; facing a barrier
    0.1 m away at speed, no batch at all."""
    world = make_world(world02)
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.1))
    world.advance(40)
    robots, others, grounds = world._guarded
    assert world.stepper.batcher.safe_time(robots, others, grounds, 0.1) == 0.1
    world.set_model_state("m2wr", Pose.from_xyz_rpy(0, 5.55, 0.1, 0, 0, -math.pi / 2))
    world.advance(40)
    assert world.stepper.batcher.safe_time(robots, others, grounds, 0.1) < 2 * STEP


@pytest.mark.parametrize("collect, calls_per_command", [(True, 3), ((), 1)])
def test_a_20_hz_drive_and_laser_cost_few_bullet_calls_per_0_1_s(make_world, world02, m2wr_urdf,
                                                                collect, calls_per_command):
    """In the open (row A 2 m to the side) a new command every 0.1 s. Collecting every
    reading, the scan and odometry one step after the drive's update cut each 20 steps into
    1 + 10 + 9; the drive's next update, with the same command, would change nothing and is
    run through (see the next test). Collecting none, the readings are skipped inside one
    call of 20 steps. The drive's schedule, which adds its period to its last time, runs a
    few 1e-17 s ahead of the steps' times, and that rounding must not cost a Bullet call of
    its own (it cost two in three of every ten commands)."""
    world = make_world(world02)
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(-1.0, 7.0, 0.1))
    drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
    world.advance(CONTROL)                        # settled, first scan taken
    calls = Calls(world)
    for command in [(0.2, 0.0), (0.3, 0.1), (0.2, -0.1)] * 10:
        drive_part.set_command(*command)
        world.advance(CONTROL, collect=collect)
    assert calls.steps == 30 * CONTROL
    assert calls.calls == 30 * calls_per_command


def test_readings_skipped_inside_a_stretch_are_those_single_steps_skip(make_world, world02,
                                                                      m2wr_urdf):
    """Two robots whose noisy lasers draw from the world's one noise stream, readings
    collected from neither, from one laser after a given step, or from all: the same scans
    and odometry, to the bit (noise included: the skipped scans drew theirs in the same
    order), and the same states as single steps; with fewer Bullet calls."""
    from pybullet_gazebo.engine.ray_sensor import RaySensor
    plan = [((), 0), ("a", 7), ((), 0), ("a", 0), ("b", 13), (True, 0), ("a", 19), ((), 0)] * 2
    runs = []
    for batched in (False, True):
        world = make_world(world02)
        robots = [world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(-1.0, 7.0, 0.1)),
                  world.spawn_urdf("m2wr_b", m2wr_urdf, Pose.from_xyz_rpy(-1.0, -7.0, 0.1))]
        lasers = {"a": robots[0].parts_with(RaySensor.KEY)[0],
                  "b": robots[1].parts_with(RaySensor.KEY)[0]}
        assert lasers["a"].rng is lasers["b"].rng and lasers["a"]._noisy
        drives = [next(p for p in r.parts if isinstance(p, DiffDrive)) for r in robots]
        calls = Calls(world)
        out = []
        for index, (which, first) in enumerate(plan):
            drives[0].set_command(0.3, 0.4 if index % 3 else -0.4)
            drives[1].set_command(0.2, 0.0)
            collect = which if which in ((), True) else (lasers[which],)
            if batched:
                readings = world.advance(CONTROL, collect=collect, collect_from=first)
            else:
                readings = []
                for step in range(CONTROL):
                    readings += world.step(collect=collect if step >= first else ())
            out.append(readings_record(readings))
        runs.append((out, [state(world, r) for r in robots], calls.calls))
    assert runs[0][:2] == runs[1][:2]
    assert sum(len(record) for record in runs[1][0]) > len(plan)
    assert runs[1][2] < runs[0][2] / 4


@pytest.mark.parametrize("variant", ["plain", "wheel acceleration", "command timeout"])
def test_a_drive_update_that_changes_nothing_is_run_through_bit_for_bit(make_world, world02,
                                                                       m2wr_urdf, variant):
    """A wheel update that would give the wheels the motor commands they already have (the
    same command, rims at its speeds, neither wheel held at zero) does not cut a stretch; its
    schedule is kept as if it ran, so every later update comes at the same step. Held,
    changed and zero commands, a wheelAcceleration ramp (updates that do change the wheels
    until the ramp ends) and a command_timeout that stops the robot in the middle of a held
    command: bit for bit what single steps give."""
    urdf, timeout = m2wr_urdf, 0.0
    if variant == "wheel acceleration":
        urdf = m2wr_urdf.replace("<updateRate>20</updateRate>", "<updateRate>20</updateRate>"
                                 "<wheelAcceleration>0.8</wheelAcceleration>")
        assert urdf.count("wheelAcceleration") == 2
    elif variant == "command timeout":
        timeout = 0.03             # [s]: each command stops between two updates of its call
    commands = [(0.4, 0.3)] * 6 + [(0.0, 0.0)] * 3 + [(0.4, -0.2)] * 5 + [(0.3, 0.0)] * 2
    runs = {}
    for batched in (False, True):
        world = make_world(world02)
        world.command_timeout = timeout
        robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(-1.0, 7.0, 0.1))
        drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
        assert drive_part.command_timeout == timeout
        assert drive_part.wheel_acceleration == (0.8 if variant == "wheel acceleration" else 0)
        calls = Calls(world)
        marks = []

        def between(index, calls=calls, marks=marks):
            marks.append(calls.calls)
        trace = drive(world, robot, commands, batched, between)
        runs[batched] = trace, calls, marks
    (single, single_events), _, _ = runs[False]
    (trace, events), calls, marks = runs[True]
    assert trace == single and events == single_events
    moved = [state[2][0] for state, _, _ in trace]
    assert math.dist(moved[5][:2], moved[0][:2]) > 0.05     # it drove
    if variant == "plain":
        # each call's first step brings a scan (collected), the drive's update at its middle
        # is run through: 1 + 10 + 9; the zero commands hold the wheels (an update reads their
        # angles) and keep 1 + 9 + 1 + 9
        per_call = [b - a for a, b in zip(marks, marks[1:] + [calls.calls])]
        assert per_call == [3] * 6 + [4] * 3 + [3] * 7
def test_a_schedule_a_rounding_ahead_is_not_a_reset():
    """next_period_time: `last` above `now` by a rounding still promises the next period;
    by more (the sim time went back: a reset) it promises nothing."""
    period = 0.05
    last = 0.0
    for _ in range(3):
        last += period                            # 0.15000000000000002
    now = 30 * 0.005                              # 0.15
    assert now < last < now + SCHEDULE_SLACK
    assert next_period_time(last, period, now) == last + period - SCHEDULE_SLACK
    assert next_period_time(now + 0.01, period, now) == now
    assert next_period_time(None, period, now) == now
    assert next_period_time(now - 0.01, period, now) == now - 0.01 + period - SCHEDULE_SLACK


def test_collect_from_skips_the_readings_before_it_as_single_steps_do(make_world, world02,
                                                                      m2wr_urdf):
    """advance(n, collect, collect_from=i): the readings due in the first i steps are skipped
    (schedules and noise go on), those from step i on are measured; the same scans, to the
    last bit of their noise, as stepping one by one and collecting from step i."""
    from pybullet_gazebo.engine.ray_sensor import RaySensor
    runs = []
    for batched in (False, True):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(-1.0, 7.0, 0.1))
        laser = robot.parts_with(RaySensor.KEY)[0]
        drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
        out = []
        for index, first in enumerate([5, 10, 0, 11, 20] * 3):
            drive_part.set_command(0.3, 0.4 if index % 2 else -0.4)
            if batched:
                readings = world.advance(CONTROL, collect=(laser,), collect_from=first)
            else:
                readings = []
                for step in range(CONTROL):
                    readings += world.step(collect=(laser,) if step >= first else ())
            out.append(readings_record(readings))
        runs.append((out, state(world, robot)))
    assert runs[0] == runs[1]
    counts = [len(record) for record in runs[1][0][:5]]
    # 20 Hz scans at the 1st and 11th step of each 20 (the first came with the spawn's step)
    assert counts == [1, 1, 2, 0, 0]


def test_touching_at_the_end_of_a_call_then_moved_away_batches_again(make_world, world02,
                                                                     m2wr_urdf):
    """The guard is not asked while a robot touches a model at the step (contacts read at
    that very step). A call ending on a barrier, a teleport to the open in between: the
    next calls batch again, and the run is bit for bit single stepping's, events included."""
    runs = {}
    for batched in (False, True):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
        calls = Calls(world)
        marks = {}

        def between(index, world=world, calls=calls, marks=marks):
            if index == 30:
                assert world.touching()           # pressed on row A's face
                marks["pressed"] = calls.calls
                world.set_model_state("m2wr", Pose.from_xyz_rpy(-1.0, 7.0, 0.1))
            if index == 32:
                marks["open"] = calls.calls
        trace = drive(world, robot, [(0.5, 0.0)] * 30 + [(0.3, 0.2)] * 10, batched, between)
        runs[batched] = trace, calls, marks
    (single, single_events), _, _ = runs[False]
    (trace, events), calls, marks = runs[True]
    assert events and events == single_events
    assert trace == single
    assert not any(touched for _, _, touched in trace[30:])
    assert marks["pressed"] > 20 * 5              # the last commands on the barrier: singles
    assert calls.calls - marks["open"] == 8 * 3   # in the open: 1 + 10 + 9 per command


def test_a_call_that_continues_another_keeps_the_guards_answer_and_stays_identical(
        make_world, world02, m2wr_urdf):
    """Each 20 steps as 9 (the guard looking over all 20), the next command, then 11 with
    continues=True (as m2wr_gym's run_ahead does): bit for bit single stepping with the
    command given at the same step, contact events included; the guard asked no more often
    than by calls of 20 (in the open); and a teleport between the two calls makes a fresh start all the
    same: m2wr backs away from row A in the open, is put 1 cm from its face heading in,
    and drives into it."""
    near = Pose.from_xyz_rpy(0, 5.545, 0.1, 0, 0, -math.pi / 2)
    commands = [(-0.3, 0.0)] * 8 + [(0.4, 0.0)] * 12
    runs = {}
    for way in ("single", "split", "whole"):
        world = make_world(world02)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, FACING_ROW_A)
        drive_part = next(p for p in robot.parts if isinstance(p, DiffDrive))
        asked = []
        safe_time = world.stepper.batcher.safe_time
        world.stepper.batcher.safe_time = lambda *a, **k: asked.append(1) or safe_time(*a, **k)
        trace = []
        for index, command in enumerate(commands):
            touched = set()
            if index == 8:
                asked_in_the_open = len(asked)
            if way == "whole":
                if index == 8:
                    world.set_model_state("m2wr", near)
                drive_part.set_command(*command)
                readings = world.advance(CONTROL, touched=touched)
            elif way == "split":
                readings = world.advance(9, touched=touched, horizon=CONTROL)
                if index == 8:
                    world.set_model_state("m2wr", near)
                drive_part.set_command(*command)
                readings += world.advance(CONTROL - 9, touched=touched, continues=True)
            else:
                readings = []
                for step in range(CONTROL):
                    if step == 9:
                        if index == 8:
                            world.set_model_state("m2wr", near)
                        drive_part.set_command(*command)
                    readings += world.step()
                    touched.update(world.touching())
            trace.append((state(world, robot), readings_record(readings), sorted(touched)))
        runs[way] = trace, list(world.contact_events), asked_in_the_open
    single, split, whole = runs["single"], runs["split"], runs["whole"]
    assert split[:2] == single[:2]
    events = single[1]
    assert events and events[0].sim_time > 8 * CONTROL * STEP    # the touch after the teleport
    assert 0 < split[2] <= whole[2]
