"""Compare a policy with the tutorial's obstacle_avoidance.py on the same start poses, in
process (the engine of the ROS simulator, in lockstep semantics: each controller answers
every decision at the sim time it would in lockstep), through m2wr_gym's environment.

    python -m m2wr_tools.batch.gym_evaluate --policy FILE.npz --world world02 --runs 40 \
        --seconds 120

Start poses: `runs` free poses drawn from --start-seed by the environment's free-pose
sampler (the same list for both controllers). The tutorial's program is loaded from
motion_plan/scripts unchanged (tutorial_scripts.py); its take_action() answers each scan
(20 Hz, the laser's rate) with the Twist it would publish. The policy decides every
control_period of its file. Contacts do not end a run here: they are counted.

Per run: collided (any contact), contacts (touch events), distance [m] travelled, minimum
clearance [m] between m2wr's footprint and any obstacle's (m2wr_gym.geometry, from the world
file), time stuck [s] (1-s windows in which the robot moved less than 0.1 m).
Prints progress per run and a Markdown table; --csv writes one row per run.
"""
import csv
import logging
import os
import statistics
import sys
import time

import numpy as np
from m2wr_gym import geometry, observation, resources
from m2wr_gym.env import M2wrEnv
from m2wr_gym.policy import PolicyFileError, load

from .. import tutorial_scripts
from ..tool_exit import exit_status
from .. import usage

STUCK_WINDOW = 1.0          # [s]
STUCK_DISTANCE = 0.1        # [m]


def start_poses(world, runs, seed):
    footprints = geometry.Footprints(resources.world_spec(resources.resolve_world(world)))
    rng = np.random.default_rng(seed)
    return [footprints.free_pose(rng) for _ in range(runs)]


class TutorialController:
    """episode 5's obstacle_avoidance.py: its own clbk_laser regions and take_action()."""
    rate = 20.0               # [Hz] it answers every scan

    def __init__(self):
        self.module = tutorial_scripts.load("obstacle_avoidance.py")
        logging.getLogger("rosout").setLevel(logging.WARNING)   # its per-scan loginfo
        self.sent = None

        class Capture:
            def publish(inner, msg):
                self.sent = (msg.linear.x, msg.angular.z)
        self.module.pub = Capture()

    def command(self, ranges):
        r = observation.regions(ranges)
        self.module.take_action({"right": r[0], "fright": r[1], "front": r[2],
                                 "fleft": r[3], "left": r[4]})
        return self.sent


class PolicyController:
    def __init__(self, path):
        self.policy = load(path)
        self.rate = 1.0 / self.policy.control_period

    def command(self, ranges):
        features = observation.laser_features(self.policy.observation, ranges, 10.0,
                                              self.policy.downsample)
        return self.policy.command(features)


def footprint_clearance(env, bound):
    """m2wr's footprint clearance [m] now, or `bound` when it cannot be below it: the centre's
    distance minus the footprint's circumradius is a lower bound, cheap to compute."""
    s = env.snapshot
    centre = env.footprints.distance([(s.x, s.y)], within=bound + geometry.ROBOT_RADIUS)[0]
    if centre - geometry.ROBOT_RADIUS >= bound:
        return bound
    return min(bound, env.footprints.clearance(s.x, s.y, s.yaw, within=bound))


def run_one(controller, world, pose, seconds, seed):
    env = M2wrEnv(world=world, action="continuous", control_rate=controller.rate,
                  max_episode_seconds=seconds, end_on_contact=False)
    try:
        env.reset(seed=seed, options={"start": pose})
        clearance = env.clearance(within=2.0)
        contacts, touching, collided = 0, False, False
        positions = [(env.snapshot.x, env.snapshot.y)]
        while True:
            command = controller.command(env.snapshot.ranges)
            _, _, terminated, truncated, info = env.step(np.array(command, np.float32))
            positions.append((info["x"], info["y"]))
            if info["touched"]:
                collided = True
                contacts += 0 if touching else 1
            touching = bool(info["touched"])
            clearance = min(clearance, footprint_clearance(env, clearance))
            if terminated or truncated:
                break
        window = max(1, int(round(STUCK_WINDOW / env.dt)))
        p = np.array(positions)
        moved = np.linalg.norm(p[window::window] - p[:-window:window][:len(p[window::window])], axis=1)
        return dict(collided=collided, contacts=contacts, distance=info["distance"],
                    min_clearance=clearance, stuck=float((moved < STUCK_DISTANCE).sum() * window * env.dt),
                    seconds=info["sim_time"])
    finally:
        env.close()


def summarize(name, rows):
    n = len(rows)
    free = sum(not r["collided"] for r in rows)
    return ("| %s | %d/%d (%.0f %%) | %.1f | %.1f | %.2f | %.2f | %.1f |"
            % (name, free, n, 100.0 * free / n, statistics.median(r["distance"] for r in rows),
               statistics.mean(r["distance"] for r in rows),
               statistics.median(r["min_clearance"] for r in rows),
               min(r["min_clearance"] for r in rows),
               statistics.median(r["stuck"] for r in rows)))


HEADER = ("| controller | runs without contact | median distance [m] | mean distance [m] | "
          "median min. clearance [m] | worst min. clearance [m] | median time stuck [s] |\n"
          "|---|---|---|---|---|---|---|")


def print_table(paths):
    """The Markdown table, one block per world, from CSVs written with --csv."""
    by_world = {}
    for path in paths:
        with open(path) as f:
            for row in csv.DictReader(f):
                row = dict(row, collided=row["collided"] == "True",
                           **{k: float(row[k]) for k in ("distance", "min_clearance", "stuck",
                                                         "seconds")})
                by_world.setdefault(row["world"], {}).setdefault(row["controller"], []).append(row)
    for world, controllers in by_world.items():
        some = next(iter(controllers.values()))
        print("\n%s, %d start poses, %.0f s each\n" % (world, len(some), some[0]["seconds"]))
        print(HEADER)
        for name, rows in controllers.items():
            print(summarize(name, rows))
    return 0


def main(argv=None):
    p = usage.parser("python -m m2wr_tools.batch.gym_evaluate", __doc__, examples=[
        "python -m m2wr_tools.batch.gym_evaluate --world world02   # the shipped policy, 40 starts",
        "python -m m2wr_tools.batch.gym_evaluate --policy /tmp/try/policy.npz --runs 10",
        "python -m m2wr_tools.batch.gym_evaluate --only tutorial --csv oa.csv"],
        exit_statuses="Exit status: 0 with the table printed; 2 for bad arguments or a policy "
        "file that cannot be\nused; 130 when interrupted.")
    p.add_argument("--policy", default=None,
                   help="the policy file (.npz, as scripts/train.sh exports it) (default: "
                   "m2wr_gym's shipped policies/avoid_world02.npz)")
    p.add_argument("--world", default="world02", help="world01, world02 or a .world path")
    p.add_argument("--runs", type=int, default=40,
                   help="start poses, the same for both controllers")
    p.add_argument("--seconds", type=float, default=120.0, help="sim time of a run [s]")
    p.add_argument("--start-seed", type=int, default=2026,
                   help="seed of the free start poses")
    p.add_argument("--only", choices=("policy", "tutorial"), default=None,
                   help="run one controller only (write --csv, then --table the CSVs) "
                   "(default: both)")
    p.add_argument("--csv", default="", help="write one row per run to this file "
                   "(default: none)")
    p.add_argument("--table", nargs="+", default=None, metavar="CSV",
                   help="print the table of earlier runs' CSVs and stop")
    args = p.parse_args(argv)
    if args.policy is None:
        args.policy = os.path.join(resources.package_path("m2wr_gym"), "policies",
                                   "avoid_world02.npz")
    if args.table:
        return print_table(args.table)
    poses = start_poses(args.world, args.runs, args.start_seed)
    controllers = {}
    if args.only in (None, "policy"):
        controllers["learned (%s)" % os.path.basename(args.policy)] = PolicyController(args.policy)
    if args.only in (None, "tutorial"):
        controllers["obstacle_avoidance.py"] = TutorialController()
    results = {}
    writer, out = None, None
    if args.csv:                       # one row per run as it ends: a stopped run keeps its rows
        out = open(args.csv, "w", newline="")
    started = time.monotonic()
    for name, controller in controllers.items():
        results[name] = []
        for i, pose in enumerate(poses):
            row = run_one(controller, args.world, pose, args.seconds, seed=i)
            results[name].append(row)
            if out is not None:
                record = dict(controller=name, world=args.world, run=i, x=pose[0], y=pose[1],
                              yaw=pose[2], **row)
                if writer is None:
                    writer = csv.DictWriter(out, fieldnames=list(record))
                    writer.writeheader()
                writer.writerow(record)
                out.flush()
            print("[evaluate] %s %s run %2d/%d from (%.2f, %.2f, %.2f): %s, %.1f m, clearance "
                  "%.2f m, stuck %.0f s  (%.0f s elapsed)"
                  % (args.world, name, i + 1, len(poses), pose[0], pose[1], pose[2],
                     "CONTACT" if row["collided"] else "no contact", row["distance"],
                     row["min_clearance"], row["stuck"], time.monotonic() - started), flush=True)
    if out is not None:
        out.close()
    print("\n%s, %d start poses (seed %d), %.0f s each\n" % (args.world, len(poses),
                                                            args.start_seed, args.seconds))
    print(HEADER)
    for name, rows in results.items():
        print(summarize(name, rows))
    return 0


if __name__ == "__main__":
    sys.exit(exit_status("gym_evaluate", main, bad_input=(PolicyFileError,)))
