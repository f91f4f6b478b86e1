"""A class of submissions: one folder per student in CLASS_DIR, each a catkin package (its
package.xml names it, normally motion_plan; anywhere up to three folders deep, e.g.
catkin_ws/src/motion_plan) or loose scripts (*.py, *.launch), which are made into a package
named motion_plan (scripts/ and launch/).

  discover(class_dir) -> [Submission]   ValueError when the class folder is missing or empty
  stage(submission, folder)             copies its packages into folder/<package>/, scripts
                                        executable (as catkin_install_python would install
                                        them); returns the package names
  overlay_env(env, packages_root, shadowed)
                                        the environment a student's run resolves packages
                                        in: packages_root first on ROS_PACKAGE_PATH, and no
                                        package named in `shadowed` (the student's own names
                                        and those the spec's commands use) anywhere else, so
                                        `rosrun motion_plan ...` finds the student's package
                                        or none, never the project's or another student's
"""
from dataclasses import dataclass
import os
import re
import shutil
import xml.etree.ElementTree as ET
from typing import Optional, Tuple

DEFAULT_PACKAGE = "motion_plan"
SCRIPT_SUFFIXES = (".py",)
LAUNCH_SUFFIXES = (".launch", ".xml")
MAX_DEPTH = 3
SKIP = {".git", "build", "devel", "install", "__pycache__", ".venv"}
STUDENT = re.compile(r"^[A-Za-z0-9_.-]+$")


@dataclass(frozen=True)
class Submission:
    student: str                       # the folder's name
    source: str                        # its path
    packages: Tuple[Tuple[str, str], ...] = ()   # (name, folder) of each package.xml found
    scripts: Tuple[str, ...] = ()      # loose scripts and launch files, when no package
    problem: Optional[str] = None      # why it cannot be graded, if it cannot

    @property
    def kind(self):
        return "package" if self.packages else "scripts" if self.scripts else "nothing"


def _package_name(path):
    try:
        name = ET.parse(path).getroot().findtext("name")
    except (ET.ParseError, OSError) as err:
        raise ValueError("%s cannot be read (%s)" % (path, err))
    if not name or not name.strip():
        raise ValueError("%s has no <name>" % path)
    return name.strip()


def _walk(folder):
    """(dirpath, files) up to MAX_DEPTH folders below `folder`, skipping build folders."""
    base = folder.rstrip(os.sep).count(os.sep)
    for dirpath, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if d not in SKIP and not d.startswith("."))
        if dirpath.count(os.sep) - base >= MAX_DEPTH:
            dirs[:] = []
        yield dirpath, sorted(files)


def inspect(student, folder):
    """The Submission of one student's folder."""
    if not STUDENT.match(student):
        return Submission(student, folder, problem="the folder name '%s' has characters other "
                          "than letters, digits, '.', '_' and '-'; rename it" % student)
    packages, scripts = [], []
    try:
        for dirpath, files in _walk(folder):
            if "package.xml" in files:
                packages.append((_package_name(os.path.join(dirpath, "package.xml")), dirpath))
            scripts += [os.path.join(dirpath, f) for f in files
                        if f.endswith(SCRIPT_SUFFIXES + LAUNCH_SUFFIXES) and f != "package.xml"]
    except ValueError as err:
        return Submission(student, folder, problem="%s; fix the package.xml" % err)
    names = [n for n, _ in packages]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        return Submission(student, folder, problem="the package %s is handed in twice (%s); "
                          "keep one" % (twice[0], ", ".join(d for n, d in packages
                                                             if n == twice[0])))
    if packages:
        return Submission(student, folder, packages=tuple(packages))
    if scripts:
        return Submission(student, folder, scripts=tuple(scripts))
    return Submission(student, folder, problem="no package.xml and no scripts (.py, .launch) "
                      "in %s; hand in the %s package or its scripts" % (folder, DEFAULT_PACKAGE))


def discover(class_dir):
    """Every student folder of `class_dir`, sorted by name; ValueError when there is none."""
    if not os.path.isdir(class_dir):
        raise ValueError("class folder %s not found; pass CLASS_DIR, a folder with one folder "
                         "per student" % class_dir)
    students = sorted(d for d in os.listdir(class_dir)
                      if os.path.isdir(os.path.join(class_dir, d)) and not d.startswith("."))
    if not students:
        raise ValueError("class folder %s has no student folders; put one folder per student "
                         "in it (each a %s package or its scripts)" % (class_dir, DEFAULT_PACKAGE))
    return [inspect(s, os.path.join(class_dir, s)) for s in students]


def stage(submission, folder):
    """Copies the submission's packages into folder/<name>/ (loose scripts into a package
    motion_plan: .py in scripts/, launch files in launch/), makes scripts/ and nodes/ files
    executable; returns the package names."""
    os.makedirs(folder, exist_ok=True)
    names = []
    ignore = shutil.ignore_patterns(*SKIP)
    for name, source in submission.packages:
        target = os.path.join(folder, name)
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(source, target, symlinks=False, ignore=ignore)
        names.append(name)
    if submission.scripts:
        target = os.path.join(folder, DEFAULT_PACKAGE)
        shutil.rmtree(target, ignore_errors=True)
        for sub in ("scripts", "launch"):
            os.makedirs(os.path.join(target, sub))
        for path in submission.scripts:
            sub = "scripts" if path.endswith(SCRIPT_SUFFIXES) else "launch"
            shutil.copy(path, os.path.join(target, sub, os.path.basename(path)))
        with open(os.path.join(target, "package.xml"), "w") as out:
            out.write('<?xml version="1.0"?>\n<package format="2">\n  <name>%s</name>\n'
                      '  <version>0.0.0</version>\n  <description>%s\'s loose scripts, made into '
                      'a package by the grader</description>\n  <maintainer email="grader@'
                      'localhost">grader</maintainer>\n  <license>unknown</license>\n'
                      '  <buildtool_depend>catkin</buildtool_depend>\n</package>\n'
                      % (DEFAULT_PACKAGE, submission.student))
        names.append(DEFAULT_PACKAGE)
    for name in names:
        for sub in ("scripts", "nodes"):
            for dirpath, _, files in os.walk(os.path.join(folder, name, sub)):
                for f in files:
                    path = os.path.join(dirpath, f)
                    os.chmod(path, os.stat(path).st_mode | 0o755)
    return names


def _packages_in(entry):
    """{name: folder} of the packages under a ROS_PACKAGE_PATH entry."""
    import rospkg
    cache = {}
    rospkg.rospack.list_by_path("package.xml", entry, cache)
    return cache


def overlay_env(env, packages_root, shadowed):
    """A copy of `env` in which packages_root comes first on ROS_PACKAGE_PATH and no other
    package named in `shadowed` can be found (ROS_PACKAGE_PATH entries holding one are
    replaced by their other packages; CMAKE_PREFIX_PATH workspaces built from one, which
    rosrun's catkin_find would search, are dropped)."""
    shadowed = set(shadowed)
    entries = []
    for entry in filter(None, env.get("ROS_PACKAGE_PATH", "").split(os.pathsep)):
        found = _packages_in(entry)
        if shadowed & set(found):
            entries += sorted(folder for name, folder in found.items() if name not in shadowed)
        else:
            entries.append(entry)
    prefixes = []
    for prefix in filter(None, env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep)):
        try:
            with open(os.path.join(prefix, ".catkin")) as marker:
                sources = [s for s in marker.read().split(";") if s]
        except OSError:
            sources = []
        if not any(shadowed & set(_packages_in(s)) for s in sources if os.path.isdir(s)):
            prefixes.append(prefix)
    out = dict(env)
    out["ROS_PACKAGE_PATH"] = os.pathsep.join([packages_root] + entries)
    out["CMAKE_PREFIX_PATH"] = os.pathsep.join(prefixes)
    return out
