"""The demo's replay in a real browser (Debian's chromium through Playwright): scripts/demo.sh
writes <output>/demo_world02_replay.html; opened from file:// with no server, it loads with
no console error, and at the end of its time slider m2wr stands where the simulator had it
when the run ended (the summary's `end`, from /gazebo/get_model_state at the pause) within
0.05 m."""
import json
import os
import re
import subprocess

import pytest

from m2wr_tools.paths import ROOT

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--headless", "--use-gl=angle", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
ROBOT = re.compile(r"m2wr x\s*(-?\d+\.\d+) y\s*(-?\d+\.\d+) yaw\s*(-?\d+\.\d+)")


def test_the_demos_replay_ends_where_the_run_ended(tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api")
    done = subprocess.run(["bash", os.path.join(ROOT, "scripts", "demo.sh"), "--duration", "15",
                           "--output", str(tmp_path)], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=300,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout[-3000:]
    with open(tmp_path / "demo_world02.json") as source:
        summary = json.load(source)
    page_path = tmp_path / "demo_world02_replay.html"
    assert summary["replay"] == str(page_path) and page_path.exists()
    assert (tmp_path / "web" / "three.min.js").exists()
    errors = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto("file://%s" % page_path)
            page.wait_for_function("() => window.m2wrReplay !== undefined", timeout=20000)
            page.evaluate("() => window.m2wrReplay.seek(window.m2wrReplay.end)")
            x, y, _ = map(float, ROBOT.search(page.inner_text("#status")).groups())
            assert abs(x - summary["end"]["x"]) < 0.05 and abs(y - summary["end"]["y"]) < 0.05, \
                (x, y, summary["end"])
            assert page.inner_text("#problems") == ""
        finally:
            browser.close()
    assert errors == []
