"""The grading spec: a YAML file listing the tasks every submission is graded on. Field by
field (the default, spec_default.yaml beside this file, says the same in its comments):

  version: 1                      the format's version
  limits:                         what one run of a submission may use (optional; defaults)
    cpu_s: 120                    [s] CPU time of each of its processes
    memory_mib: 1536              [MiB] resident memory of all its processes together
    processes: 256                processes and threads of its user at once
    file_mib: 64                  [MiB] largest file it may write
  defaults: {FIELD: VALUE}        task fields every task gets unless it sets its own
  tasks:                          a list; each task:
    name        required  a short id: letters, digits, _ and - (a column of the grades)
    command     required  the command line, as a student would type it: `rosrun PKG SCRIPT`
                          or `roslaunch PKG FILE.launch ARG:=VALUE...`
    kind        required  wander | goal | wall: what the batch runner measures
                          (m2wr_tools.analysis.metrics: wander = no contact and min_distance
                          travelled; goal = within tolerance of goal; wall = no contact and
                          half the time 0.2-1.5 m from an obstacle)
    episode               the series' episode number (shown in the report)
    description           one line shown in the report
    world                 world01 | world02 | world03 | a .world path, absolute or relative
                          to the spec's folder (default world02)
    starts                [[x, y, yaw], ...] [m, m, rad] start poses (default [[0, 8, 0]])
    seeds                 [0, ...] simulator seeds (laser noise); one run per start x seed
    duration              [s] of sim time a run lasts (default 60)
    points                what the task is worth; a student gets points x runs passed / runs
    goal                  [x, y] [m], the goal task's goal (also set as the ROS parameters
                          des_pos_x, des_pos_y; the start as initial_x, initial_y)
    tolerance             [m] goal radius (default 0.3)
    min_distance          [m] wander/wall: least distance travelled (default 1)
    allow                 extra permissions (m2wr_tools.grade.rules.PERMISSIONS), e.g.
                          [set_model_state_to_start] for the bug programs
    legacy_mode           false (default): Gazebo Noetic's diff drive, a positive angular.z
                          turns m2wr clockwise; true: Kinetic's, REP 103 turning (counter-
                          clockwise), which the series' own programs of episodes 6-10 are
                          written for. Passed to the world launch as legacy_mode:=
    after_start           what the grader does once the controller is up, before the world
                          runs, in order; each item one of
                            {call: SERVICE, request: "FIELD: VALUE, ...", if_offered: BOOL,
                             wait: S}   calls SERVICE as `rosservice call SERVICE "REQUEST"`
                                        would (the type asked of the service); if_offered
                                        true: a program that does not offer it within `wait`
                                        [s] of wall time (default 2) is run as it is (the
                                        page says so); false (default): that fails the run
                            {param: NAME, value: VALUE}   sets a ROS parameter
                          e.g. [{call: /go_to_point_switch, request: "data: true",
                          if_offered: true}], as the series' pages switch go to point on

load(path) -> Spec; SpecError (a ValueError) names the file, the line and the field, and
says what to write instead.
"""
from dataclasses import dataclass, field
import math
import os
import re
import shlex
from typing import Optional, Tuple

import yaml

from ..analysis.metrics import TASKS
from .rules import PERMISSIONS

DEFAULT_SPEC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "spec_default.yaml")
NAME = re.compile(r"^[A-Za-z0-9_-]+$")
TASK_FIELDS = ("name", "command", "kind", "episode", "description", "world", "starts", "seeds",
               "duration", "points", "goal", "tolerance", "min_distance", "allow",
               "legacy_mode", "after_start")
STEP_FIELDS = {"call": ("call", "request", "if_offered", "wait"), "param": ("param", "value")}
STEP_WAIT = 2.0                 # [s wall] an after_start call waits this long for its service
LIMIT_FIELDS = ("cpu_s", "memory_mib", "processes", "file_mib")


@dataclass(frozen=True)
class Step:
    """One thing the grader does after the controller is up (a task's `after_start`).
    kind "call": `name` is the service, `text` the request as rosservice call's YAML;
    kind "param": `name` is the parameter, `text` its value as YAML."""
    kind: str
    name: str
    text: str = ""
    if_offered: bool = False
    wait: float = STEP_WAIT      # [s wall]

    def as_dict(self):
        return {"kind": self.kind, "name": self.name, "text": self.text,
                "if_offered": self.if_offered, "wait": self.wait}

    def describe(self):
        if self.kind == "call":
            return 'rosservice call %s "%s"%s' % (self.name, self.text, " (if offered)"
                                                  if self.if_offered else "")
        return "rosparam set %s %s" % (self.name, self.text)


class SpecError(ValueError):
    """The spec cannot be used; the message names the file, line and field."""


@dataclass(frozen=True)
class Limits:
    cpu_s: float = 120.0          # [s] CPU per process (RLIMIT_CPU)
    memory_mib: float = 1536.0    # [MiB] resident memory of the run's processes together
    processes: int = 256          # processes + threads of the run's user (RLIMIT_NPROC)
    file_mib: float = 64.0        # [MiB] largest file written (RLIMIT_FSIZE)


@dataclass(frozen=True)
class TaskSpec:
    name: str
    command: Tuple[str, ...]
    kind: str
    episode: Optional[int] = None
    description: str = ""
    world: str = "world02"
    starts: Tuple[Tuple[float, float, float], ...] = ((0.0, 8.0, 0.0),)
    seeds: Tuple[int, ...] = (0,)
    duration: float = 60.0        # [s] sim
    points: float = 10.0
    goal: Optional[Tuple[float, float]] = None
    tolerance: float = 0.3        # [m]
    min_distance: float = 1.0     # [m]
    allow: Tuple[str, ...] = ()
    legacy_mode: bool = False     # the simulator's legacy_mode:= (Kinetic's turning)
    after_start: Tuple[Step, ...] = ()

    @property
    def runs(self):
        """[(index, (x, y, yaw), seed)] in a fixed order."""
        return [(i, start, seed) for i, (seed, start) in enumerate(
            (s, p) for s in self.seeds for p in self.starts)]


@dataclass(frozen=True)
class Spec:
    path: str
    tasks: Tuple[TaskSpec, ...]
    limits: Limits = field(default_factory=Limits)

    @property
    def points(self):
        return sum(t.points for t in self.tasks)

    @property
    def legacy_modes(self):
        """The turning conventions its tasks use, sorted: (False,), (True,) or both."""
        return tuple(sorted({t.legacy_mode for t in self.tasks}))


class _Located(dict):
    """A YAML mapping that remembers the line of each key (1-based)."""
    line = 0

    def __init__(self):
        super().__init__()
        self.lines = {}


class _Loader(yaml.SafeLoader):
    pass


def _mapping(loader, node):
    loader.flatten_mapping(node)
    data = _Located()
    data.line = node.start_mark.line + 1
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        data[key] = loader.construct_object(value_node, deep=True)
        data.lines[key] = key_node.start_mark.line + 1
    return data


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)


def load(path):
    """The Spec of the YAML file at `path`; SpecError naming the file, line and field."""
    if not os.path.isfile(path):
        raise SpecError("spec %s not found; pass --spec PATH of a YAML spec (the default: %s)"
                        % (path, DEFAULT_SPEC))
    try:
        with open(path, encoding="utf-8") as source:
            data = yaml.load(source, Loader=_Loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = " line %d" % (mark.line + 1) if mark else ""
        raise SpecError("spec %s%s: not valid YAML (%s); fix the indentation or quoting there"
                        % (path, where, getattr(err, "problem", None) or err))
    return parse(data, path)


def parse(data, path="<spec>"):
    def fail(line, what):
        raise SpecError("spec %s line %d: %s" % (path, line, what))
    if not isinstance(data, _Located):
        fail(1, "the spec must be a mapping with a `tasks:` list")
    unknown = sorted(set(data) - {"version", "limits", "defaults", "tasks"})
    if unknown:
        fail(data.lines[unknown[0]], "unknown field `%s`; the fields are version, limits, "
             "defaults, tasks" % unknown[0])
    if data.get("version", 1) != 1:
        fail(data.lines["version"], "version %r is not supported; write version: 1"
             % data["version"])
    limits = _limits(data.get("limits"), data.lines.get("limits", data.line), fail)
    defaults = data.get("defaults") or _Located()
    if not isinstance(defaults, _Located):
        fail(data.lines["defaults"], "`defaults` must be a mapping of task fields")
    tasks = data.get("tasks")
    if not isinstance(tasks, list) or not tasks:
        fail(data.lines.get("tasks", data.line), "`tasks` must be a non-empty list of tasks")
    parsed, names = [], set()
    for number, task in enumerate(tasks, 1):
        if not isinstance(task, _Located):
            fail(data.lines["tasks"], "task %d must be a mapping (name:, command:, kind:, ...)"
                 % number)
        one = _task(task, defaults, number, fail, path)
        if one.name in names:
            fail(task.lines["name"], "tasks[%d].name: '%s' is used twice; give each task its "
                 "own name" % (number, one.name))
        names.add(one.name)
        parsed.append(one)
    return Spec(path=path, tasks=tuple(parsed), limits=limits)


def _limits(data, line, fail):
    if data is None:
        return Limits()
    if not isinstance(data, _Located):
        fail(line, "`limits` must be a mapping of %s" % ", ".join(LIMIT_FIELDS))
    values = {}
    for key, value in data.items():
        if key not in LIMIT_FIELDS:
            fail(data.lines[key], "limits.%s is unknown; the limits are %s"
                 % (key, ", ".join(LIMIT_FIELDS)))
        if not _number(value) or value <= 0:
            fail(data.lines[key], "limits.%s: %r must be a number > 0" % (key, value))
        values[key] = int(value) if key == "processes" else float(value)
    return Limits(**values)


def _number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


def _task(task, defaults, number, fail, path="<spec>"):
    merged, lines = dict(defaults), dict(getattr(defaults, "lines", {}))
    merged.update(task)
    lines.update(task.lines)
    where = "tasks[%d]" % number

    def bad(key, what):
        fail(lines.get(key, task.line), "%s.%s: %s" % (where, key, what))
    for key in merged:
        if key not in TASK_FIELDS:
            bad(key, "unknown field; a task's fields are %s" % ", ".join(TASK_FIELDS))
    for key in ("name", "command", "kind"):
        if key not in merged:
            fail(task.line, "%s: `%s` is missing; every task needs name, command and kind"
                 % (where, key))
    name = merged["name"]
    if not isinstance(name, str) or not NAME.match(name):
        bad("name", "%r must be letters, digits, _ and - only" % (name,))
    if not isinstance(merged["command"], str) or not merged["command"].strip():
        bad("command", "must be a command line such as 'rosrun motion_plan "
            "obstacle_avoidance.py'")
    try:
        command = tuple(shlex.split(merged["command"]))
    except ValueError as err:
        bad("command", "cannot be split into words (%s)" % err)
    if command[0] not in ("rosrun", "roslaunch"):
        bad("command", "'%s' must start with rosrun or roslaunch (the student's package is "
            "found through them)" % merged["command"])
    if merged["kind"] not in TASKS:
        bad("kind", "%r is not a task kind; use one of %s" % (merged["kind"], ", ".join(TASKS)))
    values = {"name": name, "command": command, "kind": merged["kind"]}
    if "episode" in merged:
        if not isinstance(merged["episode"], int) or isinstance(merged["episode"], bool):
            bad("episode", "%r must be a whole number" % (merged["episode"],))
        values["episode"] = merged["episode"]
    if "description" in merged:
        values["description"] = str(merged["description"])
    if "world" in merged:
        if not isinstance(merged["world"], str) or not merged["world"].strip():
            bad("world", "must be a world name (world01, world02, world03) or a .world path")
        world = merged["world"]
        if world.endswith(".world") and not os.path.isabs(world) and os.path.isfile(path):
            # a .world path relative to the spec's folder (the default spec's bug 2 world)
            world = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)),
                                                  world))
        values["world"] = world
    if "starts" in merged:
        starts = merged["starts"]
        if not isinstance(starts, list) or not starts or not all(
                isinstance(s, list) and len(s) == 3 and all(map(_number, s)) for s in starts):
            bad("starts", "must be a list of [x, y, yaw] in m, m, rad, e.g. [[0, 8, 0]]")
        values["starts"] = tuple(tuple(float(v) for v in s) for s in starts)
    if "seeds" in merged:
        seeds = merged["seeds"]
        if not isinstance(seeds, list) or not seeds or not all(
                isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds):
            bad("seeds", "must be a list of whole numbers >= 0, e.g. [0, 1]")
        values["seeds"] = tuple(seeds)
    for key in ("duration", "tolerance"):
        if key in merged:
            if not _number(merged[key]) or merged[key] <= 0:
                bad(key, "%r must be a number > 0" % (merged[key],))
            values[key] = float(merged[key])
    for key in ("points", "min_distance"):
        if key in merged:
            if not _number(merged[key]) or merged[key] < 0:
                bad(key, "%r must be a number >= 0" % (merged[key],))
            values[key] = float(merged[key])
    if "goal" in merged:
        goal = merged["goal"]
        if not (isinstance(goal, list) and len(goal) == 2 and all(map(_number, goal))):
            bad("goal", "must be [x, y] in m, e.g. [2, -3]")
        values["goal"] = (float(goal[0]), float(goal[1]))
    elif merged["kind"] == "goal":
        fail(task.line, "%s: the goal task '%s' needs `goal: [x, y]`" % (where, name))
    if "allow" in merged:
        allow = merged["allow"]
        if not isinstance(allow, list) or not all(a in PERMISSIONS for a in allow):
            bad("allow", "%r must be a list of permissions from: %s" % (
                allow, ", ".join(sorted(PERMISSIONS))))
        values["allow"] = tuple(allow)
    if "legacy_mode" in merged:
        if not isinstance(merged["legacy_mode"], bool):
            bad("legacy_mode", "%r must be true (Kinetic's turning, as the series' code is "
                "written) or false (Gazebo Noetic's, the default)" % (merged["legacy_mode"],))
        values["legacy_mode"] = merged["legacy_mode"]
    if "after_start" in merged:
        values["after_start"] = _steps(merged["after_start"], lambda what: bad(
            "after_start", what))
    return TaskSpec(**values)


def _plain(value):
    """`value` with the loader's mappings as plain dicts (for yaml.safe_dump)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _steps(items, bad):
    """The Steps of an `after_start` list; bad(what) for anything else."""
    example = ('e.g. [{call: /go_to_point_switch, request: "data: true", if_offered: true}] '
               'or [{param: /my_node/active, value: true}]')
    if not isinstance(items, list):
        bad("must be a list of {call: SERVICE, request: ...} or {param: NAME, value: ...}, "
            + example)
    steps = []
    for number, item in enumerate(items, 1):
        kinds = [k for k in STEP_FIELDS if isinstance(item, dict) and k in item]
        if len(kinds) != 1:
            bad("item %d must have one of `call:` or `param:`, %s" % (number, example))
        kind = kinds[0]
        unknown = sorted(set(item) - set(STEP_FIELDS[kind]))
        if unknown:
            bad("item %d: `%s` is unknown; a %s item has %s" % (
                number, unknown[0], kind, ", ".join(STEP_FIELDS[kind])))
        name = item[kind]
        if not isinstance(name, str) or not re.match(r"^/?[A-Za-z][A-Za-z0-9_/]*$", name):
            bad("item %d: %s %r must be a ROS name such as /go_to_point_switch"
                % (number, kind, name))
        if kind == "call":
            request = item.get("request", "")
            if isinstance(request, dict):
                request = yaml.safe_dump(_plain(request), default_flow_style=True,
                                         sort_keys=True).strip()[1:-1]
            elif not isinstance(request, str):
                bad("item %d: request %r must be rosservice call's YAML, e.g. \"data: true\""
                    % (number, request))
            if_offered = item.get("if_offered", False)
            wait = item.get("wait", STEP_WAIT)
            if not isinstance(if_offered, bool):
                bad("item %d: if_offered %r must be true or false" % (number, if_offered))
            if not _number(wait) or wait < 0:
                bad("item %d: wait %r must be a number of seconds >= 0" % (number, wait))
            steps.append(Step("call", name, request, if_offered, float(wait)))
        else:
            if "value" not in item:
                bad("item %d: param %s needs `value:`" % (number, name))
            steps.append(Step("param", name, yaml.safe_dump(
                _plain(item["value"]), default_flow_style=True).strip().replace("\n...", "")))
    return tuple(steps)
