"""Process ids of ROS nodes on this machine, for lockstep's barrier (idle_threads.py).

A node's id comes from the master (lookupNode: its XML-RPC address) and then the node itself
(the slave API's getPid), once per node name; a node on another machine has none that this
machine could watch, and is left out (say so: lockstep then cannot wait for it). The answer
is asked again when the process it named has ended (a node restarted under the same name).
"""
import os
import socket
import time
from urllib.parse import urlparse
from xmlrpc.client import ServerProxy, Transport

import rosgraph

RETRY_AFTER = 1.0        # [s] wall: a node whose id could not be had is asked again after this
ASK_TIMEOUT = 2.0        # [s] wall: a node that does not answer getPid within this is skipped


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
        self._pids = {}                 # node name -> pid
        self._unknown = {}              # node name -> monotonic time of the failed ask
        self.remote = set()             # nodes on other machines (or unanswering): not watched

    def pids(self, names):
        """The local process ids of the nodes `names` (those that could be found)."""
        found = set()
        for name in names:
            pid = self._pids.get(name)
            if pid is not None and not os.path.isdir("/proc/%d" % pid):
                del self._pids[name]                 # ended: ask again
                pid = None
            if pid is None:
                pid = self._ask(name)
            if pid is not None:
                found.add(pid)
        if len(self._pids) > 2 * len(names) + 16:      # anonymous nodes come and go
            names = set(names)
            self._pids = {n: p for n, p in self._pids.items() if n in names}
        return found

    def forget(self):
        """Every id found so far is asked again when next wanted."""
        self._pids.clear()
        self._unknown.clear()
        self.remote.clear()

    def names_of(self, pid):
        """The node names found for process `pid`."""
        return sorted(n for n, p in self._pids.items() if p == pid)

    def pid_of(self, name):
        """The process id found for node `name`, or "not found"."""
        return self._pids.get(name, "on another machine" if name in self.remote else "unknown")

    def _ask(self, name):
        failed_at = self._unknown.get(name)
        if failed_at is not None and time.monotonic() - failed_at < RETRY_AFTER:
            return None
        try:
            uri = self._lookup(name)
            if urlparse(uri).hostname not in self._local:
                self.remote.add(name)
                self._unknown[name] = time.monotonic()
                return None
            pid = int(self._get_pid(uri))
        except Exception:                   # noqa: BLE001 (any failure: the node is gone)
            self._unknown[name] = time.monotonic()
            return None
        self._unknown.pop(name, None)
        self._pids[name] = pid
        return pid

    def _lookup_uri(self, name):
        return rosgraph.Master(self.caller_id).lookupNode(name)

    def _pid_from_node(self, uri):
        code, _, pid = ServerProxy(uri, transport=_TimeoutTransport()).getPid(self.caller_id)
        if code != 1:
            raise RuntimeError("getPid failed")
        return pid
