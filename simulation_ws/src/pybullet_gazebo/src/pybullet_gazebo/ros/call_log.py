"""Who calls the simulator's Gazebo services: with the global parameter `/gazebo/call_log`
set to a file path before the simulator starts, every request to one of its services is
appended to that file as one JSON line, before it is answered:
  {"service": "/gazebo/set_model_state", "caller": "/bug2", "sim_time": 3.25,
   "model": "m2wr", "x": 0.0, "y": 8.0}
`caller` is the calling node's name from the request's connection header (rospy's
`_connection_header`, the `callerid` the client sent), `sim_time` [s] the world's time then;
`model`, `x`, `y` [m] only for requests that carry a model state (set_model_state) or a
model name and pose (spawn_*_model). The users of the simulator's own /gazebo/* topics go
into the same file, each node once a topic, when it connects (a subscriber of model_states,
link_states, contacts) or sends its first message (a publisher on set_model_state):
  {"topic": "/gazebo/model_states", "subscriber": "/dan", "sim_time": 0.0}
  {"topic": "/gazebo/set_model_state", "publisher": "/eve", "sim_time": 4.5}
so a reader of the file needs no look at the master while the world runs. Unset (the
default), nothing is logged and the services and topics are untouched. The batch grader
(scripts/m2wr_tools/grade) reads it to enforce a task's
rules; the file is the simulator's to write, so a node under test cannot rewrite it.

The parameter is read here, once, rather than in params.py's SimulatorParams: it concerns
the services alone, and the node module that reads SimulatorParams is being redesigned.
"""
import json
import threading

import rospy

PARAM = "/gazebo/call_log"


def request_summary(request):
    """{"model", "x", "y"} of a request that names a model and a pose; {} otherwise."""
    state = getattr(request, "model_state", None)
    if state is not None:
        return {"model": state.model_name, "x": state.pose.position.x,
                "y": state.pose.position.y}
    pose = getattr(request, "initial_pose", None)
    if pose is not None:
        return {"model": request.model_name, "x": pose.position.x, "y": pose.position.y}
    return {}


class CallLog:
    """Appends one JSON line a service request (or topic user) to `path`; `stamp()` gives
    the sim time."""

    def __init__(self, path, stamp):
        self.path = path
        self.stamp = stamp
        self._lock = threading.Lock()
        self._users = set()             # (topic, "subscriber" | "publisher", node) logged

    def _append(self, entry):
        with self._lock, open(self.path, "a") as out:
            out.write(json.dumps(entry) + "\n")

    def _user(self, topic, role, node):
        """Logs `node` as a `role` of `topic`, the first time only."""
        with self._lock:
            if (topic, role, node) in self._users:
                return
            self._users.add((topic, role, node))
        self._append({"topic": topic, role: node,
                      "sim_time": round(self.stamp().to_sec(), 3)})

    def watch_publisher(self, impl):
        """Logs each node that subscribes to the topic of `impl` (rospy's _PublisherImpl),
        those connected already at once."""
        log, topic = self, impl.resolved_name

        class Subscribers(rospy.SubscribeListener):
            def peer_subscribe(self, topic_name, topic_publish, peer_publish):
                for connection in list(impl.connections):
                    log._user(topic, "subscriber", connection.endpoint_id)
        impl.add_subscriber_listener(Subscribers())
        for connection in list(impl.connections):
            self._user(topic, "subscriber", connection.endpoint_id)

    def watch_subscriber(self, impl):
        """Logs each node that publishes on the topic of `impl` (rospy's _SubscriberImpl),
        at its first message."""
        def heard(msg, topic):
            header = getattr(msg, "_connection_header", None) or {}
            self._user(topic, "publisher", header.get("callerid", "?"))
        impl.add_callback(heard, impl.resolved_name)

    def wrap(self, service):
        """Makes the rospy.Service `service` log each request before its handler answers."""
        handler, name = service.handler, service.resolved_name

        def logged(request):
            header = getattr(request, "_connection_header", None) or {}
            entry = {"service": name, "caller": header.get("callerid", "?"),
                     "sim_time": round(self.stamp().to_sec(), 3)}
            entry.update(request_summary(request))
            self._append(entry)
            return handler(request)
        service.handler = logged


def log_callers(services, stamp, prefix="/gazebo/"):
    """Wraps every rospy.Service of `services`, and watches every topic under `prefix` this
    node publishes or subscribes to, when PARAM names a file; returns the CallLog or None."""
    path = rospy.get_param(PARAM, "")
    if not path:
        return None
    log = CallLog(path, stamp)
    for service in services:
        log.wrap(service)
    from rospy.impl.registration import get_topic_manager
    topics = get_topic_manager()
    for topic, _ in topics.get_publications():
        if topic.startswith(prefix):
            log.watch_publisher(topics.get_publisher_impl(topic))
    for topic, _ in topics.get_subscriptions():
        if topic.startswith(prefix):
            log.watch_subscriber(topics.get_subscriber_impl(topic))
    rospy.loginfo("logging the callers of the Gazebo services to %s (%s)", path, PARAM)
    return log
