"""scripts/grade.sh on the fixture class (scripts/test/fixtures/class, written for this test)
with a two-task spec (fixtures/grade_spec.yaml: avoid = `roslaunch motion_plan avoid.launch`,
wander 10 s; goal = `rosrun motion_plan go_to_point.py` to (2, 8) from (0, 8) facing north,
15 s): each student gets the grade and the reason a teacher would expect, the machine stays
responsive while the fork-and-allocate student runs, nothing is left running, and grading
again gives the same grades.csv byte for byte."""
import csv
import json
import os
import shutil
import subprocess
import threading
import time

from m2wr_tools.grade import sandbox

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
GRADE = os.path.join(ROOT, "scripts", "grade.sh")
FIXTURES = os.path.join(ROOT, "scripts", "test", "fixtures")


def grade(class_dir, output, *extra, timeout=300,
          spec=os.path.join(FIXTURES, "grade_spec.yaml")):
    result = subprocess.run(["bash", GRADE, str(class_dir)] + (["--spec", spec] if spec else [])
                            + ["--output", str(output), "--workers", "2", "--no-progress", *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=timeout)
    return result.returncode, result.stdout


class Responsiveness(threading.Thread):
    """The longest wall-time gap [s] between 50 ms sleeps of this thread while it runs."""

    def __init__(self):
        super().__init__(daemon=True)
        self.worst, self.running = 0.0, True

    def run(self):
        last = time.monotonic()
        while self.running:
            time.sleep(0.05)
            now = time.monotonic()
            self.worst = max(self.worst, now - last - 0.05)
            last = now


def test_the_fixture_class_gets_the_grades_a_teacher_expects(tmp_path):
    class_dir = tmp_path / "class"
    shutil.copytree(os.path.join(FIXTURES, "class"), class_dir)
    os.chmod(class_dir, 0o700)
    watch = Responsiveness()
    watch.start()
    status, text = grade(class_dir, tmp_path / "out")
    watch.running = False
    assert status == 0, text
    with open(tmp_path / "out" / "grades.csv", newline="") as source:
        rows = {r["student"]: r for r in csv.DictReader(source)}
    assert set(rows) == {"ada", "bert", "cleo", "dan", "eve", "fay", "gus", "hal"}

    def grade_of(student):
        r = rows[student]
        return float(r["avoid"]), float(r["goal"]), float(r["total"]), int(r["rank"])
    # ada: a correct avoider and go-to-point: full points, first
    assert grade_of("ada") == (10.0, 10.0, 20.0, 1), rows["ada"]
    # gus: his launch file spawns m2wr again: left out, his avoider graded
    assert grade_of("gus") == (10.0, 0.0, 10.0, 2), rows["gus"]
    assert "package 'motion_plan'" in rows["gus"]["failures"] and \
        "has no file 'go_to_point.py'" in rows["gus"]["failures"]
    failures = {s: rows[s]["failures"] for s in rows}
    # bert: loose scripts; his go-to-point turns the wrong way and never gets there
    assert grade_of("bert")[:3] == (0.0, 0.0, 0.0)
    assert "goal run 0: did not reach the goal (2.00, 8.00) within 0.30 m" in failures["bert"]
    assert "has no launch file 'avoid.launch'" in failures["bert"]
    # cleo teleports, dan reads the ground truth: rules, by which node, at what sim time
    assert "goal run 0: rules: called /gazebo/set_model_state for m2wr at (2.00, 8.00), by " \
        "/go_to_point, at 0.00 s" in failures["cleo"]
    assert "goal run 0: rules: subscribed to /gazebo/model_states, by /go_to_point, at " \
        in failures["dan"]
    # eve crashes, fay forks and allocates, hal handed in nothing gradable
    assert "goal run 0: controller exited with status 1 while starting" in failures["eve"]
    assert "goal run 0: resources: its processes used more than the 400 MiB of memory allowed" \
        " together" in failures["fay"]
    assert "no package.xml and no scripts (.py, .launch)" in failures["hal"]
    for student in ("bert", "cleo", "dan", "eve", "fay", "hal"):
        assert rows[student]["total"] == "0.00" and rows[student]["rank"] == "3"
    data = json.loads((tmp_path / "out" / "results.json").read_text())
    gus = data["students"]["gus"]["runs"][0]
    # each run that ran the world has its replay, made within its measuring (timed apart)
    stages = gus["stages"]
    assert os.path.isfile(gus["replay"]) and 0 < stages["replay_s"] <= stages["measure_s"]
    # his launch file's spawn is left out (the grader's m2wr is the one graded): no second
    # spawn reaches the simulator
    assert gus["findings"] == [] and [x["element"] for x in gus["left_out"]] == [
        '<param name="robot_description">',
        '<node pkg="gazebo_ros" type="spawn_model" name="mybot_spawn">']
    fay = next(r for r in data["students"]["fay"]["runs"] if r["task"] == "goal")
    if sandbox.isolating():
        # runs start as the slot's unprivileged user, and the output is the grader's alone
        assert fay["user"].startswith("m2wr-grade") and fay["isolated"]
        assert os.stat(tmp_path / "out").st_mode & 0o077 == 0
    assert watch.worst < 2.0, "the machine stalled %.1f s while grading" % watch.worst
    # nothing left running: no process of the run users, no process of the batch
    if sandbox.isolating():
        for slot in range(2):
            try:
                uid = int(subprocess.run(["id", "-u", sandbox.USER % slot], text=True,
                                         stdout=subprocess.PIPE).stdout)
            except ValueError:
                continue
            assert sandbox.pids_of_user(uid) == []
    leftover = subprocess.run(["pgrep", "-f", str(tmp_path)], stdout=subprocess.PIPE, text=True)
    assert leftover.stdout == "", leftover.stdout
    # grading again from scratch: the same gradebook, byte for byte
    status, text = grade(class_dir, tmp_path / "again")
    assert status == 0, text
    assert (tmp_path / "out" / "grades.csv").read_bytes() == \
        (tmp_path / "again" / "grades.csv").read_bytes()
    # an appeal: dan's goal run replayed on a fresh simulator is the graded run, the rule
    # finding (what, who, when) included
    replayed = subprocess.run(["bash", GRADE, "--replay", "dan", "goal", "0", "--output",
                               str(tmp_path / "out")], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=120)
    assert replayed.returncode == 0, replayed.stdout
    assert replayed.stdout.rstrip().endswith(
        "the replay is the graded run: every measure equal to the last digit"), replayed.stdout


def test_the_default_spec_grades_a_class_not_written_in_the_series_style(tmp_path):
    """The default spec (episodes 5-10) on the fixture class, whose students hand in one or
    two programs each, written their own way: what they handed in is graded, each missing
    program fails its task with the file it lacks, and the rules and limits hold."""
    class_dir = tmp_path / "class"
    shutil.copytree(os.path.join(FIXTURES, "class"), class_dir)
    os.chmod(class_dir, 0o700)
    status, text = grade(class_dir, tmp_path / "out", spec=None)
    assert status == 0, text
    with open(tmp_path / "out" / "grades.csv", newline="") as source:
        rows = {r["student"]: r for r in csv.DictReader(source)}
    tasks = ["ep5_avoid", "ep6_go_to_point", "ep7_follow_wall", "ep8_bug0", "ep9_bug1",
             "ep10_bug2"]
    scores = {s: [float(rows[s][t]) for t in tasks] + [float(rows[s]["total"])] for s in rows}
    # ada's avoider drives its minute, her go to point reaches (2, 8); gus's avoider too
    assert scores["ada"] == [20.0, 15.0, 0.0, 0.0, 0.0, 0.0, 35.0], rows["ada"]
    assert scores["gus"] == [20.0, 0.0, 0.0, 0.0, 0.0, 0.0, 20.0], rows["gus"]
    for student in ("bert", "cleo", "dan", "eve", "fay", "hal"):
        assert scores[student] == [0.0] * 7, rows[student]
    assert [rows[s]["rank"] for s in ("ada", "gus", "bert")] == ["1", "2", "3"]
    data = json.loads((tmp_path / "out" / "results.json").read_text())
    reasons = {(s, r["task"]): r["reason"] for s, student in data["students"].items()
               for r in student["runs"]}
    assert "has no file 'follow_wall.py'" in reasons["ada", "ep7_follow_wall"]
    assert "has no launch file 'bug2.launch'" in reasons["ada", "ep10_bug2"]
    assert "has no file 'obstacle_avoidance.py'" in reasons["bert", "ep5_avoid"]
    assert reasons["bert", "ep6_go_to_point"].startswith("did not reach the goal (2.00, 8.00)")
    assert reasons["cleo", "ep6_go_to_point"].startswith(
        "rules: called /gazebo/set_model_state for m2wr at (2.00, 8.00), by /go_to_point")
    assert reasons["dan", "ep6_go_to_point"].startswith(
        "rules: subscribed to /gazebo/model_states, by /go_to_point")
    assert reasons["eve", "ep6_go_to_point"].startswith("controller exited with status 1")
    assert reasons["fay", "ep6_go_to_point"].startswith("resources: its processes used more "
                                                       "than the 1536 MiB of memory allowed")
    assert "no package.xml and no scripts" in reasons["hal", "ep5_avoid"]


SERIES_SPEC = """\
version: 1
defaults:
  world: world02
  legacy_mode: {legacy_mode}
tasks:
"""
BUG_TASK = """\
  - name: {name}
    command: roslaunch motion_plan {launch} initial_x:=3.5 initial_y:=-3.5 des_x:=3.5 des_y:=3.5
    kind: goal
    world: {{pillar}}
    starts: [[3.5, -3.5, 0]]
    goal: [3.5, 3.5]
    duration: {duration}
    points: {points}
    allow: [set_model_state_to_start]
"""                              # bug 0-2's tasks: alike but for these four fields
SERIES_TASKS = {                 # each graded with the spec above: its text in the spec's list
    "ep6_go_to_point": """\
  - name: ep6_go_to_point
    command: rosrun motion_plan go_to_point.py
    kind: goal
    starts: [[0, 8, 1.5708]]
    goal: [2, 8]
    duration: 30
    points: 15
    after_start:
      - call: /go_to_point_switch
        request: "data: true"
        if_offered: true
""",
    "ep7_follow_wall": """\
  - name: ep7_follow_wall
    command: rosrun motion_plan follow_wall.py
    kind: wall
    duration: 60
    points: 15
    after_start:
      - call: /wall_follower_switch
        request: "data: true"
        if_offered: true
""",
    "ep8_bug0": BUG_TASK.format(name="ep8_bug0", launch="bug0.launch", duration=60, points=15),
    "ep9_bug1": BUG_TASK.format(name="ep9_bug1", launch="bug1.launch", duration=90, points=15),
    "ep10_bug2": BUG_TASK.format(name="ep10_bug2", launch="bug2.launch", duration=60,
                                 points=20),
}
PILLAR = os.path.join(ROOT, "catkin_ws", "src", "motion_plan", "test", "worlds",
                      "pillar_on_the_line.world")


def _series_grades(tmp_path, legacy_mode, students, tasks):
    """The `students` of the series class (fixtures/series_class: kim, the series' final
    package written for Kinetic's turning; noa, its copy flipped for Noetic's; lee, kim's
    programs with the world and the robot in her bug1.launch, and her own world launch in
    her bug2.launch) graded on `tasks` (SERIES_TASKS); (rows of grades.csv, runs by
    (student, task), the output folder)."""
    class_dir = tmp_path / ("class_%s" % legacy_mode)
    for student in students:
        shutil.copytree(os.path.join(FIXTURES, "series_class", student),
                        class_dir / student)                     # links followed
    os.chmod(class_dir, 0o700)
    spec = tmp_path / ("series_%s.yaml" % legacy_mode)
    spec.write_text(SERIES_SPEC.format(legacy_mode=str(legacy_mode).lower()) +
                    "".join(SERIES_TASKS[task].format(pillar=PILLAR) for task in tasks))
    output = tmp_path / ("out_%s" % legacy_mode)
    status, text = grade(class_dir, output, spec=str(spec), timeout=900)
    assert status == 0, text
    with open(output / "grades.csv", newline="") as source:
        rows = {r["student"]: r for r in csv.DictReader(source)}
    data = json.loads((output / "results.json").read_text())
    runs = {(s, r["task"]): r for s, student in data["students"].items()
            for r in student["runs"]}
    return rows, runs, output


def test_the_series_final_packages_are_graded_with_the_turning_they_were_written_for(tmp_path):
    """The series' final behaviours start switched off: the spec's after_start switches them
    on as the pages do. Graded with legacy_mode true, kim's package (written for Kinetic's
    turning) scores go to point, wall following and bug 0, 1 and 2. lee's launch files start
    a world and spawn m2wr (bug1.launch by gazebo_ros's and m2wr_description's launch files,
    bug2.launch through a world launch of her own, which includes my_worlds' and spawns
    m2wr itself): those parts are left out, her page says what and why, and her runs are
    kim's to the bit (the grader's world was not touched); she handed in no bug0.launch,
    and her page says so. With legacy_mode false, the other way round: noa's copy (flipped
    for Noetic's turning) scores the same, and kim's go to point and bug 0-2 turn away from
    the goal, which the page and the class table say. Bug 0-2 go round a pillar on their
    line (from (3.5, -3.5), placed facing east, to (3.5, 3.5)): under the other convention
    go to point turns away on the spot. (noa under legacy_mode true is the mirror of kim
    under false, and is not graded.)"""
    tasks = ("ep6_go_to_point", "ep7_follow_wall", "ep8_bug0", "ep9_bug1", "ep10_bug2")
    rows, runs, output = _series_grades(tmp_path, True, ("kim", "lee"), tasks)
    scores = {s: [float(rows[s][t]) for t in tasks] for s in rows}
    assert scores["kim"] == [15.0, 15.0, 15.0, 15.0, 20.0], rows["kim"]
    assert scores["lee"] == [15.0, 15.0, 0.0, 15.0, 20.0], rows["lee"]
    assert runs["lee", "ep8_bug0"]["reason"].endswith(
        "package 'motion_plan' (lee/motion_plan) has no launch file 'bug0.launch'")
    assert runs["kim", "ep6_go_to_point"]["after_start"] == [
        "called /go_to_point_switch (data: true): success: True, message: Done!"]
    # bug 0 went round the pillar (radius 1 m at (3.5, 0)), not through it
    assert min(x for _, x, _ in runs["kim", "ep8_bug0"]["path"]) < 2.5
    left_out = {
        "ep9_bug1": [('<include file="$(find gazebo_ros)/launch/empty_world.launch">',
                      "it starts a simulator or a world"),
                     ('<include file="$(find m2wr_description)/launch/spawn.launch">',
                      "it spawns the robot again")],
        "ep10_bug2": [('<include file="$(find my_worlds)/launch/world.launch">',
                       "it starts a simulator or a world"),
                      ('<param name="robot_description">', "the robot's description"),
                      ('<node pkg="gazebo_ros" type="spawn_model" name="mybot_spawn">',
                       "it spawns the robot again")]}
    for task, elements in left_out.items():
        kim, lee = runs["kim", task], runs["lee", task]
        assert [(x["element"], x["why"].split(";")[0]) for x in lee["left_out"]] == elements
        assert kim["left_out"] == []
        for key in ("path", "time_to_goal_s", "final_x", "final_y", "contact_events"):
            assert lee[key] == kim[key], (task, key)
    page = (output / "students" / "lee.html").read_text()
    assert "Left out of the launch files" in page and \
        "$(find gazebo_ros)/launch/empty_world.launch" in page and \
        "$(find my_worlds)/launch/world.launch" in page
    assert "legacy_mode true: Kinetic&#x27;s diff drive" in page
    assert "Turning: <b>legacy_mode true" in (output / "index.html").read_text()

    # (lee is graded once: her runs are kim's to the bit, shown above)
    rows, runs, output = _series_grades(tmp_path, False, ("kim", "noa"), tasks)
    scores = {s: [float(rows[s][t]) for t in tasks] for s in rows}
    assert scores["noa"] == [15.0, 15.0, 15.0, 15.0, 20.0], rows["noa"]
    turned_away = {"ep6_go_to_point": "(2.00, 8.00)", "ep8_bug0": "(3.50, 3.50)",
                   "ep9_bug1": "(3.50, 3.50)", "ep10_bug2": "(3.50, 3.50)"}
    for task, goal in turned_away.items():
        assert float(rows["kim"][task]) == 0.0, (task, rows["kim"])
        reason = runs["kim", task]["reason"]
        assert reason.startswith("did not reach the goal %s within 0.30 m: turned away from "
                                 "the goal" % goal), reason
        assert reason.endswith("(this task: legacy_mode false)"), reason
    index = (output / "index.html").read_text()
    assert "Turning: <b>legacy_mode false" in index
    # one short line per failed task in the table, the whole reason in its tooltip
    for task in turned_away:
        assert '%s</a>: did not reach the goal: turned away from the goal</div>' % task \
            in index, task
    assert 'title="did not reach the goal (2.00, 8.00) within 0.30 m: turned away' in index
