"""The xacro shim: $(find xacro)/xacro and $(find xacro)/xacro.py, run as roslaunch's
command= runs them (as executables, by path), print what the venv's xacro 1.13 prints for
the robot's description; xacro.py adds 1.13's deprecation note on stderr only."""
import os
import subprocess
import sys

import pytest

SRC = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
SHIM = os.path.join(SRC, "xacro")
ROBOT = os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")


def run(command, cwd):
    return subprocess.run(command, capture_output=True, text=True, timeout=60, cwd=cwd)


@pytest.fixture(scope="module")
def expected():
    result = run([sys.executable, "-c", "import sys, xacro; sys.argv = ['xacro', %r]; xacro.main()"
                  % ROBOT], cwd="/")
    assert result.returncode == 0, result.stderr
    assert "<robot" in result.stdout and "link_chassis" in result.stdout
    return result.stdout


@pytest.mark.parametrize("script", ["xacro", "xacro.py"])
def test_shim_prints_what_xacro_prints(script, expected, tmp_path):
    path = os.path.join(SHIM, script)
    assert os.access(path, os.X_OK), "%s must be executable for command=" % path
    # run from the shim's own folder too: its xacro.py must not shadow the xacro module
    for cwd in (str(tmp_path), SHIM):
        result = run([path, ROBOT], cwd=cwd)
        assert result.returncode == 0, result.stderr
        assert result.stdout == expected


def test_xacro_py_says_it_is_deprecated_on_stderr():
    result = run([os.path.join(SHIM, "xacro.py"), ROBOT], cwd="/")
    assert result.stderr.strip().endswith("xacro.py is deprecated; please use xacro instead")
    assert "deprecated" not in run([os.path.join(SHIM, "xacro"), ROBOT], cwd="/").stderr


def test_shebang_finds_the_python_that_has_xacro():
    # `#!/usr/bin/env python3` must resolve to a python that imports xacro (the venv's,
    # first on PATH after scripts/env.sh), as under roslaunch
    with open(os.path.join(SHIM, "xacro.py")) as script:
        assert script.readline().strip() == "#!/usr/bin/env python3"
    result = run(["/usr/bin/env", "python3", "-c", "import xacro, rospy"], cwd="/")
    assert result.returncode == 0, result.stderr


def test_missing_file_fails_with_xacro_s_error():
    result = run([os.path.join(SHIM, "xacro.py"), "/nonexistent.xacro"], cwd="/")
    assert result.returncode != 0
    assert "nonexistent.xacro" in result.stderr
