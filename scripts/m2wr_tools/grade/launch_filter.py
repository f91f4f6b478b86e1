"""A student's launch file without the parts that would touch the grader's world.

Learners keep the world and the robot in their own launch files (a `bug1.launch` that
includes `$(find gazebo_ros)/launch/empty_world.launch` and `spawn.launch`). In a graded run
the grader's simulator is already up, at the task's world and start: a second simulator node
named /gazebo would make the master shut the grader's down, and a second spawn is refused. So
before a run, the run's own copy of the launch file the command names is rewritten without:
  - an <include> of a simulator's or world's launch file: any launch file of SIMULATORS
    (gazebo_ros's empty_world.launch, my_worlds' world.launch, ...)
  - an <include> of a spawn launch file (m2wr_description's spawn.launch, any spawn*.launch)
  - a <node> of a simulator package (gazebo_ros's spawn_model, gzserver, gzclient, ...)
  - a <param name="robot_description">: the robot the grader spawned is the one graded
and with every <include> of a launch file of the student's own packages rewritten the same
way (in place, in the run's copy), so `bug1.launch` -> `world.launch` of theirs ->
empty_world.launch is found too. Everything else (their nodes, args, params, groups) is kept.

  filter_in_place(path, own_package_dir) -> [LeftOut]   what was left out, in file order
A file that is not valid XML is left as it is: roslaunch will say what is wrong with it.
"""
from dataclasses import dataclass
import os
import re
import xml.etree.ElementTree as ET

SIMULATORS = ("gazebo_ros", "gazebo_ros_pkgs", "my_worlds", "pybullet_gazebo")
FIND = re.compile(r"\$\(find\s+([^\s)]+)\)")
DIRNAME = re.compile(r"\$\(dirname\)")
WORLD_WHY = "it starts a simulator or a world; the grader's world (the task's) runs instead"
SPAWN_WHY = "it spawns the robot again; the grader has put m2wr at the task's start"
DESCRIPTION_WHY = "the robot's description; the grader's m2wr is already spawned"


@dataclass(frozen=True)
class LeftOut:
    file: str            # the launch file's name, as its package has it (launch/bug1.launch)
    element: str         # the element as written, shortened: <include file="...">
    why: str

    def describe(self):
        return "%s: %s (%s)" % (self.file, self.element, self.why)


def _tag(element):
    attrs = " ".join('%s="%s"' % (k, element.attrib[k]) for k in ("file", "pkg", "type", "name")
                     if k in element.attrib)
    return "<%s%s>" % (element.tag, " " + attrs if attrs else "")


def _why(element):
    """Why `element` is left out, or None to keep it."""
    if element.tag == "include":
        target = element.get("file", "")
        found = FIND.search(target)
        package = found.group(1) if found else ""
        base = os.path.basename(target)
        if base.startswith("spawn"):
            return SPAWN_WHY
        if package in SIMULATORS:
            return WORLD_WHY
        return None
    if element.tag == "node":
        if element.get("pkg") in SIMULATORS:
            return SPAWN_WHY if "spawn" in element.get("type", "") else WORLD_WHY
        return None
    if element.tag == "param" and element.get("name", "").lstrip("/") == "robot_description":
        return DESCRIPTION_WHY
    return None


def _own_include(element, here, packages):
    """The path of the student's own launch file an <include> names, or None."""
    target = element.get("file", "")
    found = FIND.search(target)
    if found:
        if found.group(1) not in packages:
            return None
        target = target.replace(found.group(0), packages[found.group(1)])
    target = DIRNAME.sub(os.path.dirname(here), target)
    if "$(" in target or not os.path.isfile(target):
        return None           # made of args: roslaunch resolves it, as the student wrote it
    return os.path.realpath(target)


def filter_in_place(path, packages, root=None, _seen=None):
    """Rewrites the launch file at `path` (and the student's launch files it includes) without
    what would touch the grader's world; returns [LeftOut]. `packages`: {name: folder} of the
    student's packages (in the run's copy); `root` names files relative to it."""
    seen = set() if _seen is None else _seen
    path = os.path.realpath(path)
    if path in seen:
        return []
    seen.add(path)
    root = root or os.path.dirname(path)
    try:
        tree = ET.parse(path)
    except (ET.ParseError, OSError):
        return []
    if tree.getroot().tag != "launch":
        return []
    name = os.path.relpath(path, root)
    left, changed = [], False

    def walk(parent):
        nonlocal changed
        for element in list(parent):
            why = _why(element)
            if why is not None:
                parent.remove(element)
                left.append(LeftOut(name, _tag(element), why))
                changed = True
            elif element.tag == "include":
                own = _own_include(element, path, packages)
                if own is not None:
                    left.extend(filter_in_place(own, packages, root, seen))
            elif element.tag == "group":
                walk(element)
    walk(tree.getroot())
    if changed:
        tree.write(path, encoding="utf-8", xml_declaration=True)
    return left
