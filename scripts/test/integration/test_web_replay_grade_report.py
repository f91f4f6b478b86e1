"""A grader's student page embeds each run's replay (the browser view), and the report opens
from file:// in Debian's chromium (Playwright) with no network: the replay's page loads
inside the student page with no console error and shows m2wr where the run's track ends.
The run's replay is made as the batch runner makes it (m2wr_tools.analysis.replays.build on the
offline scene), from a track written here (m2wr along world02's north corridor), so no
simulation runs."""
import json
import math
import re

import pytest

from m2wr_tools import paths
from m2wr_tools.analysis import replays
from m2wr_tools.grade import report
from m2wr_tools.grade.spec import load
from m2wr_tools.analysis.scene import Scene

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--headless", "--use-gl=angle", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
SPEC = """\
version: 1
tasks:
  - name: avoid
    command: rosrun motion_plan obstacle_avoidance.py
    kind: wander
    points: 10
"""
ROBOT = re.compile(r"m2wr x\s*(-?\d+\.\d+) y\s*(-?\d+\.\d+)")


class _Sub:
    problem, packages, scripts = None, (("motion_plan", "/x"),), ()


def _track():
    """(t, x, y, z, qx, qy, qz, qw) rows: 0.3 m/s east from (0, 8), turning gently right."""
    rows = []
    x, y, yaw = 0.0, 8.0, 0.0
    for k in range(301):
        t = 0.05 * k
        rows.append((t, x, y, 0.1, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
        x, y, yaw = x + 0.015 * math.cos(yaw), y + 0.015 * math.sin(yaw), yaw - 0.002
    return rows


@pytest.fixture
def site(tmp_path):
    urdf = paths.robot_urdf()
    scene = Scene.of_world("world02", urdf)
    track = _track()
    try:
        replay = replays.build(scene, urdf, track, "world02: obstacle_avoidance.py from (0, 8)")
    finally:
        scene.close()
    replay_path = tmp_path / "abe.replay.json"
    replay_path.write_text(json.dumps(replay))
    spec_path = tmp_path / "spec.yaml"
    spec_path.write_text(SPEC)
    log = tmp_path / "controller.log"
    log.write_text("[INFO] started\n")
    record = {"run_id": "abe__avoid__0_00000000", "student": "abe", "task": "avoid",
              "index": 0, "x": 0.0, "y": 8.0, "yaw": 0.0, "seed": 0, "success": True,
              "reason": "no contact", "distance_m": 4.5, "min_clearance_m": 0.6,
              "contact_events": 0, "controller_log": str(log), "findings": [],
              "path": [[r[0], r[1], r[2]] for r in track[::10]], "replay": str(replay_path)}
    report.write(str(tmp_path / "out"), load(str(spec_path)),
                 {"abe": {"submission": _Sub(), "records": [record]}})
    return tmp_path / "out", track[-1]


def test_a_students_page_embeds_its_runs_replay(site):
    sync_api = pytest.importorskip("playwright.sync_api")
    out, last = site
    assert (out / "runs" / "web" / "three.min.js").exists()
    errors = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1100, "height": 700})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto("file://%s" % (out / "students" / "abe.html"))
            frame = page.frame_locator("iframe.replay")
            frame.locator("#status").wait_for()
            inner = next(f for f in page.frames if f.url.endswith("abe__avoid__0_00000000.html"))
            inner.wait_for_function("() => window.m2wrReplay !== undefined", timeout=20000)
            inner.evaluate("() => window.m2wrReplay.seek(window.m2wrReplay.end)")
            x, y = map(float, ROBOT.search(inner.inner_text("#status")).groups())
            assert abs(x - last[1]) < 0.01 and abs(y - last[2]) < 0.01, (x, y, last)
            assert inner.inner_text("#problems") == ""
        finally:
            browser.close()
    assert errors == []
