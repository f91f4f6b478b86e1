"""Which robots touch which models, step by step (the ground excluded), and when each touch
started. The history is bounded: a long run keeps the last MAX_EVENTS events and a count of
all of them."""
from collections import deque
from dataclasses import dataclass
from typing import AbstractSet, Dict, Iterable, List, Tuple

MAX_EVENTS = 10000


@dataclass(frozen=True)
class ContactEvent:
    """The start of a touch between a robot and another model (the ground excluded)."""
    sim_time: float                 # [s]
    robot: str
    other: str


class ContactTracker:
    def __init__(self, max_events=MAX_EVENTS):
        self.events = deque(maxlen=max_events)   # the most recent touch onsets
        self.event_count = 0                     # every onset since the start
        self._touching = set()                   # (robot, other) pairs touching now
        self.changes = 0                         # times the touching pairs changed
        self._client = self._contact_points = None

    def update(self, client, sim_time, robots: Iterable[Tuple[str, int]],
               owner_of: Dict[int, str], grounds: AbstractSet[str]):
        """Reads Bullet's contact points of each (robot name, body) after a step; touches of
        the models named in `grounds` are not counted. Returns the (robot, other model)
        pairs touching now (a set of the tracker's own: read it, do not change it)."""
        if client is not self._client:       # bound once: called after every physics step
            self._client, self._contact_points = client, client.getContactPoints
        touching = set()
        for name, body in robots:
            for point in self._contact_points(bodyA=body):
                owner = owner_of.get(point[2])
                if owner is None or owner == name or owner in grounds:
                    continue
                touching.add((name, owner))
        if touching:                             # (the usual case, no touch, costs nothing)
            for pair in sorted(touching - self._touching):
                self.events.append(ContactEvent(sim_time, *pair))
                self.event_count += 1
        if touching != self._touching:
            self.changes += 1
        self._touching = touching
        return touching

    def any_touching(self) -> bool:
        """True when a robot touched a model (the ground excluded) at the last update."""
        return bool(self._touching)

    def touching(self) -> List[Tuple[str, str]]:
        return sorted(self._touching)

    def forget(self, name=None):
        """Drops the current touches (of one model, or all)."""
        self._touching = {pair for pair in self._touching if name is not None and name not in pair}
