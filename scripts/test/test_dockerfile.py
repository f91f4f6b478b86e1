"""Static checks of docker/Dockerfile and .dockerignore (pytest, no docker daemon needed).

The Dockerfile is parsed into instructions (comments dropped, `\\` continuations joined) and
checked against what docker/README.md promises: a pinned Debian 12 base, sources and scripts
that exist in the repository, the project at /home/ros/m2wr, a non-root user, no exposed port,
and a build context without local state.
"""
import datetime
import fnmatch
import json
import posixpath
import re
import shlex
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCKERFILE = ROOT / "docker" / "Dockerfile"
DOCKERIGNORE = ROOT / ".dockerignore"
PROJECT_DIR = "/home/ros/m2wr"  # where docker/README.md mounts output/


def parse_dockerfile(text):
    """[(KEYWORD, arguments)] in file order, e.g. ("RUN", "apt-get update && ...")."""
    instructions = []
    pending = ""
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue  # also inside a continuation, as docker does
        if stripped.endswith("\\"):
            pending += stripped[:-1] + " "
            continue
        keyword, _, arguments = (pending + stripped).partition(" ")
        instructions.append((keyword.upper(), arguments.strip()))
        pending = ""
    assert not pending, f"{DOCKERFILE}: the last instruction ends with a dangling '\\'"
    return instructions


def words(arguments):
    """The arguments of COPY/ADD/CMD in either form: JSON array or shell words."""
    if arguments.startswith("["):
        return json.loads(arguments)
    return shlex.split(arguments)


@pytest.fixture(scope="module")
def instructions():
    if not DOCKERFILE.is_file():
        pytest.fail(f"{DOCKERFILE} not found; the image is built with "
                    "`docker build -f docker/Dockerfile -t m2wr .`")
    return parse_dockerfile(DOCKERFILE.read_text())


def of(instructions, keyword):
    return [arguments for kw, arguments in instructions if kw == keyword]


def test_the_base_image_is_a_pinned_debian_bookworm(instructions):
    bases = of(instructions, "FROM")
    assert len(bases) == 1, f"expected one FROM (a single-stage build), found {bases}"
    image = bases[0].split()[0]
    match = re.fullmatch(
        r"debian:bookworm(?:-(?P<date>\d{8}))?(?:-slim)?(?P<digest>@sha256:[0-9a-f]{64})?", image)
    assert match, f"base image {image!r} is not debian:bookworm[-YYYYMMDD][-slim][@sha256:...]"
    assert match["date"] or match["digest"], (
        f"base image {image!r} floats: pin a dated tag (debian:bookworm-YYYYMMDD) or a digest")
    if match["date"]:
        datetime.datetime.strptime(match["date"], "%Y%m%d")  # a real date, or ValueError


def test_every_copy_and_add_source_exists_in_the_repository(instructions):
    sources = []
    for arguments in of(instructions, "COPY") + of(instructions, "ADD"):
        args = words(arguments)
        if any(arg.startswith("--from") for arg in args):
            continue  # copied from another stage, not from the build context
        args = [arg for arg in args if not arg.startswith("--")]
        assert len(args) >= 2, f"COPY/ADD without source and destination: {arguments!r}"
        sources += args[:-1]
    assert sources, "the Dockerfile copies nothing from the repository"
    missing = [source for source in sources if not (ROOT / source).exists()]
    assert not missing, f"COPY/ADD sources not in the repository {ROOT}: {missing}"


def test_the_project_is_copied_to_home_ros_m2wr(instructions):
    workdir = "/"
    destinations = []
    for keyword, arguments in instructions:
        if keyword == "WORKDIR":
            workdir = posixpath.join(workdir, arguments)
        elif keyword == "COPY":
            args = words(arguments)
            if "." in args[:-1]:
                destinations.append(posixpath.normpath(posixpath.join(workdir, args[-1])))
    assert destinations == [PROJECT_DIR], (
        f"expected the whole context (COPY . ...) copied once to {PROJECT_DIR}, "
        f"found {destinations}")


def test_every_scripts_path_a_run_or_cmd_uses_exists(instructions):
    commands = of(instructions, "RUN") + of(instructions, "CMD") + of(instructions, "ENTRYPOINT")
    used = sorted({m for command in commands
                   for m in re.findall(r"\bscripts/[\w.-]+(?:/[\w.-]+)*", command)})
    assert "scripts/setup.sh" in used, "no RUN calls scripts/setup.sh"
    missing = [path for path in used if not (ROOT / path).is_file()]
    assert not missing, f"the Dockerfile uses scripts missing from {ROOT}: {missing}"


def test_the_default_command_runs_the_demo(instructions):
    commands = of(instructions, "CMD")
    assert len(commands) == 1, f"expected one CMD, found {commands}"
    assert words(commands[0]) == ["bash", "scripts/demo.sh"]


def test_a_non_root_user_runs_the_default_command(instructions):
    keywords = [keyword for keyword, _ in instructions]
    assert "CMD" in keywords, "the Dockerfile has no CMD"
    users = [arguments for keyword, arguments in instructions[:keywords.index("CMD")]
             if keyword == "USER"]
    assert users, "no USER before CMD: the container would run as root"
    user = users[-1].split(":")[0]
    assert user not in ("root", "0"), f"the last USER before CMD is {users[-1]!r}"


def test_no_port_is_exposed(instructions):
    assert of(instructions, "EXPOSE") == []


@pytest.fixture(scope="module")
def ignore_patterns():
    if not DOCKERIGNORE.is_file():
        pytest.fail(f"{DOCKERIGNORE} not found; without it the build context carries .venv, "
                    "build/, devel/ and .git into the image")
    return [line.strip() for line in DOCKERIGNORE.read_text().splitlines()
            if line.strip() and not line.startswith("#")]


def ignored(path, patterns):
    """Whether .dockerignore keeps `path` (or a folder above it) out of the context."""
    parts = path.split("/")
    candidates = ["/".join(parts[:n]) for n in range(1, len(parts) + 1)]
    result = False
    for pattern in patterns:
        negate = pattern.startswith("!")
        pattern = pattern.lstrip("!").strip("/")
        if any(fnmatch.fnmatchcase(candidate, pattern) for candidate in candidates):
            result = not negate
    return result


@pytest.mark.parametrize("path", [
    ".git", ".venv/bin/python", "catkin_ws/build", "catkin_ws/devel/setup.bash",
    "simulation_ws/build", "simulation_ws/devel/setup.bash", "output/world02.png",
    "test_results/pytest-unit.xml",
])
def test_dockerignore_keeps_local_state_out(ignore_patterns, path):
    assert ignored(path, ignore_patterns), f"{DOCKERIGNORE} lets {path} into the build context"


@pytest.mark.parametrize("path", [
    "scripts/setup.sh", "requirements.txt", "docker/Dockerfile",
    "catkin_ws/src/motion_plan/scripts/obstacle_avoidance.py",
])
def test_dockerignore_keeps_the_sources_in(ignore_patterns, path):
    assert not ignored(path, ignore_patterns), f"{DOCKERIGNORE} keeps {path} out of the build context"
