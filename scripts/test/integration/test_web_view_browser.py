"""The live page (web:=true) in a real browser: Debian's chromium, headless, driven by
Playwright (executable_path; `playwright install` is never run). world02 at real time with
m2wr driving: the page loads with no console error, its status line's pose of m2wr agrees
with /gazebo/model_states within 0.05 m, its Pause button stops sim time and a
/gazebo/pause_physics from a terminal shows as paused; malformed messages from a page are
answered and change nothing. A screenshot goes to docs/web_world02.png when
M2WR_SCREENSHOTS=1."""
import json
import os
import re
import subprocess
import sys
import time

import pytest

from m2wr_tools.running import processes
from m2wr_tools.paths import ROOT
from m2wr_tools.running.session import Session
from pybullet_gazebo.ros.testing import wait_until

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--headless", "--use-gl=angle", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
PROBE = os.path.join(os.path.dirname(__file__), "web_probe_node.py")
STATUS = re.compile(r"sim (\d+\.\d+) s .*?(paused|running)")
ROBOT = re.compile(r"m2wr x\s*(-?\d+\.\d+) y\s*(-?\d+\.\d+) yaw\s*(-?\d+\.\d+)")


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    logs = tmp_path_factory.mktemp("web_view")
    session = Session(str(logs / "logs"), name="test_web_view")
    port = processes.free_port()
    probe = None
    saved = {k: os.environ.get(k) for k in ("ROS_MASTER_URI", "ROS_HOSTNAME")}
    try:
        session.start_master()
        session.join()
        session.launch_world("world02", real_time_factor=1.0, lockstep=False,
                             extra=["web:=true", "web_port:=%d" % port])
        session.wait_for_simulator()
        session.spawn(0.0, 8.0, 0.0)
        states = str(logs / "states.jsonl")
        probe = subprocess.Popen([sys.executable, PROBE, states, "0.3", "0.1"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT,
                                 start_new_session=True)
        yield {"url": "http://127.0.0.1:%d/" % port, "states": states, "env": dict(os.environ)}
    finally:
        if probe is not None:
            probe.terminate()
            probe.wait(10)
        session.stop_all()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api")
    assert os.path.exists(CHROMIUM), "apt-get install chromium (scripts/setup.sh does)"
    with sync_api.sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        try:
            yield chromium
        finally:
            chromium.close()


def open_page(browser, url):
    page = browser.new_page(viewport={"width": 1200, "height": 760})
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    return page, errors


def status(page):
    text = page.inner_text("#status")
    sim, robot = STATUS.search(text), ROBOT.search(text)
    if not (sim and robot):
        return None
    return float(sim.group(1)), sim.group(2) == "paused", float(robot.group(1)), \
        float(robot.group(2))


def call(service):
    subprocess.run(["rosservice", "call", service], check=True, timeout=30,
                   stdout=subprocess.DEVNULL)


def test_the_status_line_shows_m2wr_where_model_states_has_it(world, browser):
    page, errors = open_page(browser, world["url"])
    try:
        wait_until(lambda: (status(page) or (0, 0, 0, 8))[2] > 0.2, 30, "m2wr driving on the page")
        for _ in range(5):
            t, _, x, y = status(page)
            with open(world["states"]) as lines:
                states = [json.loads(line) for line in lines if line.strip()]
            assert states, "no /gazebo/model_states heard"
            nearest = min(states, key=lambda s: abs(s[0] - t))
            assert abs(nearest[0] - t) < 0.05, (t, nearest)
            assert abs(nearest[1] - x) < 0.05 and abs(nearest[2] - y) < 0.05, \
                ("page", t, x, y, "model_states", nearest)
            time.sleep(0.5)
        assert page.inner_text("#problems") == ""
        if os.environ.get("M2WR_SCREENSHOTS"):
            page.screenshot(path=os.path.join(ROOT, "docs", "web_world02.png"))
        assert errors == []
    finally:
        page.close()


def test_pause_stops_sim_time_and_a_terminals_pause_shows(world, browser):
    page, errors = open_page(browser, world["url"])
    try:
        wait_until(lambda: status(page), 30, "the status line")
        page.click("#pause")
        wait_until(lambda: status(page)[1], 10, "the page showing paused after Pause")
        before = status(page)[0]
        time.sleep(1.5)
        assert status(page)[0] == before, "sim time went on while paused"
        assert page.inner_text("#pause") == "Play"
        page.click("#pause")
        wait_until(lambda: not status(page)[1] and status(page)[0] > before, 10,
                   "sim time going on after Play")
        call("/gazebo/pause_physics")
        wait_until(lambda: status(page)[1], 10, "a terminal's pause_physics shown as paused")
        call("/gazebo/unpause_physics")
        wait_until(lambda: not status(page)[1], 10, "a terminal's unpause_physics shown")
        assert errors == []
    finally:
        page.close()


def test_bad_messages_are_answered_and_the_simulation_goes_on(world, browser):
    page, errors = open_page(browser, world["url"])
    try:
        wait_until(lambda: status(page), 30, "the status line")
        page.evaluate("""() => {
            const ws = new WebSocket('ws://' + location.host + '/ws');
            ws.onopen = () => { ws.send('not json'); ws.send('{"op": "explode"}');
                                ws.send('[1, 2]'); ws.send('x'.repeat(100000)); };
        }""")
        before = status(page)[0]
        wait_until(lambda: status(page)[0] > before + 1.0, 10, "sim time going on")
        assert not status(page)[1]
        assert errors == []
    finally:
        page.close()
