"""Speed figures of m2wr_gym's environments (printed, never asserted):
`python -m m2wr_tools.bench.gym`.

1. One in-process environment (world02, 10 Hz control, 720-beam scan, random continuous
   actions drawn before the timing, the same three episodes from random free starts in
   every round, see env_against_bare) against bare Bullet: the same world and m2wr built
   by the same World, driven by a constant command, stepped with client.stepSimulation()
   alone (no laser, no drive updates, no contacts), in turns with the environment. Both as
   sim seconds per wall second; the ratio is the environment's share of Bullet's speed.
2. Vectorised (--part vector): the same two episodes (seeds s and s + 1, random free starts,
   actions drawn ahead, so no sampler runs in the timed loops) stepped in this process one
   after the other, in one subprocess (an AsyncVectorEnv of one), in two subprocesses at
   once (AsyncVectorEnv of two), in m2wr_gym's SharedMemoryVectorEnv of one and of two
   (shared_vector.py: shared arrays and semaphores instead of pipes, workers that run
   the physics no action can change while they wait; of two also without that,
   run_ahead=False, and with local=True, this process stepping one of them itself, also
   with spin, both processes polling instead of sleeping), and through
   stable-baselines3's SubprocVecEnv when it is installed; env steps per second of wall
   time, each ratio taken within the round. The machine's own ceiling for two processes
   is measured in the same round: two bare Bullet steppers in two processes at once
   against one; and the environments' own: the two stretches stepped at once in two
   processes with no vector env and no lockstep (each as in process) against one in
   process, the most any vector env could give. Also the CPU each side spends (workers per
   env step, the learner's process per vector step, from /proc) and how busy the two cores
   were: what separates the figure from the ceiling; for SharedMemoryVectorEnv also its
   measured wake-ups (learner's post to a worker running, last worker's post to the
   learner running) and a worker's step as timed inside it. Odd rounds run in reverse order.
   Last, the two vector envs' own cost per step, with envs that do nothing (IdleEnv).
3. Where one in-process control step's CPU time goes, timed inside the env's own steps (see
   breakdown()): Bullet's physics, the contact guard and reads, the one scan observed, the
   rest of the engine, the environment's own Python.
Measurements alternate in rounds (--rounds); for 1 the median of the rounds' ratios (with
their range), each round's two sides taken in turns piece by piece, so a busy moment of a
shared machine hits both alike; for 3 the round with the least CPU; for 2 the median of the
same-round ratios (with their range). The in-process figures are also given per
second of this process's CPU time, which other programs on a shared machine disturb less
than wall time (but still: note the load, `uptime`, with any figure).
"""
import contextlib
import multiprocessing
import time
import warnings

import gymnasium
import numpy as np
from gymnasium.vector import AsyncVectorEnv
from m2wr_gym import actions
from m2wr_gym.shared_vector import SharedMemoryVectorEnv, children_ignore_ctrl_c

from ..running.processes import cpu_seconds
from .. import usage

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
    sim.drive.set_command(0.3, 0.2)
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


def _free_env_worker(stretch, start, results):
    f = in_process([stretch], start)
    results.put((f["steps"], f["first"], f["last"], f["cpu"]))


def _two_at_once(target, args):
    """Runs target(*args[k], barrier, results) in two spawned processes that start their
    timed loops together; what they put in results."""
    context = multiprocessing.get_context("spawn")
    start, results = context.Barrier(2), context.Queue()
    workers = [context.Process(target=target, args=tuple(a) + (start, results)) for a in args]
    finished = False
    try:
        with children_ignore_ctrl_c():
            for worker in workers:
                worker.start()
        answers = [results.get(timeout=600) for _ in workers]
        finished = True
        return answers
    finally:
        for worker in workers:
            if worker.pid is None:
                continue                         # not started
            worker.join(timeout=10 if finished else 0)
            if worker.is_alive():
                worker.terminate()
                worker.join()


def two_bare_bullets(seconds):
    """The machine's own ceiling for two processes: summed sim s / wall s of two bare Bullet
    steppers running at once (each as bare_bullet), in two processes."""
    return sum(_two_at_once(_bare_bullet_worker, [(seconds,), (seconds,)]))


def two_free_envs(work):
    """The environment's own ceiling for two processes: summed env steps/s of the two
    stretches stepped at once in two processes, each in process with no vector env and no
    lockstep (as in_process): what two envs get from the two cores with nothing between
    them and the learner. Env steps/s = both processes' timed steps / the time from the
    first one's start to the last one's end (perf_counter is system-wide); and their CPU
    seconds per env step."""
    answers = _two_at_once(_free_env_worker, [(stretch,) for stretch in work])
    steps = sum(a[0] for a in answers)
    return {"rate": steps / (max(a[2] for a in answers) - min(a[1] for a in answers)),
            "cpu": sum(a[0] * a[3] for a in answers) / steps}


def drawn_actions(env, steps, seed):
    """`steps` random actions of env's action space, drawn before any timing: the sampler
    (gymnasium's Box.sample, ~25 us) is the learner's work, not the environment's."""
    env.action_space.seed(seed)
    return [env.action_space.sample() for _ in range(steps)]


EPISODES = (0, 1, 2)    # the seeds of the episodes every round of the in-process figure runs
CHUNKS = 2              # pieces of each episode, each followed by bare Bullet's turn


def env_against_bare(steps):
    """One round of the in-process figure: the same episodes every round (seeds EPISODES,
    random free starts, steps / len(EPISODES) random actions each, drawn ahead; the reset
    before each is not timed) in CHUNKS pieces each, every piece followed by bare Bullet
    stepping as much sim time (bare_bullet's world and command), so both sides meet the
    same moments of a shared machine. Returns (env sim s per wall s, env steps per wall s,
    env sim s per CPU s, bare sim s per wall s, bare sim s per CPU s)."""
    bare_env = make().unwrapped
    bare_env.reset(seed=0)
    sim = bare_env.sim
    sim.drive.set_command(0.3, 0.2)
    sim.world.step()                      # the drive applies the command once
    bare_step = sim.client.stepSimulation
    clock, cpu = time.perf_counter, time.process_time
    env_wall = env_cpu = bare_wall = bare_cpu = 0.0
    env_steps = bare_steps = 0
    per_episode = max(CHUNKS, steps // len(EPISODES))
    dt = None
    for seed in EPISODES:
        env = make()
        dt = env.unwrapped.dt
        ahead = drawn_actions(env, per_episode, seed)
        env.reset(seed=seed)
        for piece in np.array_split(np.arange(per_episode), CHUNKS):
            started, cpu_started = clock(), cpu()
            for index in piece:
                _, _, terminated, truncated, _ = env.step(ahead[index])
                if terminated or truncated:
                    env.reset()
            env_wall += clock() - started
            env_cpu += cpu() - cpu_started
            env_steps += len(piece)
            physics = int(round(len(piece) * dt / sim.physics_step))
            started, cpu_started = clock(), cpu()
            for _ in range(physics):
                bare_step()
            bare_wall += clock() - started
            bare_cpu += cpu() - cpu_started
            bare_steps += physics
        env.close()
    bare_env.close()
    env_sim, bare_sim = env_steps * dt, bare_steps * sim.physics_step
    return (env_sim / env_wall, env_steps / env_wall, env_sim / env_cpu,
            bare_sim / bare_wall, bare_sim / bare_cpu)


@contextlib.contextmanager
def _timed(timers, owner, name, key):
    """owner.name (a class's method) adds its CPU time [s] and calls to timers[key] while
    inside; put back after."""
    original = getattr(owner, name)
    cpu = time.process_time

    def timed(*args, **kwargs):
        started = cpu()
        try:
            return original(*args, **kwargs)
        finally:
            timers[key][0] += cpu() - started
            timers[key][1] += 1

    timers[key] = [0.0, 0]
    setattr(owner, name, timed)
    try:
        yield
    finally:
        setattr(owner, name, original)


def breakdown(steps, seed=0):
    """Where the CPU time of the env's own steps goes, [us] per env step: the whole env.step
    and, timed inside those same steps, Bullet's physics (the Batcher's stepSimulation
    calls, batched as the engine runs them), the contact guard (Batcher.safe_time), the
    contact reads (ContactTracker.update), the one scan observed (RaySensor.measure), the
    rest of the engine (World.advance's loop, the drive, schedules) and the environment's
    own Python (observation, reward, info, gymnasium's wrappers). Each timer costs ~1 us a
    call, counted in its part. Also the Bullet calls per env step."""
    from pybullet_gazebo.engine.batching import Batcher
    from pybullet_gazebo.engine.contacts import ContactTracker
    from pybullet_gazebo.engine.ray_sensor import RaySensor
    from m2wr_gym.sim_inprocess import InProcessSim
    env = make()
    actions_ahead = drawn_actions(env, steps, seed)
    env.reset(seed=seed)
    timers = {}
    with contextlib.ExitStack() as stack:
        for owner, name, key in ((Batcher, "step", "physics"), (Batcher, "safe_time", "guard"),
                                 (ContactTracker, "update", "contacts"),
                                 (RaySensor, "measure", "scan"), (InProcessSim, "run", "sim")):
            stack.enter_context(_timed(timers, owner, name, key))
        started = time.process_time()
        for action in actions_ahead:
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()
        whole = time.process_time() - started
    env.close()
    us = {key: seconds / steps * 1e6 for key, (seconds, _) in timers.items()}
    return {"env step": whole / steps * 1e6, "physics": us["physics"], "guard": us["guard"],
            "contacts": us["contacts"], "scan": us["scan"],
            "engine": us["sim"] - us["physics"] - us["guard"] - us["contacts"] - us["scan"],
            "env": whole / steps * 1e6 - us["sim"],
            "bullet calls": timers["physics"][1] / steps}


LOCAL_SPIN = 0.002    # [s] SharedMemoryVectorEnv's spin in the local=True measurement
WARMUP = 10          # env steps after each reset before timing (pages touched, caches filled)


def stretches(seed, steps):
    """The vector measurement's work: two episodes (seeds `seed`, `seed` + 1, random free
    starts), each WARMUP + `steps` continuous actions drawn ahead from its own seed, so that
    every way of running them steps the same episodes with the same actions (and no
    sampler runs inside the timed loops)."""
    space = actions.space(KWARGS["action"])
    work = []
    for k in range(2):
        space.seed(seed + k)
        work.append((seed + k, np.array([space.sample() for _ in range(WARMUP + steps)])))
    return work


def in_process(work, start=None):
    """The stretches one after the other in this process: env steps/s of wall time and CPU
    seconds per env step (timed steps only; also their number, when the first timed step
    started and the last ended, perf_counter, and each timed step's CPU seconds, per
    stretch). An episode's end is followed by a reset in place of the next action, as
    AsyncVectorEnv's autoreset does."""
    env = make()
    if start is not None:
        start.wait()                       # a barrier: two_free_envs starts two at once
    wall = cpu = 0.0
    timed = 0
    first = None
    step_cpu = []
    thread_time = time.thread_time
    for seed, chosen in work:
        env.reset(seed=seed)
        ended = False
        each = np.zeros(len(chosen))
        for i, action in enumerate(chosen):
            if i == WARMUP:
                started, cpu_started = time.perf_counter(), time.process_time()
                first = started if first is None else first
            began = thread_time()
            if ended:
                env.reset()
                ended = False
            else:
                _, _, terminated, truncated, _ = env.step(action)
                ended = terminated or truncated
            each[i] = thread_time() - began
        last = time.perf_counter()
        wall += last - started
        cpu += time.process_time() - cpu_started
        timed += len(chosen) - WARMUP
        step_cpu.append(each[WARMUP:])
    env.close()
    return {"rate": timed / wall, "cpu": cpu / timed, "steps": timed, "first": first,
            "last": last, "step cpu": step_cpu}


def lockstep_price(step_cpu):
    """How much longer than an average step a vector env's step of two takes when the two
    envs' steps (each stretch's k-th, paired as a vector env pairs them) cost what they
    cost in process and the faster one waits for the slower: mean of the pairs' max / mean
    of all. Step costs vary with what the robot meets (contacts stepped one step at a time,
    Bullet's solver): the most a lockstep vector env of two can give is the two cores'
    ceiling divided by this."""
    a, b = step_cpu[:2]
    n = min(len(a), len(b))
    return float(np.maximum(a[:n], b[:n]).mean() / np.concatenate([a[:n], b[:n]]).mean())


def in_subprocesses(work, parallel, library="gymnasium", **options):
    """The stretches in subprocesses, as a learner runs them: `parallel` = 1 (one
    AsyncVectorEnv of one env, stretch after stretch) or 2 (both at once, one env per
    worker); library "sb3": stable-baselines3's SubprocVecEnv instead (its default start
    method). Returns env steps/s of wall time, CPU seconds per env step in the workers, CPU
    seconds per vector step in this (the learner's) process, timed steps only; library
    "shm": m2wr_gym's SharedMemoryVectorEnv (`options` passed on), then also its timing
    report (wake-ups and a worker's step, [us])."""
    groups = [work] if parallel == 2 else [[one] for one in work]
    wall = cpu = workers = 0.0
    steps = vector_steps = 0
    vector, finished = None, False
    try:
        with children_ignore_ctrl_c():
            if library == "sb3":
                from stable_baselines3.common.vec_env import SubprocVecEnv
                vector = SubprocVecEnv([make] * parallel)
            elif library == "shm":
                vector = SharedMemoryVectorEnv([make] * parallel, **options)
            else:
                vector = AsyncVectorEnv([make] * parallel)
        pids = [process.pid for process in vector.processes]
        for group in groups:
            seeds = [seed for seed, _ in group]
            batches = np.stack([chosen for _, chosen in group], axis=1)  # (steps, envs, 2)
            if library == "sb3":
                vector.seed(seeds[0])                 # SB3 seeds env i with seed + i
                vector.reset()
            else:
                vector.reset(seed=seeds)
            for batch in batches[:WARMUP]:
                vector.step(batch)
            if library == "shm":
                vector.reset_timing()
            workers_started = sum(cpu_seconds(pid) for pid in pids)
            started, cpu_started = time.perf_counter(), time.process_time()
            for batch in batches[WARMUP:]:
                vector.step(batch)
            wall += time.perf_counter() - started
            cpu += time.process_time() - cpu_started
            workers += sum(cpu_seconds(pid) for pid in pids) - workers_started
            vector_steps += len(batches) - WARMUP
            steps += (len(batches) - WARMUP) * parallel
        timing = vector.timing_report() if library == "shm" else {}
        finished = True
    finally:
        if vector is not None:
            _close(vector, finished)
    return dict(timing, rate=steps / wall, **{"worker cpu": workers / steps,
                                              "main cpu": cpu / vector_steps,
                                              "wall": wall / vector_steps})


def _close(vector, finished):
    """Closes a vector env; after a Ctrl-C amid a step its workers are ended at once (a
    polite close would warn, or wait for a reply that may have been read already)."""
    if finished:
        vector.close()
        return
    for process in vector.processes:
        if process.is_alive():
            process.terminate()
        process.join()
    if isinstance(vector, SharedMemoryVectorEnv):   # its pipes
        vector.close(terminate=True)
    elif isinstance(vector, AsyncVectorEnv):        # its pipes and shared memory
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                vector.close(terminate=True)
            except (EOFError, OSError):
                pass
    vector.closed = True


class IdleEnv(gymnasium.Env):
    """An env that does nothing, with m2wr's spaces and info keys (a 720-float observation,
    six floats and two tuples of info): what a vector env itself costs per step."""
    observation_space = gymnasium.spaces.Box(0.0, 10.0, (720,), np.float32)
    action_space = actions.space("continuous")

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._t = 0.0
        return np.zeros(720, np.float32), self._info((0.0, 0.0))

    def step(self, action):
        self._t += 0.1
        return (np.full(720, self._t, np.float32), 0.0, False, False,
                self._info(tuple(action.tolist())))

    def _info(self, command):
        return {"sim_time": self._t, "x": 1.0, "y": 2.0, "yaw": 0.5, "nearest": 3.0,
                "touched": (), "distance": self._t, "command": command}


def vector_overhead(steps=2000):
    """Wall and learner-CPU [us] per vector step of two IdleEnvs, AsyncVectorEnv and
    SharedMemoryVectorEnv in turn: the price of the vector env alone, little disturbed by
    other programs (each side the best of 3 runs)."""
    batch = np.zeros((2, 2), np.float32)
    figures = {}
    for name, build in (("AsyncVectorEnv", AsyncVectorEnv),
                        ("SharedMemoryVectorEnv", SharedMemoryVectorEnv)):
        with children_ignore_ctrl_c():
            vector = build([IdleEnv] * 2)
        try:
            vector.reset(seed=0)
            best = None
            for _ in range(3):
                for _ in range(100):
                    vector.step(batch)
                started, cpu_started = time.perf_counter(), time.process_time()
                for _ in range(steps):
                    vector.step(batch)
                run = ((time.perf_counter() - started) / steps * 1e6,
                       (time.process_time() - cpu_started) / steps * 1e6)
                best = run if best is None or run[0] < best[0] else best
            figures[name] = best
        finally:
            vector.close()
    return figures


def sb3_available():
    try:
        import stable_baselines3  # noqa: F401  (the training extra: scripts/train.sh)
    except ImportError:
        return False
    return True


def vector_round(r, steps, with_sb3):
    """Round r of the vector figures, all measured within a few seconds of each other: the
    same two stretches in process, in one subprocess, in two at once (and through SB3 when
    installed); bare Bullet alone and two bare Bullets in two processes at once, the
    machine's own two-process ceiling at that moment. Odd rounds go in reverse order, so a
    machine growing busier or quieter within rounds favours no side."""
    work = stretches(2 * r, steps)
    seconds = steps * 0.1
    runs = [("in process", lambda: in_process(work)),
            ("1 subprocess", lambda: in_subprocesses(work, 1)),
            ("2 subprocesses", lambda: in_subprocesses(work, 2)),
            ("1 shm subprocess", lambda: in_subprocesses(work, 1, "shm")),
            ("2 shm subprocesses", lambda: in_subprocesses(work, 2, "shm")),
            ("2 shm, no run-ahead", lambda: in_subprocesses(work, 2, "shm", run_ahead=False)),
            ("2 shm, 1 local", lambda: in_subprocesses(work, 2, "shm", local=True)),
            ("2 shm, 1 local, spin", lambda: in_subprocesses(work, 2, "shm", local=True,
                                                             spin=LOCAL_SPIN))]
    if with_sb3:
        runs.append(("2 SB3 subprocesses", lambda: in_subprocesses(work, 2, "sb3")))
    runs += [("bare Bullet", lambda: bare_bullet(seconds)[0]),
             ("2 bare Bullets", lambda: two_bare_bullets(seconds)),
             ("2 free envs", lambda: two_free_envs(work))]
    return {name: run() for name, run in (runs[::-1] if r % 2 else runs)}


def print_vector_round(r, rounds, f):
    one, sub, two = f["in process"]["rate"], f["1 subprocess"]["rate"], f["2 subprocesses"]["rate"]
    line = ("[bench] vector round %d/%d: env steps/s in process %.0f, 1 subprocess %.0f, "
            "2 subprocesses %.0f (%.2fx in process, %.2fx 1 subprocess)"
            % (r + 1, rounds, one, sub, two, two / one, two / sub))
    shm1, shm2 = f["1 shm subprocess"]["rate"], f["2 shm subprocesses"]["rate"]
    local, plain = f["2 shm, 1 local"]["rate"], f["2 shm, no run-ahead"]["rate"]
    spinning = f["2 shm, 1 local, spin"]["rate"]
    line += ("; shared-memory vector env: 1 subprocess %.0f, 2 subprocesses %.0f (%.2fx in "
             "process, %.2fx its 1; %.2fx without run-ahead), 2 with local=True %.0f (%.2fx in "
             "process; %.2fx spinning)" % (shm1, shm2, shm2 / one, shm2 / shm1, plain / one,
                                           local, local / one, spinning / one))
    if "2 SB3 subprocesses" in f:
        sb3 = f["2 SB3 subprocesses"]["rate"]
        line += ", 2 SB3 subprocesses %.0f (%.2fx in process)" % (sb3, sb3 / one)
    print(line + "; ceilings: 2 bare Bullets %.2fx one, 2 free-running envs %.2fx in process"
          % (f["2 bare Bullets"] / f["bare Bullet"], f["2 free envs"]["rate"] / one), flush=True)


def print_vector_summary(rounds, steps):
    """Median over rounds of each same-round ratio, and where a vector step's time goes."""
    def median(values):
        return float(np.median(values))

    def spread(values):
        return "%.2f-%.2f" % (min(values), max(values))

    ratio = {}
    for key in ("1 subprocess", "2 subprocesses", "1 shm subprocess", "2 shm subprocesses",
                "2 shm, no run-ahead", "2 shm, 1 local", "2 shm, 1 local, spin",
                "2 SB3 subprocesses"):
        if key in rounds[0]:
            ratio[key] = [f[key]["rate"] / f["in process"]["rate"] for f in rounds]
    two_to_one = [f["2 subprocesses"]["rate"] / f["1 subprocess"]["rate"] for f in rounds]
    ceiling = [f["2 bare Bullets"] / f["bare Bullet"] for f in rounds]
    print("\nvectorised (median of %d rounds, same-round ratios, range in brackets; 2 episodes "
          "x %d env steps, the same actions each way):" % (len(rounds), steps))
    print("  one env in process:                    %6.0f env steps/s"
          % median([f["in process"]["rate"] for f in rounds]))
    for key, label in (("1 subprocess", "one env in a subprocess:"),
                       ("2 subprocesses", "two envs in subprocesses:"),
                       ("1 shm subprocess", "one in m2wr_gym's shared-memory env:"),
                       ("2 shm subprocesses", "two in m2wr_gym's shared-memory env:"),
                       ("2 shm, no run-ahead", "two in it, run_ahead=False:"),
                       ("2 shm, 1 local", "two in it, local=True (1 here):"),
                       ("2 shm, 1 local, spin", "the same, spin=%g s:" % LOCAL_SPIN),
                       ("2 SB3 subprocesses", "two in SB3 SubprocVecEnv:")):
        if key in ratio:
            print("  %-38s %6.0f env steps/s = %.2fx in process (%s)"
                  % (label, median([f[key]["rate"] for f in rounds]), median(ratio[key]),
                     spread(ratio[key])))
    print("  two in subprocesses / one in a subprocess:   %.2fx (%s)"
          % (median(two_to_one), spread(two_to_one)))
    shm_two_to_one = [f["2 shm subprocesses"]["rate"] / f["1 shm subprocess"]["rate"]
                      for f in rounds]
    print("  two in the shared-memory env / one in it:    %.2fx (%s)"
          % (median(shm_two_to_one), spread(shm_two_to_one)))
    print("  the machine's ceiling, two bare Bullets at once / one: %.2fx (%s)"
          % (median(ceiling), spread(ceiling)))
    free = [f["2 free envs"]["rate"] / f["in process"]["rate"] for f in rounds]
    free_cpu = [f["2 free envs"]["cpu"] / f["in process"]["cpu"] for f in rounds]
    print("  the envs' ceiling, two envs free-running in two processes (no vector env, no "
          "lockstep) / one in process: %.2fx (%s); their CPU per env step %.0f us, %.2fx in "
          "process (%s)" % (median(free), spread(free),
                            median([f["2 free envs"]["cpu"] for f in rounds]) * 1e6,
                            median(free_cpu), spread(free_cpu)))
    price = [lockstep_price(f["in process"]["step cpu"]) for f in rounds]
    bound = [c / p for c, p in zip(free, price)]
    print("  lockstep's own price: the slower of the two envs' steps (paired as a vector env "
          "pairs them, CPU measured in process) takes %.2fx the mean step (%s); so the most "
          "any lockstep vector env of two could give here, the envs' ceiling / that: %.2fx "
          "in process (%s)" % (median(price), spread(price), median(bound), spread(bound)))
    # CPU: what the two cores did per vector step of two envs, against its wall time
    inproc = median([f["in process"]["cpu"] for f in rounds])
    w1 = median([f["1 subprocess"]["worker cpu"] for f in rounds])
    m1 = median([f["1 subprocess"]["main cpu"] for f in rounds])
    w2 = median([f["2 subprocesses"]["worker cpu"] for f in rounds])
    m2 = median([f["2 subprocesses"]["main cpu"] for f in rounds])
    wall2 = median([f["2 subprocesses"]["wall"] for f in rounds])
    busy = [(2 * f["2 subprocesses"]["worker cpu"] + f["2 subprocesses"]["main cpu"])
            / (2 * f["2 subprocesses"]["wall"]) for f in rounds]
    # two cores doing nothing but this work, never waiting: env steps per CPU second of the
    # pair (workers + the learner's share) x 2 cores, against one env in process
    bound = [2 * f["in process"]["cpu"]
             / (f["2 subprocesses"]["worker cpu"] + f["2 subprocesses"]["main cpu"] / 2)
             for f in rounds]
    print("  CPU per env step [us]: in process %.0f; in a worker %.0f alone, %.0f two at once "
          "(%.2fx in process)" % (inproc * 1e6, w1 * 1e6, w2 * 1e6, w2 / inproc))
    print("  learner's process per vector step [us]: %.0f with one worker, %.0f with two "
          "(pipes, pickles, info merging)" % (m1 * 1e6, m2 * 1e6))
    print("  two envs: a vector step takes %.0f us of wall time; the learner and its workers "
          "used %.0f %% of the two cores' time (%s; other programs may use the rest)"
          % (wall2 * 1e6, 100 * median(busy), spread(busy)))
    print("  if the two cores did nothing but this work, with no waiting, this CPU per step "
          "would give %.2fx in process (%s); the rest is waiting: for the slower of the two "
          "steps, the pipes' wake-ups, the learner's serial part" % (median(bound), spread(bound)))
    # the same for the shared-memory vector env, with its own wake-up timing
    two = [f["2 shm subprocesses"] for f in rounds]
    one_shm = [f["1 shm subprocess"] for f in rounds]
    shm_bound = [2 * f["in process"]["cpu"] / (t["worker cpu"] + t["main cpu"] / 2)
                 for f, t in zip(rounds, two)]
    print("  shared-memory env: CPU per env step in a worker %.0f us alone, %.0f two at once "
          "(%.2fx in process); learner per vector step %.0f us with one, %.0f with two; a "
          "vector step of two takes %.0f us of wall time"
          % (median([t["worker cpu"] for t in one_shm]) * 1e6,
             median([t["worker cpu"] for t in two]) * 1e6,
             median([t["worker cpu"] for t in two]) / inproc,
             median([t["main cpu"] for t in one_shm]) * 1e6,
             median([t["main cpu"] for t in two]) * 1e6, median([t["wall"] for t in two]) * 1e6))
    print("  shared-memory env, two at once: a worker's step %.0f us (timed inside it; CPU "
          "%.0f us, and %.0f us run ahead while waiting), learner's post -> worker running "
          "%.0f us (its run-ahead's end, when later), last worker's post -> learner running "
          "%.0f us; CPU bound as above %.2fx (%s)"
          % (median([t["work"] for t in two]), median([t["work cpu"] for t in two]),
             median([t["ahead cpu"] for t in two]), median([t["go"] for t in two]),
             median([t["wake"] for t in two]), median(shm_bound), spread(shm_bound)))


def main(argv=None):
    p = usage.parser("python -m m2wr_tools.bench.gym", __doc__, examples=[
        "python -m m2wr_tools.bench.gym                 # both halves",
        "python -m m2wr_tools.bench.gym --part env --rounds 5 --steps 1200"],
        exit_statuses="Exit status: 0 with the figures printed; 2 for bad arguments; 130 when "
        "interrupted.")
    p.add_argument("--rounds", type=int, default=3,
                   help="rounds of every measurement, the sides in turn")
    p.add_argument("--steps", type=int, default=600, help="env steps per measurement")
    p.add_argument("--part", choices=("all", "env", "vector"), default="all",
                   help="env: the in-process figures (1, 3); vector: the subprocess ones (2); "
                   "all: both")
    p.add_argument("--no-sb3", action="store_true",
                   help="leave out SB3's SubprocVecEnv (measured when stable-baselines3 is "
                        "installed: scripts/train.sh installs it)")
    args = p.parse_args(argv)
    with_sb3 = args.part != "env" and not args.no_sb3 and sb3_available()
    bare, env_rate, env_steps, bare_cpu, env_cpu, parts_by_round = [], [], [], [], [], []
    vector_rounds = []
    for r in range(args.rounds):
        if args.part != "vector":
            rate, per_s, cpu_rate, bare_rate, bare_cpu_rate = env_against_bare(args.steps)
            bare.append(bare_rate)
            bare_cpu.append(bare_cpu_rate)
            env_rate.append(rate)
            env_steps.append(per_s)
            env_cpu.append(cpu_rate)
            parts_by_round.append(breakdown(args.steps // 2, seed=0))
            print("[bench] round %d/%d: bare Bullet %.0fx real time, env %.0fx (%.0f steps/s)"
                  % (r + 1, args.rounds, bare[-1], env_rate[-1], env_steps[-1]), flush=True)
        if args.part != "env":
            vector_rounds.append(vector_round(r, args.steps, with_sb3))
            print_vector_round(r, args.rounds, vector_rounds[-1])
    if args.part != "vector":
        print_env_summary(args, bare, env_rate, env_steps, bare_cpu, env_cpu, parts_by_round)
    if args.part != "env":
        if not with_sb3 and not args.no_sb3:
            print("\n(SB3's SubprocVecEnv left out: stable-baselines3 is not installed)")
        print_vector_summary(vector_rounds, args.steps)
        idle = vector_overhead()
        print("  the vector env alone (two envs that do nothing, m2wr's observation and info): "
              + "; ".join("%s %.0f us per vector step, %.0f us of it the learner's CPU"
                          % (name, wall, cpu) for name, (wall, cpu) in idle.items()))
    return 0


def print_env_summary(args, bare, env_rate, env_steps, bare_cpu, env_cpu, parts_by_round):
    ratios = sorted(e / b for e, b in zip(env_rate, bare))
    cpu_ratios = sorted(e / b for e, b in zip(env_cpu, bare_cpu))
    print("\n%d rounds of the same %d episodes, %d env steps in all (world02, 10 Hz, 720 beams, "
          "random actions), each piece of env followed by as much sim time of bare Bullet:"
          % (args.rounds, len(EPISODES), len(EPISODES) * max(CHUNKS, args.steps // len(EPISODES))))
    print("  bare Bullet stepping (same world + m2wr):  %6.0f sim s / wall s (median of rounds)"
          % float(np.median(bare)))
    print("  one environment in process:              %6.0f sim s / wall s  (%.0f env steps/s)"
          % (float(np.median(env_rate)), float(np.median(env_steps))))
    print("  environment / bare Bullet, round by round: median %.2f (range %.2f-%.2f)"
          % (float(np.median(ratios)), ratios[0], ratios[-1]))
    print("  the same per CPU second:                   median %.2f (range %.2f-%.2f)"
          % (float(np.median(cpu_ratios)), cpu_ratios[0], cpu_ratios[-1]))
    parts = min(parts_by_round, key=lambda parts: parts["env step"])
    print("  CPU per env step in process [us] (round with the least): %.0f = Bullet's physics "
          "%.0f (%.1f calls) + contact guard %.0f + contact reads %.0f + one scan %.0f + rest "
          "of the engine %.0f + environment %.0f; env / physics: %.2f"
          % (parts["env step"], parts["physics"], parts["bullet calls"], parts["guard"],
             parts["contacts"], parts["scan"], parts["engine"], parts["env"],
             parts["physics"] / parts["env step"]))

if __name__ == "__main__":
    try:
        raise SystemExit(main())
    except KeyboardInterrupt:
        raise SystemExit(130)
