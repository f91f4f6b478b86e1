"""The browser view's simulator side (pybullet_gazebo.web) without a browser or ROS: the scene
the page draws (world02's models and colours, m2wr's URDF visuals, a mesh that cannot be
read named as a problem), frames where the engine has things, the observer's costs (nothing
built while no page watches, at most `fps` frames a wall second while one does), and the
server: the hello a page gets, answers to bad messages, view-only pages, 50 pages at once,
a frame handed over without waiting."""
import asyncio
import json
import os
import socket
import threading
import time

import aiohttp
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.specs import (CollisionSpec, LinkSpec, Mesh, ModelSpec,
                                          WorldSpec)
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World
from pybullet_gazebo.ros.testing import wait_until
from pybullet_gazebo.web import site
from pybullet_gazebo.web.frames import FrameBuilder, MAX_HITS, ray_sensors
from pybullet_gazebo.web.live import WebView
from pybullet_gazebo.web.scene import robot_scene, world_scene
from pybullet_gazebo.web.server import WebServer

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture
def world02(m2wr_urdf):
    client = BulletClient(connection_mode=pybullet.DIRECT)
    path = os.path.join(SRC, "my_worlds", "worlds", "world02.world")
    world = World(client, load_world(path, model_path_from_env(
        os.path.join(SRC, "pybullet_gazebo", "models"))), STEP, warn=lambda m: None)
    world.spawn_urdf("m2wr", m2wr_urdf, Pose((0.0, 8.0, 0.1)))
    yield world
    client.disconnect()


def test_world02s_scene_has_its_barriers_grey_and_its_barrels_orange(world02):
    scene = world_scene(world02.spec)
    names = [m["name"] for m in scene["models"]]
    assert sum(n.startswith("jersey_barrier") for n in names) == 22
    barrier = next(m for m in scene["models"] if m["name"].startswith("jersey_barrier"))
    assert barrier["static"] and {s["kind"] for s in barrier["links"][0]["shapes"]} == {"box"}
    assert barrier["links"][0]["shapes"][0]["colour"] == [0.7, 0.7, 0.7, 1.0]
    barrel = next(m for m in scene["models"] if m["name"].startswith("construction_barrel"))
    shape = barrel["links"][0]["shapes"][0]
    assert not barrel["static"] and shape["kind"] == "cylinder" and shape["radius"] == 0.3
    assert shape["colour"][:3] == [1.0, 0.5088, 0.0468]
    assert [m["ground"] for m in scene["models"]].count(True) == 1
    assert scene["problems"] == []
    json.dumps(scene)


def test_m2wrs_scene_comes_from_its_urdf_visuals(m2wr_urdf):
    scene = robot_scene("m2wr", m2wr_urdf)
    assert set(scene["links"]) == {"link_chassis", "link_left_wheel", "link_right_wheel",
                                   "sensor_laser"}
    chassis = scene["links"]["link_chassis"]
    assert [s["kind"] for s in chassis] == ["box", "sphere"]
    wheel = scene["links"]["link_left_wheel"][0]
    assert wheel["kind"] == "cylinder" and wheel["radius"] == 0.1
    assert wheel["colour"] == [0.0, 0.0, 1.0, 1.0]                  # Gazebo/Blue
    assert scene["problems"] == []


def test_a_mesh_that_cannot_be_read_is_named_and_the_rest_drawn():
    spec = WorldSpec("w", "w.world", models=(ModelSpec("thing", links=(LinkSpec(
        "link", collisions=(CollisionSpec("c", Mesh("model://thing/meshes/thing.dae")),)),)),))
    scene = world_scene(spec)
    assert scene["problems"] == ["thing::link: mesh model://thing/meshes/thing.dae could "
                                 "not be read, not drawn"]
    assert scene["models"][0]["links"][0]["shapes"] == []
    broken = robot_scene("r", "<robot")
    assert broken["links"] == {} and "not XML" in broken["problems"][0]


def test_a_frame_has_the_robot_where_the_engine_has_it_and_its_laser_hits(world02):
    robot = world02.robots()[0]
    scans = {}
    for _ in range(200):
        for reading in world02.step():
            if reading.part.KEY == "ray":
                scans["m2wr"] = [(reading.part, reading.data)]
    frame = FrameBuilder(world02).frame([robot], scans)
    state = frame["robots"]["m2wr"]
    pose = world02.model_pose("m2wr")
    assert state["pose"][:2] == pytest.approx(list(pose.position[:2]), abs=1e-4)
    assert {"link_left_wheel", "link_right_wheel", "sensor_laser"} <= set(state["links"])
    hits = frame["hits"]["m2wr"]["points"]
    assert 0 < len(hits) <= 3 * MAX_HITS
    # world02 at (0, 8): the north wall's inner face about 1.2 m to the left of the laser
    assert max(hits[1::3]) == pytest.approx(9.2, abs=0.2)
    assert frame["t"] == pytest.approx(1.0) and not frame["paused"]
    json.dumps(frame)


class _Server:
    """What WebView uses of WebServer."""

    def __init__(self, watchers=0):
        self.watchers = watchers
        self.frames, self.sent = [], []
        self.scene, self.robots, self.paths = {}, {}, {}

    def mesh_url(self, path):
        return "mesh/0/x"

    def publish_frame(self, frame):
        self.frames.append(frame)

    def send(self, message):
        self.sent.append(message)

    def close(self):
        pass


def test_no_frame_is_built_while_no_page_watches_and_at_most_fps_while_one_does(world02, m2wr_urdf):
    server = _Server(watchers=0)
    view = WebView(world02, server, threading.RLock(), lambda: False, fps=10.0)
    try:
        view.add_robot(world02.robots()[0], m2wr_urdf)
        assert server.sent[0]["type"] == "robot" and server.scene["world"]
        for _ in range(100):
            view.after_step(world02.step())
        assert server.frames == []
        assert len(server.paths["m2wr"]) >= 2          # the path is kept all the same
        server.watchers = 1
        start = time.monotonic()
        while time.monotonic() - start < 0.55:
            view.after_step(world02.step())
        assert 5 <= len(server.frames) <= 7            # 10 a wall second at most
    finally:
        view.close()


def test_step_pauses_after_its_sim_time(world02):
    paused = []
    view = WebView(world02, _Server(), threading.RLock(), lambda: bool(paused))
    view.pause = lambda: paused.append(world02.sim_time)
    try:
        view.step()
        while not paused:
            view.after_step(world02.step())
        assert paused == [pytest.approx(0.05)]
    finally:
        view.close()


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def _talk(url, messages, replies):
    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(url) as ws:
            hello = json.loads((await ws.receive()).data)
            for message in messages:
                await ws.send_str(message)
            answers = [json.loads((await ws.receive(timeout=5)).data) for _ in range(replies)]
            return hello, answers


def test_the_server_answers_bad_messages_and_passes_good_ones_on():
    ops = []
    server = WebServer("127.0.0.1", _free_port(), control=ops.append, max_rate=30)
    server.scene = {"world": "w", "models": [], "problems": []}
    server.start()
    try:
        url = "ws://127.0.0.1:%d/ws" % server.port
        hello, answers = asyncio.run(_talk(url, ["not json", '{"op": "explode"}', "[1]",
                                                 '{"op": "pause"}', '{"op": "reset"}'], 3))
        assert hello["type"] == "hello" and hello["scene"]["world"] == "w" and hello["control"]
        assert [a["type"] for a in answers] == ["error"] * 3
        assert "not JSON" in answers[0]["text"] and "unknown message" in answers[1]["text"]
        wait_until(lambda: len(ops) >= 2, 5, "the pause and reset calls", interval=0.05)
        assert ops == ["pause", "reset"]
    finally:
        server.close()


def test_a_view_only_server_refuses_the_buttons():
    server = WebServer("127.0.0.1", _free_port(), control=None)
    server.start()
    try:
        hello, answers = asyncio.run(_talk("ws://127.0.0.1:%d/ws" % server.port,
                                           ['{"op": "pause"}'], 1))
        assert not hello["control"] and "view-only" in answers[0]["text"]
    finally:
        server.close()


def test_fifty_pages_get_frames_and_a_frame_never_waits_for_them():
    server = WebServer("127.0.0.1", _free_port(), max_rate=1000)
    server.start()
    url = "ws://127.0.0.1:%d/ws" % server.port
    got = []

    async def pages():
        async with aiohttp.ClientSession() as session:
            sockets = [await session.ws_connect(url) for _ in range(50)]
            for ws in sockets:
                await ws.receive()                  # hello
            while server.watchers < 50:
                await asyncio.sleep(0.01)
            # the server's loop is held for 1 s (a page that is slow to take its frames):
            # the simulator's publish hands the frame over and goes on all the same
            held = threading.Event()
            server._loop.call_soon_threadsafe(lambda: (held.set(), time.sleep(1.0)))
            held.wait(5)
            worst = 0.0
            for k in range(5):
                start = time.perf_counter()
                server.publish_frame({"type": "frame", "t": k})
                worst = max(worst, time.perf_counter() - start)
            for ws in sockets:
                got.append(json.loads((await ws.receive(timeout=5)).data)["type"])
                await ws.close()
            return worst
    try:
        worst = asyncio.run(pages())
        assert got == ["frame"] * 50
        assert worst < 0.5          # [s]: handed over, never sent inline (the loop was held 1 s)
        # closed pages are forgotten
        wait_until(lambda: server.watchers == 0, 5, "no page watching", interval=0.05)
    finally:
        server.close()


def test_the_server_says_when_its_port_is_taken():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        server = WebServer("127.0.0.1", taken.getsockname()[1])
        with pytest.raises(OSError):
            server.start()


def test_a_replay_folder_holds_everything_its_page_needs(tmp_path):
    page = site.write_replay(str(tmp_path), "run", {"title": "a <run>", "scene": {},
                                                    "robots": {}, "frames": []})
    with open(page) as source:
        text = source.read()
    assert '<script src="run.js"></script>' in text and "<title>a &lt;run&gt;</title>" in text
    for name in list(site.THREE_FILES) + ["viewer.js", "viewer.css"]:
        assert (tmp_path / "web" / name).exists(), name
        assert ('"web/%s"' % name) in text, name
    assert "http" not in text.replace("http-equiv", "")


def test_a_kept_replay_file_makes_the_same_page_as_the_replay_itself(tmp_path):
    """The report copies a run's kept replay JSON into its page unparsed: the same data file
    and page as from the replay, the title read from the text (also when it is not first)."""
    import json
    replay = {"title": 'bug 2 "round" <the pillar>', "scene": {"models": [1, 2]},
              "robots": {}, "frames": [{"t": 0.1, "hits": {}}]}
    kept = tmp_path / "kept.replay.json"
    kept.write_text(json.dumps(replay, separators=(",", ":")))
    site.write_replay(str(tmp_path / "a"), "run", replay)
    site.write_replay_file(str(tmp_path / "b"), "run", str(kept))
    for name in ("run.js", "run.html"):
        assert (tmp_path / "a" / name).read_text() == (tmp_path / "b" / name).read_text()
    assert "<title>bug 2 &quot;round&quot; &lt;the pillar&gt;</title>" in \
        (tmp_path / "b" / "run.html").read_text()
    reordered = tmp_path / "reordered.replay.json"
    reordered.write_text(json.dumps({"frames": [], "title": "late title"}))
    site.write_replay_file(str(tmp_path / "c"), "run", str(reordered))
    assert "<title>late title</title>" in (tmp_path / "c" / "run.html").read_text()


def test_the_web_parameters_and_their_defaults():
    from pybullet_gazebo.ros.params import ParameterError, SimulatorParams
    d = SimulatorParams.from_values({})
    assert (d.web, d.web_host, d.web_port, d.web_control) == (False, "127.0.0.1", 8090, True)
    p = SimulatorParams.from_values({"web": "true", "web_host": "0.0.0.0", "web_port": 9000,
                                     "web_control": "false"})
    assert (p.web, p.web_host, p.web_port, p.web_control) == (True, "0.0.0.0", 9000, False)
    with pytest.raises(ParameterError, match="web_port"):
        SimulatorParams.from_values({"web_port": "eighty"})


def test_the_web_package_imports_without_ros():
    import subprocess
    import sys
    guarded = ("import sys\n"
               "for name in ('rospy', 'genpy', 'roslib', 'std_msgs', 'std_srvs', 'gazebo_msgs'):\n"
               "    sys.modules[name] = None\n"
               "import pybullet_gazebo.web.scene, pybullet_gazebo.web.frames\n"
               "import pybullet_gazebo.web.live, pybullet_gazebo.web.server\n"
               "import pybullet_gazebo.web.site\n"
               "print('ok')\n")
    src = os.path.join(SRC, "pybullet_gazebo", "src")
    result = subprocess.run([sys.executable, "-c", guarded], capture_output=True, text=True,
                            env=dict(os.environ, PYTHONPATH=src), timeout=60)
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stderr
