"""The run summary's maths and text, from plain recorded data (no ROS, no pybullet).

Inputs are what the demo records: poses (sim time [s], x [m], y [m]) from /odom, the case
lines obstacle_avoidance.py logs (sim time, text) from /rosout, and the sets of
(robot, model) pairs in contact from /gazebo/contacts (sim time, pairs).
"""
from dataclasses import dataclass, field
import math
import re
from typing import Dict, List, Optional, Sequence, Tuple

# obstacle_avoidance.py's state descriptions: "case 1 - nothing" .. "case 8 - ...", and
# "unknown case" (it logs the regions dict on the line before, which is not a case)
_CASE = re.compile(r"^(case \d+ - .+|unknown case)$")


def is_case(text):
    """True for a state description line of obstacle_avoidance.py."""
    return bool(_CASE.match(text.strip()))


# a rospy log line on a node's stdout with sim time: "[INFO] [<wall s>, <sim s>]: <text>"
_LOG_LINE = re.compile(r"^\[\s*[A-Z]+\s*\]\s*\[\s*[0-9.]+\s*,\s*([0-9.]+)\s*\]:\s?(.*)$")


def case_lines(text):
    """(sim time [s], text) of obstacle_avoidance.py's case lines in a node's output, as
    rospy prints them with sim time (its default format, no ROSCONSOLE_FORMAT)."""
    found = []
    for line in text.splitlines():
        match = _LOG_LINE.match(line)
        if match and is_case(match.group(2)):
            found.append((float(match.group(1)), match.group(2).strip()))
    return found


def _case_order(name):
    match = re.match(r"case (\d+)", name)
    return (0, int(match.group(1)), name) if match else (1, 0, name)


def case_durations(events: Sequence[Tuple[float, str]], start: float, end: float) -> Dict[str, float]:
    """Sim time [s] spent in each case: a case lasts from its line to the next case line
    (the last one to `end`); lines before `start` or after `end` are clipped to [start, end].
    Non-case lines are ignored. Returns {case: seconds} in case-number order."""
    lines = sorted((t, text.strip()) for t, text in events if is_case(text))
    totals = {}
    for i, (t, case) in enumerate(lines):
        t_next = lines[i + 1][0] if i + 1 < len(lines) else end
        begin, finish = max(t, start), min(t_next, end)
        if finish > begin:
            totals[case] = totals.get(case, 0.0) + (finish - begin)
    return {case: totals[case] for case in sorted(totals, key=_case_order)}


@dataclass(frozen=True)
class Collision:
    sim_time: float     # [s] when the touch started
    robot: str
    model: str


def collision_onsets(updates: Sequence[Tuple[float, Sequence[Tuple[str, str]]]]) -> List[Collision]:
    """Touches that start, from successive sets of (robot, model) pairs in contact (one set
    per /gazebo/contacts message, in time order). A pair counts again only after it was
    apart."""
    onsets, before = [], set()
    for t, pairs in updates:
        now = set(tuple(p) for p in pairs)
        for robot, model in sorted(now - before):
            onsets.append(Collision(t, robot, model))
        before = now
    return onsets


def real_time_factor(sim_seconds, wall_seconds) -> float:
    """Sim seconds per wall second (inf for no wall time, 0 for no sim time)."""
    if sim_seconds <= 0:
        return 0.0
    return sim_seconds / wall_seconds if wall_seconds > 0 else math.inf


def progress_line(sim_done, sim_total, rtf, case) -> str:
    """One progress line: sim time done / total, real-time factor, current case."""
    percent = 100.0 * sim_done / sim_total if sim_total > 0 else 100.0
    return "sim %6.1f / %.0f s (%3.0f%%)  %5.1fx real time  %s" % (
        sim_done, sim_total, percent, rtf, case or "(no case yet)")


@dataclass
class RunSummary:
    world: str
    start: Tuple[float, float, float]      # x [m], y [m], yaw [rad]
    sim_time: float                        # [s]
    wall_time: float                       # [s]
    distance: float                        # [m]
    min_clearance: Optional[float] = None  # [m]; < 0 is a penetration
    min_clearance_model: str = ""
    min_clearance_time: float = 0.0        # [s]
    collisions: List[Collision] = field(default_factory=list)
    cases: Dict[str, float] = field(default_factory=dict)   # case -> [s]
    picture: str = ""
    bag: str = ""
    replay: str = ""                       # the run's replay page (browser view)
    end: Optional[Tuple[float, float, float]] = None   # x [m], y [m], yaw [rad] at the end

    @property
    def real_time_factor(self):
        return real_time_factor(self.sim_time, self.wall_time)

    def as_dict(self):
        return {
            "world": self.world, "start": {"x": self.start[0], "y": self.start[1],
                                           "yaw": self.start[2]},
            "sim_time_s": self.sim_time, "wall_time_s": self.wall_time,
            "real_time_factor": self.real_time_factor, "distance_m": self.distance,
            "min_clearance_m": self.min_clearance, "min_clearance_model": self.min_clearance_model,
            "min_clearance_time_s": self.min_clearance_time,
            "collisions": [{"sim_time_s": c.sim_time, "robot": c.robot, "model": c.model}
                           for c in self.collisions],
            "cases_s": self.cases, "picture": self.picture, "bag": self.bag,
            "replay": self.replay,
            "end": None if self.end is None else {"x": self.end[0], "y": self.end[1],
                                                  "yaw": self.end[2]},
        }

    def text(self) -> str:
        x, y, yaw = self.start
        lines = [
            "run summary: %s, start (%.2f, %.2f) m, yaw %.1f deg" % (self.world, x, y,
                                                                   math.degrees(yaw)),
            "  sim time          %8.2f s" % self.sim_time,
            "  wall time         %8.2f s" % self.wall_time,
            "  real-time factor  %8.1f x" % self.real_time_factor,
            "  distance          %8.2f m" % self.distance,
        ]
        if self.min_clearance is None:
            lines.append("  min clearance          n/a (no obstacle within range)")
        else:
            lines.append("  min clearance     %8.3f m  (%s, at %.2f s)" % (
                self.min_clearance, self.min_clearance_model, self.min_clearance_time))
        lines.append("  collisions        %8d" % len(self.collisions))
        for c in self.collisions:
            lines.append("    %8.2f s  %s touched %s" % (c.sim_time, c.robot, c.model))
        lines.append("  time in each case:")
        total = sum(self.cases.values())
        for case, seconds in self.cases.items():
            share = 100.0 * seconds / total if total > 0 else 0.0
            lines.append("    %-36s %7.2f s  %5.1f %%" % (case, seconds, share))
        if not self.cases:
            lines.append("    (obstacle_avoidance.py logged no case)")
        if self.picture:
            lines.append("  picture           %s" % self.picture)
        if self.replay:
            lines.append("  replay            %s (opens in a browser)" % self.replay)
        if self.bag:
            lines.append("  bag               %s" % self.bag)
        return "\n".join(lines)
