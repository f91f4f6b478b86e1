"""Which node offers a service, asked of the ROS master (for board.py: a service call between
two reporting controllers is done with once its server has reported it answered)."""
import time

import rosgraph

RETRY = 1.0          # [s] wall: a service the master did not know is asked again after this


class ServiceProviders:
    def __init__(self, caller_id, system_state=None):
        self._system_state = system_state or rosgraph.Master(caller_id).getSystemState
        self._providers = {}          # service -> node
        self._unknown = {}            # service -> [s] monotonic when the master did not know

    def __call__(self, service):
        node = self._providers.get(service)
        if node is not None:
            return node
        asked = self._unknown.get(service)
        if asked is not None and time.monotonic() - asked < RETRY:
            return None
        try:
            _, _, services = self._system_state()
        except Exception:                   # noqa: BLE001 (master gone: nothing to wait for)
            services = []
        self._providers = {name: nodes[0] for name, nodes in services if nodes}
        node = self._providers.get(service)
        if node is None:
            self._unknown[service] = time.monotonic()
        return node
