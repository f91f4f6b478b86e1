"""The suite's closing lines: a failed case shows its reason, not only its name (CI keeps only
the end of the output)."""
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "summarize_test_results.py"

RESULT = """<testsuite name="bug2" tests="2" failures="1" errors="0">
<testcase classname="Bug2Test" name="test_reaches_the_goal">
<failure type="AssertionError">Traceback (most recent call last):
  File "test_bug2.py", line 98, in test_reaches_the_goal
    self.assertIsNotNone(self.reached, summary)
AssertionError: unexpectedly None : goal (0.0, -3.0): nearest 0.912 m, not reached in 300 s</failure>
</testcase>
<testcase classname="Bug2Test" name="test_other"/>
</testsuite>"""


def summarize(folder, name, xml):
    """The script run on a folder holding one result file `name` with `xml` in it."""
    (folder / name).write_text(xml)
    return subprocess.run([sys.executable, str(SCRIPT), str(folder)], capture_output=True,
                          text=True)


def test_a_failure_is_printed_with_its_reason(tmp_path):
    run = summarize(tmp_path, "rosunit-bug2.xml", RESULT)
    assert run.returncode == 1
    lines = run.stdout.splitlines()
    assert lines[0] == "FAILED: Bug2Test.test_reaches_the_goal (rosunit-bug2.xml)"
    assert "nearest 0.912 m, not reached in 300 s" in run.stdout
    assert lines[-1] == "1 passed, 1 failed, 0 skipped"


# rosunit's own layout (what rostest's Python tests write): the assertion's message first,
# then the traceback without the exception line
ROSUNIT_RESULT = """<testsuite errors="0" failures="1" name="unittest.suite.TestSuite" tests="1">
<testcase classname="__main__.RvizRobotModelTest" name="test_rviz_starts">
<failure type="AssertionError">[] is not true : rviz_probe.py printed no report (exit 1); stdout:
line 1 of the probe's output
line 2
line 3
line 4
line 5
stderr:
ImportError: the last line of the probe's error
  File "/usr/lib/python3.11/unittest/case.py", line 57, in testPartExecutor
    yield
  File "/tmp/test_rviz_robot_model.py", line 65, in test_rviz_starts
    self.assertTrue(lines, "rviz_probe.py printed no report (exit %s); stdout:"
</failure></testcase>
</testsuite>"""


def test_a_rosunit_failure_shows_its_message_not_its_traceback(tmp_path):
    run = summarize(tmp_path, "rosunit-rviz.xml", ROSUNIT_RESULT)
    assert run.returncode == 1
    assert "rviz_probe.py printed no report (exit 1)" in run.stdout
    assert "ImportError: the last line of the probe's error" in run.stdout
    assert "testPartExecutor" not in run.stdout
