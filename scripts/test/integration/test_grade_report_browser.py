"""The grader's report in a real browser: Debian's chromium, headless, driven by Playwright
for Python (the system browser through executable_path; `playwright install` is never run).
A report of three students (records written here, no simulation) opens, its class table
sorts by every column, gives one short reason a failed task (the full text in its
tooltip) under a header naming the turning convention, a student's page opens from it, every picture has loaded, the console
has no error, and a screenshot is saved."""
import os

import pytest

from m2wr_tools.grade import report
from m2wr_tools.grade.spec import load

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--headless", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
SPEC = """\
version: 1
tasks:
  - name: avoid
    command: rosrun motion_plan obstacle_avoidance.py
    kind: wander
    points: 10
  - name: goal
    command: rosrun motion_plan go_to_point.py
    kind: goal
    goal: [2, 8]
    points: 10
"""


class _Sub:
    problem, packages, scripts = None, (("motion_plan", "/x"),), ()


def _record(student, task, success, reason, log):
    return {"run_id": "%s__%s__0_00000000" % (student, task), "student": student,
            "task": task, "index": 0, "x": 0.0, "y": 8.0, "yaw": 0.0, "seed": 0,
            "success": success, "reason": reason, "distance_m": 3.2, "min_clearance_m": 0.6,
            "contact_events": 0, "controller_log": log, "findings": [],
            "path": [[0, 0.0, 8.0], [1, 1.0, 8.2], [2, 2.0, 8.0]]}


@pytest.fixture
def site(tmp_path):
    log = tmp_path / "controller.log"
    log.write_text("[INFO] started\n")
    spec_path = tmp_path / "spec.yaml"
    spec_path.write_text(SPEC)
    spec = load(str(spec_path))
    graded = {}
    for student, avoid, goal in (("cat", True, False), ("abe", True, True),
                                 ("bea", False, False)):
        graded[student] = {"submission": _Sub(), "records": [
            _record(student, "avoid", avoid, "no contact" if avoid else "touched", str(log)),
            _record(student, "goal", goal, "reached" if goal else "rules: called "
                    "/gazebo/set_model_state for m2wr at (2.00, 8.00), by /g, at 0.00 s",
                    str(log))]}
    report.write(str(tmp_path / "out"), spec, graded)
    return tmp_path / "out"


def test_the_class_table_sorts_and_a_students_page_shows_its_runs(site, tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api")
    assert os.path.exists(CHROMIUM), "apt-get install chromium (scripts/setup.sh does)"
    errors = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        try:
            page = browser.new_page()
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto("file://%s" % (site / "index.html"))
            students = lambda: page.eval_on_selector_all(  # noqa: E731
                "#grades tbody tr td:first-child", "cells => cells.map(c => c.textContent)")
            totals = lambda: page.eval_on_selector_all(  # noqa: E731
                "#grades tbody tr td:nth-child(4)", "cells => cells.map(c => c.textContent)")
            assert students() == ["abe", "bea", "cat"]
            page.click("#grades th:nth-child(4)")            # total, ascending
            assert totals() == ["0.00", "10.00", "20.00"] and students() == ["bea", "cat", "abe"]
            page.click("#grades th:nth-child(4)")            # again: descending
            assert students() == ["abe", "cat", "bea"]
            for column in range(1, 7):                       # every column sorts
                page.click("#grades th:nth-child(%d)" % column)
                assert sorted(students()) == ["abe", "bea", "cat"]
            page.click("#grades th:nth-child(1)")
            if students() != ["abe", "bea", "cat"]:
                page.click("#grades th:nth-child(1)")
            assert students() == ["abe", "bea", "cat"]
            # one short line per failed task, the whole reason in its tooltip; the header
            # names the spec and the turning convention
            reasons = page.eval_on_selector_all(
                "#grades tbody tr:nth-child(2) td:last-child div",
                "lines => lines.map(l => [l.textContent, l.title])")
            assert reasons == [["avoid: touched", "touched"],
                               ["goal: rules: called /gazebo/set_model_state for m2wr at "
                                "(2.00\u2026", "rules: called /gazebo/set_model_state "
                                "for m2wr at (2.00, 8.00), by /g, at 0.00 s"]]
            assert "Turning: legacy_mode false" in page.inner_text("body")
            page.set_viewport_size({"width": 1280, "height": 800})
            page.screenshot(path=str(tmp_path / "class_table.png"))
            page.click("text=cat")
            page.wait_for_load_state("load")
            assert page.url.endswith("students/cat.html")
            assert "rules: called /gazebo/set_model_state" in page.content()
            images = page.eval_on_selector_all(
                "img", "imgs => imgs.map(i => [i.complete, i.naturalWidth])")
            assert len(images) == 2 and all(done and width > 0 for done, width in images)
            page.screenshot(path=str(tmp_path / "student_page.png"), full_page=True)
        finally:
            browser.close()
    assert errors == []
    assert (tmp_path / "student_page.png").stat().st_size > 1000
    assert (tmp_path / "class_table.png").stat().st_size > 1000
