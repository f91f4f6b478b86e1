"""Process ids of ROS nodes on this machine, for lockstep's barrier (idle_threads.py).

A node's id comes from the master (lookupNode: its XML-RPC address) and then the node itself
(the slave API's getPid). The simulator asks for all loop nodes afresh whenever their
connections change (a node restarted under the same name is a new process). A node on
another machine has no id this machine could watch, and is left out (named as such: lockstep
then cannot wait for it); one that does not answer is left out until the next change.

The master is watched beside them (MASTER): a controller's service call or parameter read goes
through it (rospy looks a service up at every call), and while the master works on it the
controller sleeps in a socket wait. Without the master in the watch, lockstep would step on in
that gap, and bug 2 switching go to point on would land at a step the machine chose.
"""
import os
import socket
from urllib.parse import urlparse
from xmlrpc.client import ServerProxy, Transport

import rosgraph

ASK_TIMEOUT = 2.0        # [s] wall: a node that does not answer getPid within this is skipped
MASTER = "the ROS master"    # its name among the nodes found (not a node name: no '/')


class _TimeoutTransport(Transport):
    def make_connection(self, host):
        connection = super().make_connection(host)
        connection.timeout = ASK_TIMEOUT
        return connection


def local_hosts():
    """The names under which a node on this machine may give its address."""
    names = {"localhost", "127.0.0.1", "::1", socket.gethostname()}
    for variable in ("ROS_HOSTNAME", "ROS_IP"):
        if os.environ.get(variable):
            names.add(os.environ[variable])
    return names


class NodeProcesses:
    def __init__(self, caller_id, lookup=None, get_pid=None):
        self.caller_id = caller_id
        self._lookup = lookup or self._lookup_uri
        self._get_pid = get_pid or self._pid_from_node
        self._local = local_hosts()
        self._pids = {}                 # node name -> pid, of the last find()
        self.remote = set()             # nodes on other machines: not watched

    def find(self, names, with_master=True):
        """The local process ids of the nodes `names` (those that could be found), and of the
        master when `names` is not empty and `with_master`, asked afresh; remembered for pid_of
        and names_of."""
        self._pids, self.remote = {}, set()
        for name in names:
            pid = self._ask(name)
            if pid is not None:
                self._pids[name] = pid
        if names and with_master:
            pid = self._ask(MASTER)
            if pid is not None:
                self._pids[MASTER] = pid
        return set(self._pids.values())

    def names_of(self, pid):
        """The node names found for process `pid`."""
        return sorted(n for n, p in self._pids.items() if p == pid)

    def pid_of(self, name):
        """The process id found for node `name`, or why there is none."""
        return self._pids.get(name, "on another machine" if name in self.remote else "unknown")

    def _ask(self, name):
        try:
            uri = self._lookup(name)
            if urlparse(uri).hostname not in self._local:
                self.remote.add(name)
                return None
            return int(self._get_pid(uri))
        except Exception:                   # noqa: BLE001 (any failure: the node is gone)
            return None

    def _lookup_uri(self, name):
        if name == MASTER:
            return rosgraph.get_master_uri()
        return rosgraph.Master(self.caller_id).lookupNode(name)

    def _pid_from_node(self, uri):
        code, _, pid = ServerProxy(uri, transport=_TimeoutTransport()).getPid(self.caller_id)
        if code != 1:
            raise RuntimeError("getPid failed")
        return pid
