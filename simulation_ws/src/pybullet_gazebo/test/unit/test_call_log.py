"""ros.call_log: each request to a wrapped service is logged with its caller, sim time and
(for model states and spawns) the model and position, before the service answers."""
import json
from types import SimpleNamespace

import rospy
from gazebo_msgs.srv import SetModelStateRequest, SpawnModelRequest
from std_srvs.srv import EmptyRequest

from pybullet_gazebo.ros.call_log import CallLog


def _service(name, answer):
    return SimpleNamespace(resolved_name=name, handler=lambda request: answer)


def test_each_request_is_logged_with_its_caller_and_sim_time_then_answered(tmp_path):
    path = tmp_path / "calls.jsonl"
    log = CallLog(str(path), stamp=lambda: rospy.Time(3, 250000000))
    teleport = _service("/gazebo/set_model_state", "moved")
    spawn = _service("/gazebo/spawn_urdf_model", "spawned")
    pause = _service("/gazebo/pause_physics", "paused")
    for service in (teleport, spawn, pause):
        log.wrap(service)
    request = SetModelStateRequest()
    request.model_state.model_name = "m2wr"
    request.model_state.pose.position.x, request.model_state.pose.position.y = 0.0, -4.0
    request._connection_header = {"callerid": "/cheater"}
    assert teleport.handler(request) == "moved"
    again = SpawnModelRequest(model_name="m2wr")
    again.initial_pose.position.y = 8.0
    again._connection_header = {"callerid": "/urdf_spawner"}
    assert spawn.handler(again) == "spawned"
    assert pause.handler(EmptyRequest()) == "paused"        # no header: caller unknown
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert lines == [
        {"service": "/gazebo/set_model_state", "caller": "/cheater", "sim_time": 3.25,
         "model": "m2wr", "x": 0.0, "y": -4.0},
        {"service": "/gazebo/spawn_urdf_model", "caller": "/urdf_spawner", "sim_time": 3.25,
         "model": "m2wr", "x": 0.0, "y": 8.0},
        {"service": "/gazebo/pause_physics", "caller": "?", "sim_time": 3.25},
    ]


class _FakePublisherImpl:
    """What CallLog.watch_publisher uses of rospy's _PublisherImpl."""

    def __init__(self, name, subscribers):
        self.resolved_name = name
        self.connections = [SimpleNamespace(endpoint_id=n) for n in subscribers]
        self.listeners = []

    def add_subscriber_listener(self, listener):
        self.listeners.append(listener)

    def connect(self, node):          # as rospy's add_connection does
        self.connections.append(SimpleNamespace(endpoint_id=node))
        for listener in self.listeners:
            listener.peer_subscribe(self.resolved_name, None, None)


class _FakeSubscriberImpl:
    def __init__(self, name):
        self.resolved_name = name
        self.callbacks = []

    def add_callback(self, callback, argument):
        self.callbacks.append((callback, argument))

    def deliver(self, msg):
        for callback, argument in self.callbacks:
            callback(msg, argument)


def test_each_user_of_a_gazebo_topic_is_logged_once_with_the_sim_time_it_came(tmp_path):
    path = tmp_path / "calls.jsonl"
    now = [rospy.Time(0)]
    log = CallLog(str(path), stamp=lambda: now[0])
    states = _FakePublisherImpl("/gazebo/model_states", ["/rviz"])     # there already
    log.watch_publisher(states)
    teleports = _FakeSubscriberImpl("/gazebo/set_model_state")
    log.watch_subscriber(teleports)
    now[0] = rospy.Time(4, 500000000)
    states.connect("/dan")
    states.connect("/eve")              # each connection lists all: /rviz, /dan not again
    message = SimpleNamespace(_connection_header={"callerid": "/eve"})
    teleports.deliver(message)
    teleports.deliver(message)          # its second message: not logged again
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert lines == [
        {"topic": "/gazebo/model_states", "subscriber": "/rviz", "sim_time": 0.0},
        {"topic": "/gazebo/model_states", "subscriber": "/dan", "sim_time": 4.5},
        {"topic": "/gazebo/model_states", "subscriber": "/eve", "sim_time": 4.5},
        {"topic": "/gazebo/set_model_state", "publisher": "/eve", "sim_time": 4.5},
    ]
