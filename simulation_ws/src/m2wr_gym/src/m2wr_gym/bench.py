"""Speed figures of the environments (printed, never asserted): `python -m m2wr_gym.bench`.

1. One in-process environment (world02, 10 Hz control, 720-beam scan, random continuous
   actions, episodes of 120 s from random free starts, resets included) against bare Bullet:
   the same world and m2wr built by the same World, driven by a constant command, stepped with
   client.stepSimulation() alone (no laser, no drive updates, no contacts). Both as sim
   seconds per wall second; the ratio is the environment's share of Bullet's speed.
2. Two environments in subprocesses (gymnasium's AsyncVectorEnv) against one, in env steps
   per second of wall time; and, as the machine's own ceiling for that ratio, two bare
   Bullet steppers in two processes at once against one.
3. Where one in-process control step's CPU time goes (see breakdown()): Bullet's physics,
   the engine's work around it, the one scan observed, the environment's own Python.
Measurements alternate in rounds (--rounds) and the best round of each is kept, so a busy
moment of a shared machine hits both sides alike. The in-process figures are also given per
second of this process's CPU time, which other programs on a shared machine disturb less
than wall time (but still: note the load, `uptime`, with any figure).
"""
import argparse
import multiprocessing
import time

import gymnasium
import numpy as np
from gymnasium.vector import AsyncVectorEnv

from pybullet_gazebo.engine.transforms import Pose

KWARGS = dict(world="world02", start="random", observation="scan", action="continuous",
              control_rate=10.0, max_episode_seconds=120.0, end_on_contact=False)


def make():
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **KWARGS)


def bare_bullet(seconds, start=None):
    """Sim seconds per wall second (and per CPU second) of stepSimulation alone on the env's
    world and robot; `start`: a barrier to wait at before stepping."""
    env = make().unwrapped
    env.reset(seed=0)
    sim = env.sim
    sim._drive.set_command(0.3, 0.2)
    sim.world.step()                      # the drive applies the command once
    client, steps = sim.client, int(seconds / sim.physics_step)
    if start is not None:
        start.wait()
    started, cpu_started = time.perf_counter(), time.process_time()
    for _ in range(steps):
        client.stepSimulation()
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu_started
    env.close()
    return steps * sim.physics_step / wall, steps * sim.physics_step / cpu


def _bare_bullet_worker(seconds, start, results):
    results.put(bare_bullet(seconds, start)[0])


def two_bare_bullets(seconds):
    """The machine's own ceiling for two processes: summed sim s / wall s of two bare Bullet
    steppers running at once (each as bare_bullet), in two processes."""
    context = multiprocessing.get_context("spawn")
    start, results = context.Barrier(2), context.Queue()
    workers = [context.Process(target=_bare_bullet_worker, args=(seconds, start, results))
               for _ in range(2)]
    for worker in workers:
        worker.start()
    try:
        return sum(results.get(timeout=600) for _ in workers)
    finally:
        for worker in workers:
            worker.join(timeout=10)
            if worker.is_alive():
                worker.terminate()


def one_env(steps, seed=0):
    env = make()
    env.action_space.seed(seed)
    env.reset(seed=seed)
    started, cpu_started = time.perf_counter(), time.process_time()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu_started
    dt = env.unwrapped.dt
    env.close()
    return steps * dt / wall, steps / wall, steps * dt / cpu


def breakdown(steps, seed=0):
    """Where one control step's CPU time goes in process, [us] each (same env, same run):
    the whole env.step; Bullet's stepSimulation alone for the step's physics steps, one call
    each; the engine's work around them (drive, schedules, contacts, batching: World.advance
    without readings, as the env steps, minus that physics: negative when batching saves
    more of Bullet's per-call cost than the engine spends); the one scan observed; the rest
    is the environment's own Python."""
    env = make()
    env.action_space.seed(seed)
    env.reset(seed=seed)
    sim, per_action = env.unwrapped.sim, env.unwrapped.options.steps_per_action
    cpu = time.process_time
    started = cpu()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    whole = (cpu() - started) / steps
    world, bullet_step = sim.world, sim.client.stepSimulation
    engine = physics = scan = 0.0
    for _ in range(steps):                 # alternating, so both meet the same scenes
        sim._drive.set_command(*env.action_space.sample())
        started = cpu()
        world.advance(per_action, collect=())
        engine += cpu() - started
        started = cpu()
        for _ in range(per_action):
            bullet_step()
        physics += cpu() - started
        started = cpu()
        sim._laser.measure(world.sim_time)
        scan += cpu() - started
    env.close()
    physics, scan = physics / steps, scan / steps
    engine = engine / steps - physics
    return {"env step": whole * 1e6, "physics": physics * 1e6, "engine": engine * 1e6,
            "scan": scan * 1e6, "env": (whole - physics - engine - scan) * 1e6}


def vector_env(n, steps):
    vector = AsyncVectorEnv([make] * n)
    try:
        vector.action_space.seed(0)
        vector.reset(seed=list(range(n)))
        vector.step(vector.action_space.sample())        # workers warm
        started = time.perf_counter()
        for _ in range(steps):
            vector.step(vector.action_space.sample())    # autoreset inside
        wall = time.perf_counter() - started
    finally:
        vector.close()
    return n * steps / wall


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--steps", type=int, default=600, help="env steps per measurement")
    args = p.parse_args(argv)
    bare, env_rate, env_steps, one_sub, two_sub = [], [], [], [], []
    bare_cpu, env_cpu, two_bare, parts_by_round = [], [], [], []
    for r in range(args.rounds):
        rate, cpu_rate = bare_bullet(args.steps * 0.1)
        bare.append(rate)
        bare_cpu.append(cpu_rate)
        rate, per_s, cpu_rate = one_env(args.steps, seed=r)
        env_rate.append(rate)
        env_steps.append(per_s)
        env_cpu.append(cpu_rate)
        one_sub.append(vector_env(1, args.steps))
        two_sub.append(vector_env(2, args.steps))
        two_bare.append(two_bare_bullets(args.steps * 0.1))
        parts_by_round.append(breakdown(args.steps // 2, seed=r))
        print("[bench] round %d/%d: bare Bullet %.0fx real time, env %.0fx (%.0f steps/s), "
              "1 subprocess %.0f steps/s, 2 subprocesses %.0f steps/s, 2 bare Bullets %.0fx"
              % (r + 1, args.rounds, bare[-1], env_rate[-1], env_steps[-1], one_sub[-1],
                 two_sub[-1], two_bare[-1]), flush=True)
    print("\nbest of %d rounds, %d env steps each (world02, 10 Hz, 720 beams, random actions):"
          % (args.rounds, args.steps))
    print("  bare Bullet stepping (same world + m2wr):  %6.0f sim s / wall s" % max(bare))
    print("  one environment in process:              %6.0f sim s / wall s  (%.0f env steps/s)"
          % (max(env_rate), max(env_steps)))
    print("  environment / bare Bullet:               %6.2f" % (max(env_rate) / max(bare)))
    print("  per CPU second: bare Bullet %.0f, environment %.0f sim s; ratio %.2f"
          % (max(bare_cpu), max(env_cpu), max(env_cpu) / max(bare_cpu)))
    print("  one environment in a subprocess:         %6.0f env steps/s" % max(one_sub))
    print("  two environments in subprocesses:        %6.0f env steps/s  (%.2fx one in a "
          "subprocess, %.2fx one in process)" % (max(two_sub), max(two_sub) / max(one_sub),
                                                 max(two_sub) / max(env_steps)))
    parts = min(parts_by_round, key=lambda parts: parts["env step"])
    print("  CPU per env step in process [us] (round with the least): %.0f = Bullet's physics "
          "%.0f + engine around it %.0f + one scan %.0f + environment %.0f; "
          "env / bare Bullet from these: %.2f"
          % (parts["env step"], parts["physics"], parts["engine"], parts["scan"], parts["env"],
             parts["physics"] / parts["env step"]))
    print("  the machine's ceiling: two bare Bullet processes at once %.2fx one"
          % (max(two_bare) / max(bare)))
    return 0


if __name__ == "__main__":
    try:
        raise SystemExit(main())
    except KeyboardInterrupt:
        raise SystemExit(130)
