"""The batch runner puts the parameter server back after each run: what a run's launch file
added is deleted, what it changed or deleted is set back (no ROS master: a dict stands in)."""
from m2wr_tools.running.param_snapshot import ParamSnapshot, leaves


class FakeServer:
    def __init__(self, tree):
        self.tree = tree

    def _parent(self, name, make=False):
        parts = name.strip("/").split("/")
        node = self.tree
        for part in parts[:-1]:
            node = node.setdefault(part, {}) if make else node[part]
        return node, parts[-1]

    def get(self, name):
        assert name == "/"
        return self.tree

    def put(self, name, value):
        parent, key = self._parent(name, make=True)
        parent[key] = value

    def delete(self, name):
        parent, key = self._parent(name)
        del parent[key]


def test_what_a_run_added_goes_and_what_it_changed_comes_back():
    server = FakeServer({"robot_description": "<robot/>", "use_sim_time": True,
                         "gazebo": {"call_log": "/tmp/calls.jsonl"}})
    snapshot = ParamSnapshot(server.get, server.put, server.delete)
    snapshot.take()
    # what a run does: the rig's goal, a bug 2 launch's private params, a student's changes
    server.put("/des_pos_x", 2.0)
    server.put("/go_to_point/turn_sign", -1)
    server.put("/follow_wall/turn_sign", -1)
    server.put("/use_sim_time", False)
    server.delete("/gazebo/call_log")
    touched = snapshot.restore()
    assert leaves(server.tree) == {"/robot_description": "<robot/>", "/use_sim_time": True,
                                   "/gazebo/call_log": "/tmp/calls.jsonl"}
    assert "/go_to_point/turn_sign" in touched and "/use_sim_time" in touched
    assert snapshot.restore() == []            # once per snapshot
