"""What a graded controller may use, and the findings that fail its run.

By default a controller may use what the real robot has: /cmd_vel, /odom,
/m2wr/laser/scan, TF, /clock, parameters, and services among its own nodes. Every other
use of the simulator's own interface (Gazebo's `/gazebo/*` services and topics) is a finding:
  - a call of a /gazebo/* service (the simulator logs each request's caller id and sim time:
    pybullet_gazebo.ros.call_log),
  - a subscription to a /gazebo/* topic (ground truth: model_states, link_states, contacts)
    or a publication on one (set_model_state as a topic): the simulator logs each node that
    connects to one of its own /gazebo/* topics, and the master lists the rest.
Always allowed (a note, not a failure): spawning a model named m2wr, which the simulator
refuses because m2wr is already there (the series' launch files may include spawn.launch).
A task adds permissions with `allow:` (PERMISSIONS). A finding that nothing allows fails the
run with "rules: <what>, by <node>, at <sim time> s".
"""
import math

GAZEBO = "/gazebo/"
ROBOT = "m2wr"
START_RADIUS = 0.1            # [m] set_model_state counts as "to the start" within this
SPAWN_SERVICES = ("/gazebo/spawn_urdf_model", "/gazebo/spawn_sdf_model")

PERMISSIONS = {
    "set_model_state_to_start": "call /gazebo/set_model_state to put m2wr at this run's "
                                "start (within %.1f m), as the series' bug programs place "
                                "the robot" % START_RADIUS,
}


def service_findings(calls, allow, start, ignore=()):
    """Findings of the call log's entries (dicts of pybullet_gazebo.ros.call_log) made by
    nodes other than `ignore`; `start` is the run's (x, y, yaw)."""
    found = []
    for call in calls:
        if "service" not in call or call.get("caller") in ignore:
            continue
        finding = {"what": "called %s" % call["service"], "node": call.get("caller", "?"),
                   "sim_time": call.get("sim_time")}
        model = call.get("model")
        if model is not None:
            finding["what"] += " for %s at (%.2f, %.2f)" % (model, call.get("x", math.nan),
                                                            call.get("y", math.nan))
        finding["allowed"], finding["why"] = _call_allowed(call, allow, start)
        found.append(finding)
    return found


def _call_allowed(call, allow, start):
    service, model = call["service"], call.get("model")
    if service in SPAWN_SERVICES and model == ROBOT:
        return True, "spawning m2wr again is refused by the simulator (it is there already)"
    if service == "/gazebo/set_model_state" and "set_model_state_to_start" in allow:
        if model == ROBOT and math.hypot(call.get("x", math.inf) - start[0],
                                         call.get("y", math.inf) - start[1]) <= START_RADIUS:
            return True, "to the run's start, as the task allows"
        return False, "the task allows set_model_state only for m2wr to its start (%.2f, %.2f)" \
            % (start[0], start[1])
    return False, "not allowed by this task"


def graph_findings(system_state, ignore=()):
    """{(kind, topic, node)} of the master's getSystemState [publishers, subscribers,
    services]: every subscription to, or publication on, a /gazebo/* topic by a node other
    than `ignore` (kind "subscribed to" or "published on")."""
    publishers, subscribers, _ = system_state
    found = set()
    for kind, listing in (("subscribed to", subscribers), ("published on", publishers)):
        for topic, nodes in listing:
            if topic.startswith(GAZEBO):
                found.update((kind, topic, n) for n in nodes if n not in ignore)
    return found


def logged_topic_users(entries, ignore=()):
    """[(kind, topic, node, sim_time)] of the call log's topic entries (a node that
    connected to one of the simulator's /gazebo/* topics) by nodes other than `ignore`."""
    found = []
    for entry in entries:
        for role, kind in (("subscriber", "subscribed to"), ("publisher", "published on")):
            if "topic" in entry and role in entry and entry[role] not in ignore:
                found.append((kind, entry["topic"], entry[role], entry.get("sim_time")))
    return found


def topic_finding(kind, topic, node, sim_time):
    return {"what": "%s %s" % (kind, topic), "node": node, "sim_time": sim_time,
            "allowed": False, "why": "ground truth is not on the real robot"}


def describe(finding):
    when = finding.get("sim_time")
    return "%s, by %s, at %s" % (finding["what"], finding["node"],
                                 "%.2f s" % when if when is not None else "an unknown time")


def verdict(findings):
    """None when every finding is allowed; else the run's failure reason."""
    broken = [f for f in findings if not f["allowed"]]
    if not broken:
        return None
    first = sorted(broken, key=lambda f: (f.get("sim_time") is None, f.get("sim_time") or 0))
    more = " (and %d more)" % (len(broken) - 1) if len(broken) > 1 else ""
    return "rules: %s%s" % (describe(first[0]), more)
