"""The grader's parts without a simulator: the spec (errors name the line and the field),
the class folder (packages, loose scripts, nothing), the overlay that hides the project's
motion_plan, the rules, the scores and the trajectory picture."""
import json
import os
import subprocess
import textwrap

import pytest

from m2wr_tools.running import gazebo_calls
from m2wr_tools.running import processes
from m2wr_tools.running.commands import check, package_dir
from m2wr_tools.grade import classroom, rules, sandbox, scoring
from m2wr_tools.grade.report import svg
from m2wr_tools.grade.spec import DEFAULT_SPEC, SpecError, load
from pybullet_gazebo.ros.testing import wait_until

GOOD = """\
version: 1
tasks:
  - name: avoid
    command: rosrun motion_plan obstacle_avoidance.py
    kind: wander
    duration: 10
  - name: goal
    command: roslaunch motion_plan bug2.launch des_x:=0 des_y:=-4
    kind: goal
    goal: [0, -4]
    starts: [[0, 8, 0], [1, 8, 0]]
    seeds: [0, 1]
    allow: [set_model_state_to_start]
"""


def _spec(tmp_path, text):
    path = tmp_path / "spec.yaml"
    path.write_text(textwrap.dedent(text))
    return str(path)


def test_a_spec_gives_its_tasks_and_their_runs(tmp_path):
    spec = load(_spec(tmp_path, GOOD))
    avoid, goal = spec.tasks
    assert avoid.command == ("rosrun", "motion_plan", "obstacle_avoidance.py")
    assert avoid.starts == ((0.0, 8.0, 0.0),) and avoid.duration == 10.0
    assert goal.goal == (0.0, -4.0) and goal.allow == ("set_model_state_to_start",)
    assert [(i, s, seed) for i, s, seed in goal.runs] == [
        (0, (0.0, 8.0, 0.0), 0), (1, (1.0, 8.0, 0.0), 0), (2, (0.0, 8.0, 0.0), 1),
        (3, (1.0, 8.0, 0.0), 1)]
    assert spec.points == 20.0


def test_the_default_spec_covers_episodes_5_to_10():
    spec = load(DEFAULT_SPEC)
    assert [t.episode for t in spec.tasks] == [5, 6, 7, 8, 9, 10]
    assert spec.points == 100.0
    assert all("set_model_state_to_start" in t.allow for t in spec.tasks if "bug" in t.name)


@pytest.mark.parametrize("task_name", ["ep8_bug0", "ep9_bug1", "ep10_bug2"])
def test_the_benchmark_class_bug_launch_files_take_the_default_specs_start_and_goal(
        tmp_path, task_name):
    """The grader's benchmark class hands in bug 0-2's launch files: the default spec's
    command line starts each (roslaunch refuses an argument the file does not declare), and
    the parameters it sets are the task's start and goal."""
    from m2wr_tools.bench import grade as grade_bench
    task, = [t for t in load(DEFAULT_SPEC).tasks if t.name == task_name]
    words = list(task.command)
    assert words[:2] == ["roslaunch", "motion_plan"]
    student, = grade_bench.make_class(str(tmp_path / "class"), 1)
    launch = tmp_path / "class" / student / "motion_plan" / "launch" / words[2]
    dumped = subprocess.run(["roslaunch", "--dump-params", str(launch)] + words[3:],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=60, stdin=subprocess.DEVNULL)
    assert dumped.returncode == 0, dumped.stdout
    params = dict(line.split(": ", 1) for line in dumped.stdout.splitlines() if ": " in line)
    x, y, _ = task.starts[0]
    assert (float(params["/initial_x"]), float(params["/initial_y"])) == (x, y)
    assert (float(params["/des_pos_x"]), float(params["/des_pos_y"])) == tuple(task.goal)


@pytest.mark.parametrize("change, message", [
    (("kind: wander", "kind: dance"), "line 5: tasks[1].kind: 'dance' is not a task kind; "
                                      "use one of wander, goal, wall"),
    (("    goal: [0, -4]\n", ""), "line 7: tasks[2]: the goal task 'goal' needs `goal: [x, y]`"),
    (("duration: 10", "duration: -1"), "line 6: tasks[1].duration: -1 must be a number > 0"),
    (("starts: [[0, 8, 0], [1, 8, 0]]", "starts: [[0, 8]]"),
     "line 11: tasks[2].starts: must be a list of [x, y, yaw]"),
    (("allow: [set_model_state_to_start]", "allow: [teleport]"),
     "line 13: tasks[2].allow: ['teleport'] must be a list of permissions from: "
     "set_model_state_to_start"),
    (("name: goal", "name: avoid"), "line 7: tasks[2].name: 'avoid' is used twice"),
    (("    kind: wander\n", "    kidn: wander\n"), "line 5: tasks[1].kidn: unknown field"),
    (("command: rosrun motion_plan obstacle_avoidance.py", "command: python3 x.py"),
     "line 4: tasks[1].command: 'python3 x.py' must start with rosrun or roslaunch"),
    (("version: 1", "version: 1\n  oops: [\n"), "line 2: not valid YAML"),
])
def test_a_bad_spec_names_the_line_and_the_field(tmp_path, change, message):
    path = _spec(tmp_path, GOOD.replace(*change))
    with pytest.raises(SpecError) as error:
        load(path)
    assert str(error.value).startswith("spec %s " % path) and message in str(error.value)


def test_a_missing_spec_says_where_the_default_is(tmp_path):
    with pytest.raises(SpecError, match="spec .*nope.yaml not found; pass --spec PATH"):
        load(str(tmp_path / "nope.yaml"))


def _package(folder, name="motion_plan", scripts=("go_to_point.py",)):
    os.makedirs(os.path.join(folder, "scripts"))
    with open(os.path.join(folder, "package.xml"), "w") as out:
        out.write("<package format='2'><name>%s</name><version>0.0.0</version></package>" % name)
    for script in scripts:
        with open(os.path.join(folder, "scripts", script), "w") as out:
            out.write("print('hi')\n")


def test_a_class_folder_has_packages_loose_scripts_and_nothing(tmp_path):
    _package(str(tmp_path / "ann" / "catkin_ws" / "src" / "motion_plan"))
    (tmp_path / "bob").mkdir()
    (tmp_path / "bob" / "go_to_point.py").write_text("print('hi')\n")
    (tmp_path / "cy").mkdir()
    (tmp_path / "cy" / "notes.txt").write_text("nothing\n")
    ann, bob, cy = classroom.discover(str(tmp_path))
    assert (ann.student, ann.kind, [n for n, _ in ann.packages]) == ("ann", "package",
                                                                      ["motion_plan"])
    assert (bob.kind, cy.kind) == ("scripts", "nothing")
    assert "no package.xml and no scripts (.py, .launch)" in cy.problem
    assert classroom.stage(bob, str(tmp_path / "stage")) == ["motion_plan"]
    staged = tmp_path / "stage" / "motion_plan" / "scripts" / "go_to_point.py"
    assert staged.exists() and os.access(staged, os.X_OK)


def test_an_empty_or_missing_class_folder_is_named(tmp_path):
    with pytest.raises(ValueError, match="has no student folders; put one folder per student"):
        classroom.discover(str(tmp_path))
    with pytest.raises(ValueError, match="class folder .*nope not found"):
        classroom.discover(str(tmp_path / "nope"))


def test_the_overlay_finds_the_students_package_never_the_projects(tmp_path):
    project = tmp_path / "project_src"
    _package(str(project / "motion_plan"), scripts=("obstacle_avoidance.py",))
    _package(str(project / "my_worlds"), name="my_worlds", scripts=())
    student = tmp_path / "student"
    _package(str(student / "motion_plan"), scripts=("go_to_point.py",))
    for script in (project / "motion_plan" / "scripts").iterdir():
        script.chmod(0o755)
    env = {"PATH": os.environ["PATH"], "ROS_PACKAGE_PATH": str(project),
           "CMAKE_PREFIX_PATH": ""}
    assert check(("rosrun", "motion_plan", "obstacle_avoidance.py"), env) is None
    overlay = classroom.overlay_env(env, str(student), ["motion_plan"])
    assert overlay["ROS_PACKAGE_PATH"].split(":") == [str(student),
                                                       str(project / "my_worlds")]
    with pytest.raises(ValueError, match=r"\(%s\) has no file 'obstacle_avoidance.py'"
                       % (student / "motion_plan")):
        check(("rosrun", "motion_plan", "obstacle_avoidance.py"), overlay)


def test_a_package_is_found_on_the_first_path_that_holds_it_as_rospack_finds_it(tmp_path):
    first, second = tmp_path / "first", tmp_path / "second"
    _package(str(first / "motion_plan"), scripts=())
    _package(str(second / "pkgs" / "motion_plan"), scripts=())
    _package(str(second / "my_worlds"), name="my_worlds", scripts=())
    env = {"ROS_PACKAGE_PATH": "%s:%s" % (first, second)}
    assert package_dir("motion_plan", env) == str(first / "motion_plan")
    assert package_dir("my_worlds", env) == str(second / "my_worlds")
    assert package_dir("no_such_package", env) is None
    env["ROS_PACKAGE_PATH"] = "%s:%s" % (second, first)
    assert package_dir("motion_plan", env) == str(second / "pkgs" / "motion_plan")


def test_a_users_processes_are_listed_and_its_ended_ones_are_not():
    live = subprocess.Popen(["sleep", "30"])
    ended = subprocess.Popen(["true"])
    try:
        # a zombie until waited for
        wait_until(lambda: not processes.alive(ended.pid), 5, "'true' to end", interval=0.01)
        mine = sandbox.pids_of_user(os.getuid())
        assert live.pid in mine and ended.pid not in mine and os.getpid() not in mine
        assert live.pid not in sandbox.pids_of_user(os.getuid() + 12345)
    finally:
        live.kill()
        live.wait()
        ended.wait()


def test_rules_allow_the_bug_programs_start_and_fail_everything_else():
    start = (0.0, 8.0, 0.0)
    to_start = {"service": "/gazebo/set_model_state", "caller": "/bug2", "sim_time": 0.0,
                "model": "m2wr", "x": 0.0, "y": 8.0}
    to_goal = dict(to_start, x=0.0, y=-4.0, sim_time=12.5)
    spawn = {"service": "/gazebo/spawn_urdf_model", "caller": "/spawn", "sim_time": 0.0,
             "model": "m2wr", "x": 0.0, "y": 8.0}
    ours = dict(to_start, caller="/m2wr_batch")
    allowed = rules.service_findings([to_start, spawn, ours], ("set_model_state_to_start",),
                                     start, ignore=("/m2wr_batch",))
    assert [f["allowed"] for f in allowed] == [True, True] and rules.verdict(allowed) is None
    found = rules.service_findings([to_start, to_goal], (), start)
    assert rules.verdict(found) == ("rules: called /gazebo/set_model_state for m2wr at "
                                    "(0.00, 8.00), by /bug2, at 0.00 s (and 1 more)")
    found = rules.service_findings([to_goal], ("set_model_state_to_start",), start)
    assert rules.verdict(found) == ("rules: called /gazebo/set_model_state for m2wr at "
                                    "(0.00, -4.00), by /bug2, at 12.50 s")
    state = ([["/gazebo/set_model_state", ["/cheat"]], ["/cmd_vel", ["/bug2"]]],
             [["/gazebo/model_states", ["/peek", "/m2wr_batch"]], ["/odom", ["/bug2"]]], [])
    assert rules.graph_findings(state, ignore=("/m2wr_batch", "/gazebo")) == {
        ("published on", "/gazebo/set_model_state", "/cheat"),
        ("subscribed to", "/gazebo/model_states", "/peek")}
    logged = [to_start, {"topic": "/gazebo/model_states", "subscriber": "/peek", "sim_time": 3.0},
              {"topic": "/gazebo/model_states", "subscriber": "/m2wr_batch", "sim_time": 0.0},
              {"topic": "/gazebo/set_model_state", "publisher": "/cheat", "sim_time": 4.5}]
    assert rules.service_findings(logged, (), start) == rules.service_findings(
        [to_start], (), start)                      # the topic entries are not service calls
    assert rules.logged_topic_users(logged, ignore=("/m2wr_batch",)) == [
        ("subscribed to", "/gazebo/model_states", "/peek", 3.0),
        ("published on", "/gazebo/set_model_state", "/cheat", 4.5)]


class _Sub:
    problem = None


def test_scores_ranks_and_the_gradebook_are_stable(tmp_path):
    spec = load(_spec(tmp_path, GOOD))
    ok = {"success": True}

    def failed(reason):
        return {"success": False, "reason": reason}
    graded = {
        "zoe": {"submission": _Sub(), "records": [dict(ok, task="avoid", index=0)] + [
            dict(ok, task="goal", index=i) for i in range(3)] + [
            dict(failed("controller exited with status 1 while starting; see /x/y.log:\n"
                        "Traceback"), task="goal", index=3)]},
        "amy": {"submission": _Sub(), "records": [dict(ok, task="avoid", index=0)] + [
            dict(failed("rules: called /gazebo/get_model_state, by /a, at 1.00 s"),
                 task="goal", index=i) for i in range(4)]},
        "bo": {"submission": _Sub(), "records": [dict(ok, task="avoid", index=0)] + [
            dict(failed("x"), task="goal", index=i) for i in range(4)]},
    }
    rows = scoring.rows(spec, graded)
    assert [(r["student"], r["total"], r["rank"]) for r in rows] == [
        ("amy", 10.0, 2), ("bo", 10.0, 2), ("zoe", 17.5, 1)]
    text = scoring.csv_text(spec, graded)
    assert text.splitlines()[0] == "student,avoid,goal,total,max,rank,failures"
    assert text.splitlines()[3] == ("zoe,10.00,7.50,17.50,20.00,1,goal run 3: controller "
                                    "exited with status 1 while starting")
    assert text == scoring.csv_text(spec, dict(reversed(list(graded.items()))))


def test_the_trajectory_picture_draws_obstacles_path_start_and_goal():
    from m2wr_tools.analysis.scene import Outline
    outlines = [Outline(model="can", kind="circle", center=(1.0, 1.0), radius=0.5),
                Outline(model="box", kind="polygon", points=((2, 2), (3, 2), (3, 3), (2, 3)))]
    record = {"x": 0.0, "y": 0.0, "success": True, "path": [[0, 0, 0], [1, 0.0, 0.5]]}
    text = svg(outlines, record, goal=(3.0, 0.0))
    assert text.startswith('<svg xmlns="http://www.w3.org/2000/svg"')
    assert text.count("<circle") == 3 and "<polygon" in text and 'stroke="#080"' in text


def test_runs_that_cannot_start_fail_with_their_reason_and_the_rest_are_planned(tmp_path):
    from m2wr_tools.grade.grading import plan
    spec = load(_spec(tmp_path, GOOD.replace("    duration: 10\n",
                                             "    duration: 10\n    world: world99\n")))
    class_dir = tmp_path / "class"
    _package(str(class_dir / "ann" / "motion_plan"), scripts=("obstacle_avoidance.py",))
    (class_dir / "bob").mkdir()
    todo, failed, shadowed = plan(spec, classroom.discover(str(class_dir)), str(tmp_path / "o"))
    assert todo == [] and "motion_plan" in shadowed
    reasons = {(r["student"], r["task"], r["index"]): r["reason"] for r in failed}
    assert len(reasons) == 2 * (1 + 4)
    assert reasons[("ann", "avoid", 0)].startswith(
        "the task's world: world 'world99' not found; set the task's `world:` to one of world01")
    assert reasons[("ann", "goal", 3)] == ("controller 'roslaunch motion_plan bug2.launch "
                                           "des_x:=0 des_y:=-4': package 'motion_plan' "
                                           "(ann/motion_plan) has no launch file 'bug2.launch'")
    assert reasons[("bob", "goal", 0)].startswith("no package.xml and no scripts")


def test_runs_are_planned_simulator_by_simulator_so_that_a_worker_keeps_its_own(tmp_path):
    """A worker relaunches its simulator when the world, the seed or the turning convention
    changes: the runs go by those, in the spec's order, each group's students in name order."""
    from m2wr_tools.grade.grading import plan
    spec = load(_spec(tmp_path, """\
        version: 1
        tasks:
          - {name: a, command: rosrun motion_plan go_to_point.py, kind: wander, world: world02}
          - {name: b, command: rosrun motion_plan go_to_point.py, kind: wander, world: world03}
          - {name: c, command: rosrun motion_plan go_to_point.py, kind: wander, world: world02}
          - {name: d, command: rosrun motion_plan go_to_point.py, kind: wander, world: world02,
             legacy_mode: true}
          - {name: e, command: rosrun motion_plan go_to_point.py, kind: wander, world: world03,
             seeds: [0, 1]}
        """))
    class_dir = tmp_path / "class"
    for student in ("bo", "ann"):
        _package(str(class_dir / student / "motion_plan"))
    todo, failed, _ = plan(spec, classroom.discover(str(class_dir)), str(tmp_path / "o"))
    assert failed == []
    assert [(s.task_name, s.seed, s.student) for s in todo] == [
        ("a", 0, "ann"), ("c", 0, "ann"), ("a", 0, "bo"), ("c", 0, "bo"),    # world02
        ("b", 0, "ann"), ("e", 0, "ann"), ("b", 0, "bo"), ("e", 0, "bo"),    # world03
        ("d", 0, "ann"), ("d", 0, "bo"),                                     # legacy_mode
        ("e", 1, "ann"), ("e", 1, "bo")]                                     # world03, seed 1


def test_a_project_closed_to_other_users_is_named():
    """Runs start as unprivileged users: a project under a private folder (mktemp -d, a home
    folder) would hide m2wr_description and the project's Python from them."""
    import shutil
    import tempfile
    from m2wr_tools.grade import sandbox
    top = tempfile.mkdtemp(prefix="m2wr-closed-test-")       # under /tmp (o+x)
    try:
        project = os.path.join(top, "private", "project")
        os.makedirs(project)
        os.chmod(top, 0o755)
        os.chmod(os.path.join(top, "private"), 0o700)
        assert sandbox.closed_to_others(project) == os.path.join(top, "private")
        os.chmod(os.path.join(top, "private"), 0o711)
        assert sandbox.closed_to_others(project) is None
    finally:
        shutil.rmtree(top)


def test_the_call_log_is_read_line_by_line_from_where_the_last_read_stopped(tmp_path):
    path = tmp_path / "gazebo_calls.jsonl"
    assert gazebo_calls.read(str(path)) == ([], 0)           # not there yet
    first = {"service": "/gazebo/set_model_state", "caller": "/bug2", "sim_time": 0.0}
    second = {"topic": "/gazebo/model_states", "subscriber": "/dan", "sim_time": 1.5}
    path.write_text(json.dumps(first) + "\n" + json.dumps(second)[:10])   # one being written
    entries, offset = gazebo_calls.read(str(path))
    assert entries == [first] and offset == len(json.dumps(first)) + 1
    with open(path, "w") as log:
        log.write(json.dumps(first) + "\n" + json.dumps(second) + "\n")
    assert gazebo_calls.read(str(path), offset) == ([second], path.stat().st_size)
    assert gazebo_calls.called([first, second], "/gazebo/set_model_state", by="/bug2")
    assert not gazebo_calls.called([first], "/gazebo/set_model_state", not_by="/bug2")
    assert not gazebo_calls.called([second], "/gazebo/set_model_state")


SERIES_CLASS = os.path.join(os.path.dirname(__file__), "fixtures", "series_class")


def test_legacy_mode_and_after_start_are_spec_fields_with_defaults(tmp_path):
    spec = load(_spec(tmp_path, GOOD.replace("version: 1\n", "version: 1\ndefaults:\n"
                                             "  legacy_mode: true\n").replace(
        "    duration: 10\n", "    duration: 10\n    legacy_mode: false\n    after_start:\n"
        "      - call: /go_to_point_switch\n        request: {data: true}\n"
        "        if_offered: true\n      - param: /my_node/active\n        value: true\n")))
    avoid, goal = spec.tasks
    assert (avoid.legacy_mode, goal.legacy_mode) == (False, True)
    assert spec.legacy_modes == (False, True)
    call, param = avoid.after_start
    assert (call.kind, call.name, call.text, call.if_offered, call.wait) == (
        "call", "/go_to_point_switch", "data: true", True, 2.0)
    assert call.describe() == 'rosservice call /go_to_point_switch "data: true" (if offered)'
    assert (param.kind, param.name, param.text) == ("param", "/my_node/active", "true")
    assert goal.after_start == ()
    default = load(DEFAULT_SPEC)
    assert default.legacy_modes == (False,)     # Gazebo Noetic's, as episode 5's page needs
    switches = {t.name: [s.describe() for s in t.after_start] for t in default.tasks}
    assert switches["ep6_go_to_point"] == [
        'rosservice call /go_to_point_switch "data: true" (if offered)']
    assert switches["ep7_follow_wall"] == [
        'rosservice call /wall_follower_switch "data: true" (if offered)']
    assert all(not switches[t] for t in ("ep5_avoid", "ep8_bug0", "ep9_bug1", "ep10_bug2"))


@pytest.mark.parametrize("change, message", [
    ("    legacy_mode: yes please\n", "tasks[1].legacy_mode: 'yes please' must be true"),
    ("    after_start: {call: /x}\n", "tasks[1].after_start: must be a list of {call:"),
    ("    after_start:\n      - cal: /x\n", "tasks[1].after_start: item 1 must have one of "
                                             "`call:` or `param:`"),
    ("    after_start:\n      - call: /x\n        wiat: 3\n",
     "tasks[1].after_start: item 1: `wiat` is unknown; a call item has call, request, "
     "if_offered, wait"),
    ("    after_start:\n      - param: /x\n", "tasks[1].after_start: item 1: param /x needs "
                                               "`value:`"),
    ("    after_start:\n      - call: 'not a name'\n", "item 1: call 'not a name' must be a "
                                                        "ROS name"),
])
def test_a_bad_legacy_mode_or_after_start_names_the_line_and_the_field(tmp_path, change,
                                                                       message):
    path = _spec(tmp_path, GOOD.replace("    duration: 10\n", "    duration: 10\n" + change))
    with pytest.raises(SpecError) as error:
        load(path)
    assert message in str(error.value) and "line 7" in str(error.value)


def test_a_launch_file_loses_its_world_and_spawn_and_keeps_the_rest(tmp_path):
    """lee's bug1.launch includes empty_world.launch and spawn.launch; her bug2.launch
    includes her own world.launch, which includes my_worlds' and runs spawn_model: each is
    left out, with why, and every node of hers stays."""
    import shutil
    import xml.etree.ElementTree as ET
    from m2wr_tools.grade.launch_filter import SPAWN_WHY, WORLD_WHY, filter_in_place
    ws = tmp_path / "ws"
    shutil.copytree(os.path.join(SERIES_CLASS, "lee", "motion_plan"), ws / "motion_plan")
    packages = {"motion_plan": str(ws / "motion_plan")}
    bug1 = ws / "motion_plan" / "launch" / "bug1.launch"
    left = filter_in_place(str(bug1), packages, root=str(ws))
    assert [(x.file, x.element, x.why) for x in left] == [
        ("motion_plan/launch/bug1.launch",
         '<include file="$(find gazebo_ros)/launch/empty_world.launch">', WORLD_WHY),
        ("motion_plan/launch/bug1.launch",
         '<include file="$(find m2wr_description)/launch/spawn.launch">', SPAWN_WHY)]
    root = ET.parse(str(bug1)).getroot()
    assert [n.get("type") for n in root.iter("node")] == ["follow_wall.py", "go_to_point.py",
                                                          "bug1.py"]
    assert [a.get("name") for a in root.findall("arg")] == ["initial_x", "initial_y", "des_x",
                                                             "des_y"]
    assert root.find("include") is None and root.find("env") is not None
    left = filter_in_place(str(ws / "motion_plan" / "launch" / "bug2.launch"), packages,
                           root=str(ws))
    assert [(x.file, x.element) for x in left] == [
        ("motion_plan/launch/world.launch",
         '<include file="$(find my_worlds)/launch/world.launch">'),
        ("motion_plan/launch/world.launch", '<param name="robot_description">'),
        ("motion_plan/launch/world.launch",
         '<node pkg="gazebo_ros" type="spawn_model" name="mybot_spawn">')]
    assert left[2].why == SPAWN_WHY
    world = ET.parse(str(ws / "motion_plan" / "launch" / "world.launch")).getroot()
    assert [e.tag for e in world] == ["arg"]
    # a launch file with nothing of the kind is left byte for byte
    behaviors = os.path.join(SERIES_CLASS, "kim", "motion_plan", "launch", "bug0.launch")
    shutil.copy(behaviors, ws / "motion_plan" / "launch" / "bug0.launch")
    before = (ws / "motion_plan" / "launch" / "bug0.launch").read_bytes()
    assert filter_in_place(str(ws / "motion_plan" / "launch" / "bug0.launch"), packages) == []
    assert (ws / "motion_plan" / "launch" / "bug0.launch").read_bytes() == before


def test_the_class_table_gives_one_short_reason_a_failed_task(tmp_path):
    spec = load(_spec(tmp_path, GOOD))
    never = "the controller never published on /cmd_vel; see /out/batch/runs/x.log"
    records = [{"task": "avoid", "index": 0, "success": False, "reason": never}] + [
        {"task": "goal", "index": i, "success": False,
         "reason": "did not reach the goal (0.00, -4.00) within 0.30 m: turned away from the "
                   "goal: never nearer than at its start (12.00 m), it ended facing 179 deg "
                   "off the goal's direction"} for i in range(3)] + [
        {"task": "goal", "index": 3, "success": False, "reason": "controller exited with "
                                                                  "status 1 while starting"}]
    short = scoring.short_failures(spec, records)
    assert short[0] == ("avoid", "the controller never published on /cmd_vel",
                        ["the controller never published on /cmd_vel"])
    name, text, full = short[1]
    assert name == "goal" and len(full) == 2 and full[0].endswith("off the goal's direction")
    assert text == "did not reach the goal: turned away from the goal (4 runs), +1 other reason"
    # a controller that cannot start: why, not its command line (that is in the task's head)
    unstarted = [{"task": "avoid", "index": 0, "success": False, "reason": (
        "controller 'roslaunch motion_plan bug0.launch des_x:=0 des_y:=-4': package "
        "'motion_plan' (ann/motion_plan) has no launch file 'bug0.launch'")},
        {"task": "goal", "index": 0, "success": False, "reason": (
            "controller 'rosrun nav go.py': package 'nav' not found on ROS_PACKAGE_PATH; "
            "hand in a package of that name")}]
    assert [text for _, text, _ in scoring.short_failures(spec, unstarted)] == [
        "cannot start: no launch file 'bug0.launch'",
        "cannot start: package 'nav' not found on ROS_PACKAGE_PATH"]


def test_a_goal_run_that_turned_away_is_told_so():
    # the series' go to point under the other convention: it turns on the spot until it faces
    # away from the goal, and stays there
    away = {"x": 0.0, "y": 8.0, "path": [[0, 0.0, 8.0], [5, 0.01, 8.0]], "final_x": 0.01,
            "final_y": 8.0, "final_yaw": 3.12}
    assert scoring.goal_hint(away, (2.0, 8.0), False) == (
        "turned away from the goal: never nearer than at its start (2.00 m), it ended facing "
        "179 deg off the goal's direction, as a program written for the other turning "
        "convention does (this task: legacy_mode false)")
    stuck = dict(away, final_yaw=0.0)
    assert scoring.goal_hint(stuck, (2.0, 8.0), True) == \
        "never nearer the goal than at its start (2.00 m)"
    near = dict(away, path=[[0, 0.0, 8.0], [5, 1.5, 8.0]], final_x=1.0)
    assert scoring.goal_hint(near, (2.0, 8.0), True) == "came within 0.50 m of it, ended " \
        "1.00 m away"


def _spin(track, t, x, y, yaw, rate, seconds):
    """`track` extended by a turn on the spot at (x, y) from `yaw`, `rate` [rad/s], 20 Hz."""
    for i in range(1, int(seconds * 20) + 1):
        track.append((t + i / 20.0, x, y, yaw + rate * i / 20.0))
    return t + seconds, yaw + rate * seconds


def test_a_bug_run_that_turns_away_on_the_spot_is_told_so():
    # a bug program's go to point under the other convention, switched on at (0, 8) facing
    # east with its goal south: on the spot it turns left (away), each time it is switched
    # on; between two switchings the wall follower takes it a few metres
    goal = (0.0, -3.0)
    track = [(0.0, 0.0, 8.0, 0.0)]
    t, yaw = _spin(track, 0.0, 0.0, 8.0, 0.0, 0.7, 2.2)            # -90 deg off -> -180
    for i in range(1, 41):                                          # wall following, 2 m
        track.append((t + i / 10.0, 0.0, 8.0 - 0.05 * i, -1.2))
    t, yaw = _spin(track, t + 4.0, 0.0, 6.0, -1.2, 0.7, 2.0)        # -21 deg off -> -101
    away, toward = scoring.turns_in_place(track, goal)
    assert toward == 0.0 and 145 < away < 165, (away, toward)
    record = {"x": 0.0, "y": 8.0, "path": [[r[0], r[1], r[2]] for r in track[::10]],
              "final_x": 0.0, "final_y": 6.0, "final_yaw": yaw}
    hint = scoring.goal_hint(record, goal, False, turns=(away, toward))
    assert hint.startswith("turned away from the goal: on the spot it turned %.0f deg away "
                           "from the goal's direction and 0 deg toward it" % away), hint
    assert hint.endswith("as a program written for the other turning convention does (this "
                         "task: legacy_mode false)"), hint
    # the same program under its own convention turns toward the goal: no such hint
    track = [(0.0, 0.0, 8.0, 0.0)]
    _spin(track, 0.0, 0.0, 8.0, 0.0, -0.7, 2.2)
    away, toward = scoring.turns_in_place(track, goal)
    assert away == 0.0 and toward > 60, (away, toward)
    assert not scoring.goal_hint(dict(record, final_yaw=-1.57), goal, True,
                                 turns=(away, toward)).startswith("turned away")
    # driving (not on the spot) and turning while facing the goal or right away from it
    # count for neither side
    assert scoring.turns_in_place([(0.0, 0.0, 8.0, 0.0), (0.1, 0.06, 8.0, 0.1),
                                   (0.2, 0.12, 8.0, 0.2)], goal) == (0.0, 0.0)
    track = [(0.0, 0.0, 8.0, 1.571)]
    _spin(track, 0.0, 0.0, 8.0, 1.571, 0.7, 0.2)
    assert scoring.turns_in_place(track, goal) == (0.0, 0.0)
