"""SharedMemoryVectorEnv: a gymnasium VectorEnv running one environment per worker process,
with the per-step traffic in shared memory instead of pipes.

    from m2wr_gym.shared_vector import SharedMemoryVectorEnv
    envs = SharedMemoryVectorEnv([lambda: gymnasium.make("m2wr_gym:M2wrAvoid-v0")] * 2)
    observations, infos = envs.reset(seed=0)          # seeds 0 and 1, as AsyncVectorEnv
    observations, rewards, terminations, truncations, infos = envs.step(actions)
    envs.close()

What a step returns is what gymnasium's AsyncVectorEnv returns for the same environments,
seeds and actions (observations, rewards, flags and the merged infos with their "_key"
masks), autoreset included (NEXT_STEP by default, as AsyncVectorEnv; SAME_STEP and DISABLED
on request; metadata["autoreset_mode"] says which). The difference is the way there:

- Actions, observations, rewards and the terminated/truncated flags live in shared arrays;
  the numeric entries of each info (float, int, bool, numpy scalars, tuples of floats, such
  as m2wr's sim_time, x, y, yaw, nearest, distance, command) in shared slots
  (info_slots.py). A step is: the learner writes the actions and posts each worker's "go"
  semaphore, each worker steps and posts its "done" semaphore. No pickling and no pipe on
  that path.
- After answering a step or reset, a worker calls its environment's run_ahead() when it
  has one (env.unwrapped.run_ahead; run_ahead=False: never): m2wr's runs the physics of the
  next step that no action can change (up to its drive's next command reading), in the time
  the worker would otherwise wait for the slower worker and the learner. What the next step
  returns is unchanged to the bit. An error it raises is reported as the next step's.
- Each worker also has a pipe, used only when something is rare: reset (seeds, options),
  call / get_attr / set_attr, close, and from the worker: an info whose keys or kinds
  changed, info values that do not fit a slot (touched model names, final_obs/final_info
  at an episode's end in SAME_STEP mode, nested dicts), and errors.
- An exception in a sub-environment's reset or step is caught in its worker, which keeps the
  environment; the learner raises SubEnvironmentError naming the sub-environment, its
  worker's PID, the call and its input, with the original exception as __cause__. The other
  sub-environments have stepped: their results are in the error's `.result`, and the next
  step goes on from there (the failed one's environment is as the failed call left it).
- A worker that dies (killed, crashed) is noticed while waiting (liveness checked every
  0.2 s): WorkerDiedError names it; the vector env is then broken, close() still works.
- close() asks every worker to close its environment and exit, joins it by PID (5 s), then
  terminates (and kills) what is left. Workers block SIGINT from their first instruction,
  so a Ctrl-C reaches the learner alone, which closes them.
- Workers wait for "go", and the learner for each worker's "done", spinning for `spin`
  seconds (non-blocking tries of the semaphore, yielding the core to any other runnable
  thread) before they block on it; `pin=True` pins worker i to the i-th core this process
  may use (the learner floats). Both are off by default: spinning pays only where every
  process has a core of its own (local=True, two environments, two cores), and pinning
  lost on this shared machine (see the README).
- timing_report(): the measured wake-ups and the workers' step times, [us] per step.
"""
import contextlib
import ctypes
import multiprocessing
import os
import signal
import time
import traceback

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import CloudpickleWrapper, batch_space

from .info_slots import MAX_SLOTS, decode_info, encode_info, merge_plan, merge_same_layout

__all__ = ["SharedMemoryVectorEnv", "SubEnvironmentError", "WorkerDiedError", "children_ignore_ctrl_c"]

LIVENESS = 0.2           # [s] between checks that a waited-for worker is still alive
CLOSE_JOIN = 5.0         # [s] a worker is given to exit after "close" before terminate

# command (learner -> worker), in shared memory
STEP, MESSAGE = 0, 1
# status (worker -> learner), in shared memory: the step's results are all in the shared
# arrays, or a pipe message follows
PLAIN, FOLLOWS = 0, 1


@contextlib.contextmanager
def children_ignore_ctrl_c():
    """Processes started inside have SIGINT blocked for good (they inherit the signal mask),
    so a Ctrl-C reaches this process alone, which then closes them and no worker prints a
    traceback; a Ctrl-C pressed meanwhile is delivered here as the block ends."""
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


class SubEnvironmentError(RuntimeError):
    """A sub-environment raised in its worker; the worker and its environment go on.
    index, pid, call ("step" or "reset"), given (repr of the action or arguments),
    error_type (the original exception's class name), remote_traceback, result (the
    step's return with the failed sub-environments masked out: observation as before,
    reward 0, flags False, no info)."""

    def __init__(self, message, index, pid, call, given, error_type, remote_traceback):
        super().__init__(message)
        self.index, self.pid, self.call, self.given = index, pid, call, given
        self.error_type, self.remote_traceback = error_type, remote_traceback
        self.result = None


class WorkerDiedError(RuntimeError):
    """A worker process ended while it was expected to answer."""


class _RemoteError(Exception):
    """Stands for an exception that could not be pickled back from a worker."""


def _shared_array(ctx, dtype, shape):
    dtype = np.dtype(dtype)
    size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    return (ctx.RawArray(ctypes.c_uint8, max(size, 1)), dtype.str, tuple(shape))


def _view(shared):
    raw, dtype, shape = shared
    count = int(np.prod(shape, dtype=np.int64))
    return np.frombuffer(raw, dtype=np.dtype(dtype), count=count).reshape(shape)


def _fixed_shape_space(space, what):
    if not isinstance(space, (spaces.Box, spaces.Discrete, spaces.MultiDiscrete,
                              spaces.MultiBinary)):
        raise ValueError("SharedMemoryVectorEnv needs a Box, Discrete, MultiDiscrete or "
                         "MultiBinary %s space (fixed shape and dtype); got %r: use "
                         "gymnasium.vector.AsyncVectorEnv for this environment" % (what, space))
    return space


def _poll(semaphore, spin):
    """Tries to take `semaphore` without blocking for up to `spin` seconds, yielding the
    core to any other runnable thread between tries: True once taken, False at the end."""
    if spin > 0:
        deadline = time.perf_counter() + spin
        while True:
            if semaphore.acquire(False):
                return True
            if time.perf_counter() > deadline:
                break
            os.sched_yield()
    return False


# --- the worker ----------------------------------------------------------------------------
def _wait_go(go, spin, learner):
    """Takes the "go" semaphore: polls for `spin` seconds (_poll), then blocks; exits if
    the learner (a multiprocessing parent_process(), whatever the start method) is gone."""
    if _poll(go, spin):
        return
    while not go.acquire(True, 1.0):
        if learner is not None and not learner.is_alive():
            os._exit(0)                      # the learner died without closing us


class _Runner:
    """One sub-environment's side of a step or reset: runs it (autoreset included) and
    writes what it returns into the shared arrays at `index`; gives the info's (layout,
    extras) or raises what the environment raised. Used by the workers, and by the
    learner's process for the sub-environment it steps itself (local=True)."""

    def __init__(self, env, index, views, autoreset_mode):
        self.env, self.index, self.mode = env, index, autoreset_mode
        (self.actions, self.observations, self.rewards, self.terminations,
         self.truncations) = views[:5]
        self.row = views[7][index]
        self.scalar_action = self.actions.ndim == 1
        self.autoreset = False

    def shared_action(self):
        i = self.index
        return self.actions[i] if self.scalar_action else self.actions[i].copy()

    def step(self, action):
        env, i = self.env, self.index
        if self.mode is AutoresetMode.NEXT_STEP and self.autoreset:
            observation, info = env.reset()
            reward, terminated, truncated = 0.0, False, False
        else:
            observation, reward, terminated, truncated, info = env.step(action)
            if self.mode is AutoresetMode.SAME_STEP and (terminated or truncated):
                reset_observation, reset_info = env.reset()
                info = {"final_info": info, "final_obs": observation, **reset_info}
                observation = reset_observation
        self.autoreset = terminated or truncated
        self.rewards[i] = reward
        self.terminations[i] = terminated
        self.truncations[i] = truncated
        self.observations[i] = observation
        return encode_info(info, self.row)

    def reset(self, kwargs):
        observation, info = self.env.reset(**kwargs)
        self.autoreset = False
        self.observations[self.index] = observation
        return encode_info(info, self.row)


def _given(call, action, kwargs):
    """The input of a failed call, for its error message."""
    if call == "step":
        return repr(action)
    return "reset(%s)" % ", ".join("%s=%r" % item for item in kwargs.items())


def _worker(index, env_fn, pipe, parent_pipe, shared, go, done, autoreset_mode, spin, cpu,
            run_ahead):
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})     # Ctrl-C is the learner's
    parent_pipe.close()
    learner = multiprocessing.parent_process()
    if cpu is not None:
        try:
            os.sched_setaffinity(0, {cpu})
        except OSError:
            pass
    try:
        env = env_fn()
    except Exception as err:                 # reported by the learner's constructor
        pipe.send(("error", _error_payload(err, "make", "the environment function")))
        return
    views = [_view(s) for s in shared]
    runner = _Runner(env, index, views, autoreset_mode)
    command, status, clock = views[5], views[6], views[8][index]
    now, cpu_now = time.perf_counter, time.thread_time
    pipe.send(("ready", None))
    sent_layout = None
    ahead = getattr(env.unwrapped, "run_ahead", None) if run_ahead else None
    ahead_error = None
    try:
        while True:
            _wait_go(go, spin, learner)
            clock[1] = now()
            cpu_started = cpu_now()
            message = None if command[index] == STEP else pipe.recv()
            call = "step" if message is None else message[0]
            if call == "close":
                break
            if call not in ("step", "reset"):             # call / setattr / apply
                answer = _answer(env, message)
                status[index] = FOLLOWS
                done.release()
                pipe.send(("result", answer))
                continue
            action = None
            try:
                if call == "step":
                    # (through the pipe: an action the shared array cannot hold as given)
                    action = runner.shared_action() if message is None else message[1]
                    if ahead_error is not None:
                        raise ahead_error
                    layout, extras = runner.step(action)
                else:
                    layout, extras = runner.reset(message[1])
            except Exception as err:
                status[index] = FOLLOWS
                done.release()
                pipe.send(("error", _error_payload(
                    err, call, _given(call, action, message and message[1]))))
                continue
            finally:
                ahead_error = None
            clock[2] = now()
            clock[3] = cpu_now() - cpu_started
            if layout == sent_layout and extras is None:
                status[index] = PLAIN
                done.release()
            else:
                status[index] = FOLLOWS
                done.release()
                pipe.send(("info", None if layout == sent_layout else layout, extras))
                sent_layout = layout
            if ahead is not None:
                cpu_started = cpu_now()
                try:
                    ahead()
                except Exception as err:         # reported as the next step's error
                    ahead_error = err
                clock[4] = cpu_now() - cpu_started
    finally:
        env.close()


def _answer(env, message):
    call = message[0]
    try:
        if call == "call":
            name, args, kwargs = message[1:]
            attribute = env.get_wrapper_attr(name)
            return ("ok", attribute(*args, **kwargs) if callable(attribute) else attribute)
        if call == "setattr":
            env.set_wrapper_attr(message[1], message[2])
            return ("ok", None)
        if call == "apply":
            function, args = message[1:]
            return ("ok", function(env, *args))
        raise ValueError("unknown message %r" % (call,))
    except Exception as err:
        return ("error", _error_payload(err, call, repr(message[1:])))


def _error_payload(err, call, given):
    import pickle
    try:
        pickled = pickle.dumps(err)
        pickle.loads(pickled)
    except Exception:
        pickled = None
    return {"call": call, "given": given, "type": type(err).__name__, "message": str(err),
            "pickled": pickled, "traceback": traceback.format_exc()}


# --- the learner's side ----------------------------------------------------------------------
class SharedMemoryVectorEnv(VectorEnv):
    """`env_fns`: functions that make the sub-environments (all with the same spaces).
    autoreset_mode: NEXT_STEP (default), SAME_STEP or DISABLED, as AsyncVectorEnv.
    context: multiprocessing start method (None: its default, as AsyncVectorEnv; "spawn" and
    "forkserver" need the main module importable, `if __name__ == "__main__":`).
    spin [s]: how long a worker polls for the next step, and the learner for a worker's
    results, before blocking (0: always block). A sleeping process costs its waker a wake-up
    (17 us of CPU in this VM) and its caches; polling instead pays where each process has a
    core of its own, as with local=True and two environments on two cores, and loses where
    the learner is a third process (it takes a worker's core).
    pin: pin worker i to the i-th core this process may use (round robin).
    local: this (the learner's) process steps sub-environment 0 itself, while the workers
    step the others: one process fewer to wake and to schedule; errors, results and infos as
    with a worker (its "worker pid" is this process's).
    copy: return copies of the observations (True), or the shared array itself.
    run_ahead: after each step or reset, a worker calls its environment's run_ahead() if it
    has one (env.unwrapped.run_ahead: m2wr's runs the physics of the next step that no
    action can change), while the learner and the other workers finish theirs."""

    def __init__(self, env_fns, autoreset_mode=AutoresetMode.NEXT_STEP, context=None,
                 spin=0.0, pin=False, local=False, copy=True, run_ahead=True):
        self.env_fns = list(env_fns)
        self.num_envs = len(self.env_fns)
        if self.num_envs < 1:
            raise ValueError("SharedMemoryVectorEnv needs at least one environment function")
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        self.copy = copy
        self.spin = float(spin)
        self.processes = []                    # the workers' multiprocessing.Process
        self._process, self._pipes = {}, {}    # by sub-environment index
        self._local = None                     # the _Runner of sub-environment 0 if local
        self._local_message = None             # what it is to do next (None: step)
        self._broken = None
        self._pending = None
        self.closed = False
        dummy = self.env_fns[0]()
        try:
            self.metadata = dict(dummy.metadata, autoreset_mode=self.autoreset_mode)
            self.render_mode = dummy.render_mode
            self.single_observation_space = _fixed_shape_space(dummy.observation_space,
                                                               "observation")
            self.single_action_space = _fixed_shape_space(dummy.action_space, "action")
        finally:
            if not local:
                dummy.close()
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        ctx = multiprocessing.get_context(context)
        n = self.num_envs
        obs, act = self.single_observation_space, self.single_action_space
        shared = [_shared_array(ctx, act.dtype, (n,) + tuple(act.shape)),
                  _shared_array(ctx, obs.dtype, (n,) + tuple(obs.shape)),
                  _shared_array(ctx, np.float64, (n,)),
                  _shared_array(ctx, np.bool_, (n,)),
                  _shared_array(ctx, np.bool_, (n,)),
                  _shared_array(ctx, np.int32, (n,)),
                  _shared_array(ctx, np.int32, (n,)),
                  _shared_array(ctx, np.float64, (n, MAX_SLOTS)),
                  _shared_array(ctx, np.float64, (n, 5))]
        views = [_view(s) for s in shared]
        (self._actions, self._observations, self._rewards, self._terminations,
         self._truncations, self._command, self._status, self._slots, self._clock) = views
        if local:
            self._local = _Runner(dummy, 0, views, self.autoreset_mode)
        self._workers = list(range(1 if local else 0, n))
        self._go = [ctx.Semaphore(0) for _ in range(n)]
        self._done = [ctx.Semaphore(0) for _ in range(n)]
        self._layouts = [None] * n
        self._extras = [None] * n
        self._plan = None               # (layout, merge plan, slots used) of the last merge
        self.reset_timing()
        cores = sorted(os.sched_getaffinity(0))
        try:
            with children_ignore_ctrl_c():
                for i in self._workers:
                    env_fn = self.env_fns[i]
                    parent_pipe, child_pipe = ctx.Pipe()
                    cpu = cores[i % len(cores)] if pin else None
                    process = ctx.Process(
                        target=_worker, name="SharedMemoryVectorEnv-%d" % i, daemon=True,
                        args=(i, CloudpickleWrapper(env_fn), child_pipe, parent_pipe, shared,
                              self._go[i], self._done[i], self.autoreset_mode,
                              float(spin), cpu, run_ahead))
                    process.start()
                    child_pipe.close()
                    self.processes.append(process)
                    self._process[i], self._pipes[i] = process, parent_pipe
            for i in self._workers:
                kind, payload = self._receive(i, "start")
                if kind == "error":
                    raise self._error(i, payload)
        except BaseException:
            self.close(terminate=True)
            raise

    # --- waiting, with liveness checks ----------------------------------------------------
    def _died(self, i, during):
        process = self._process[i]
        process.join(0.1)
        code = process.exitcode
        how = ("killed by %s" % signal.Signals(-code).name if code is not None and code < 0
               else "exit code %s" % code)
        self._broken = WorkerDiedError(
            "SharedMemoryVectorEnv: sub-environment %d's worker (pid %d) died during %s (%s); "
            "close() this vector env and make a new one%s"
            % (i, process.pid, during, how,
               " (its traceback, if any, is on stderr above)" if during == "start" else ""))
        return self._broken

    def _wait_done(self, i, during):
        done, process = self._done[i], self._process[i]
        if _poll(done, self.spin):
            return
        while not done.acquire(True, LIVENESS):
            if not process.is_alive():
                raise self._died(i, during)

    def _receive(self, i, during):
        pipe, process = self._pipes[i], self._process[i]
        while not pipe.poll(LIVENESS):
            if not process.is_alive() and not pipe.poll(0):
                raise self._died(i, during)
        try:
            return pipe.recv()
        except (EOFError, OSError):
            raise self._died(i, during) from None

    def _error(self, i, payload):
        cause = None
        if payload["pickled"] is not None:
            import pickle
            cause = pickle.loads(payload["pickled"])
        else:
            cause = _RemoteError("%s: %s" % (payload["type"], payload["message"]))
        pid = self._process[i].pid if i in self._process else os.getpid()
        error = SubEnvironmentError(
            "sub-environment %d (%s pid %d) raised %s in %s, given %s: %s"
            % (i, "worker" if i in self._process else "the learner's process,", pid,
               payload["type"], payload["call"], payload["given"], payload["message"]),
            i, pid, payload["call"], payload["given"], payload["type"], payload["traceback"])
        error.__cause__ = cause
        return error

    def _check_usable(self):
        if self.closed:
            from gymnasium.error import ClosedEnvironmentError
            raise ClosedEnvironmentError("SharedMemoryVectorEnv: used after close()")
        if self._broken is not None:
            raise self._broken
        if self._pending is not None:
            raise RuntimeError("SharedMemoryVectorEnv: a %s was interrupted; close() it"
                               % self._pending)

    def _post(self, i, message=None):
        if i not in self._process:               # the learner's own: run in _collect
            self._local_message = message
            return
        if message is None:
            self._command[i] = STEP
        else:
            self._command[i] = MESSAGE
            try:
                self._pipes[i].send(message)
            except OSError:
                raise self._died(i, message[0]) from None
        self._clock[i, 0] = time.perf_counter()
        self._go[i].release()

    def _collect(self, which, during):
        """Runs the learner's own sub-environment if it is in `which` (while the workers,
        posted already, run theirs), waits for the workers in `which`, then reads what they
        sent through their pipes: (errors as SubEnvironmentError, {index: call's answer})."""
        errors, answers = [], {}
        if self._local is not None and 0 in which:
            self._run_local(errors, answers)
        which = [i for i in which if i in self._process]
        for i in which:
            self._wait_done(i, during)
        if during == "step" and which:
            self._time(which)
        for i in which:
            if self._status[i] == FOLLOWS:
                kind, *rest = self._receive(i, during)
                if kind == "info":
                    layout, extras = rest
                    if layout is not None:
                        self._layouts[i] = layout
                    self._extras[i] = extras
                elif kind == "error":
                    errors.append(self._error(i, rest[0]))
                elif kind == "result":
                    answers[i] = rest[0]
            else:
                self._extras[i] = None
        return errors, answers

    def _run_local(self, errors, answers):
        runner, message = self._local, self._local_message
        call = "step" if message is None else message[0]
        if call not in ("step", "reset"):
            answers[0] = _answer(runner.env, message)
            return
        action = None
        try:
            if call == "step":
                action = runner.shared_action() if message is None else message[1]
                self._layouts[0], self._extras[0] = runner.step(action)
            else:
                self._layouts[0], self._extras[0] = runner.reset(message[1])
        except Exception as err:
            errors.append(self._error(0, _error_payload(
                err, call, _given(call, action, message and message[1]))))

    def _time(self, which):
        """Adds this step's clocks to the sums timing_report reads (one numpy sum: this runs
        on every step)."""
        returned = time.perf_counter()
        clock = self._clock[which] if len(which) < self.num_envs else self._clock
        self._clock_sums += clock.sum(axis=0)
        self._wake_sum += returned - clock[:, 2].max()
        self._timed_steps += 1
        self._timed_envs += len(clock)

    def timing_report(self):
        """Mean [us] per step since construction (or the last reset_timing()): go = from
        the learner's post to a worker running (wake-up; the end of its run-ahead when that
        is later); work = a worker's step, action read to results written (its reset on
        autoreset included), "work cpu" the CPU time of that; "ahead cpu" the CPU time of
        a worker's run-ahead; wake = from the last worker's post to the learner running."""
        posted, running, finished, work_cpu, ahead_cpu = self._clock_sums
        steps, envs = max(self._timed_steps, 1), max(self._timed_envs, 1)
        return {"go": (running - posted) / envs * 1e6, "work": (finished - running) / envs * 1e6,
                "work cpu": work_cpu / envs * 1e6, "ahead cpu": ahead_cpu / envs * 1e6,
                "wake": self._wake_sum / steps * 1e6}

    def reset_timing(self):
        self._clock_sums = np.zeros(self._clock.shape[1])
        self._wake_sum = 0.0
        self._timed_steps = self._timed_envs = 0

    def _info_list(self, which):
        return [decode_info(self._layouts[i], self._slots[i], self._extras[i]) for i in which]

    def _infos(self, which):
        layouts = [self._layouts[i] for i in which]
        if (len(which) == self.num_envs and all(l is layouts[0] or l == layouts[0] for l in layouts)
                and all(self._extras[i] is None for i in which)):
            if self._plan is None or self._plan[0] != layouts[0]:
                self._plan = (layouts[0],) + merge_plan(layouts[0])
            return merge_same_layout(self._plan[1], self._plan[2], self._slots)
        infos = {}
        for i in which:
            infos = self._add_info(infos, decode_info(self._layouts[i], self._slots[i],
                                                       self._extras[i]), i)
        return infos

    def _returned_observations(self):
        return self._observations.copy() if self.copy else self._observations

    # --- gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        self._check_usable()
        n = self.num_envs
        if seed is None:
            seeds = [None] * n
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError("reset(seed=%r): give one seed or a list of %d" % (seed, n))
        options = dict(options) if options is not None else None
        mask = None
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options.pop("reset_mask"))
            if mask.shape != (n,) or mask.dtype != np.bool_ or not mask.any():
                raise ValueError("reset options reset_mask: give a bool array of shape (%d,) "
                                 "with at least one True" % n)
        which = [i for i in range(n) if mask is None or mask[i]]
        self._reset(which, seeds, [options] * n)
        return self._returned_observations(), self._infos(which)

    def reset_each(self, seeds, options):
        """Resets every sub-environment i with seeds[i] and options[i] (a dict or None):
        (observations, [info of each])."""
        self._check_usable()
        which = range(self.num_envs)
        self._reset(which, list(seeds), list(options))
        return self._returned_observations(), self._info_list(which)

    def _reset(self, which, seeds, options):
        self._pending = "reset"
        for i in which:
            self._post(i, ("reset", {"seed": seeds[i], "options": options[i]}))
        errors, _ = self._collect(which, "reset")
        self._pending = None
        if errors:
            raise errors[0]

    def step(self, actions):
        self._step(actions)
        return (self._returned_observations(), self._rewards.copy(), self._terminations.copy(),
                self._truncations.copy(), self._infos(range(self.num_envs)))

    def step_each(self, actions):
        """As step(), with the infos as a list of each sub-environment's info dict (as
        stable-baselines3 wants them) instead of merged arrays."""
        self._step(actions)
        return (self._returned_observations(), self._rewards.copy(), self._terminations.copy(),
                self._truncations.copy(), self._info_list(range(self.num_envs)))

    def _step(self, actions):
        self._check_usable()
        n = self.num_envs
        batch = np.asarray(actions)
        fits = batch.dtype == self._actions.dtype and batch.shape == self._actions.shape
        if fits:
            self._actions[...] = batch
        elif len(batch) != n:
            raise ValueError("step: %d actions for %d sub-environments" % (len(batch), n))
        self._pending = "step"
        for i in range(n):
            # an action the shared array would have to cast goes as given, through the pipe
            self._post(i, None if fits else ("step", actions[i]))
        errors, _ = self._collect(range(n), "step")
        self._pending = None
        if errors:
            failed = {error.index for error in errors}
            ok = [i for i in range(n) if i not in failed]
            rewards, terminations, truncations = (self._rewards.copy(),
                                                  self._terminations.copy(),
                                                  self._truncations.copy())
            for i in failed:
                rewards[i], terminations[i], truncations[i] = 0.0, False, False
            errors[0].result = (self._observations.copy(), rewards, terminations, truncations,
                                self._infos(ok))
            if len(errors) > 1:
                errors[0].args = (errors[0].args[0] + "; and: " + "; ".join(
                    str(e) for e in errors[1:]),)
            raise errors[0]

    def call(self, name, *args, **kwargs):
        """env.name(*args, **kwargs) in every sub-environment (or env.name when not
        callable), through its wrappers: a tuple of the results."""
        return self._ask({i: ("call", name, args, kwargs) for i in range(self.num_envs)})

    def call_at(self, indices, name, *args, **kwargs):
        """As call(), in the sub-environments `indices` only: their results, in that order."""
        return self._ask({i: ("call", name, args, kwargs) for i in indices})

    def get_attr(self, name):
        return self.call(name)

    def set_attr(self, name, values):
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError("set_attr(%r): give one value or %d" % (name, self.num_envs))
        self._ask({i: ("setattr", name, value) for i, value in enumerate(values)})

    def set_attr_at(self, indices, name, value):
        self._ask({i: ("setattr", name, value) for i in indices})

    def apply(self, function, *args, indices=None):
        """function(env, *args) in every worker (or those `indices`), `function` picklable
        (a module's function): a tuple of its results."""
        indices = range(self.num_envs) if indices is None else indices
        return self._ask({i: ("apply", function, args) for i in indices})

    def render(self):
        return self.call("render")

    def _ask(self, messages):
        """Sends messages[i] to worker i, waits for those workers: their answers in order."""
        self._check_usable()
        which = list(messages)
        self._pending = "call"
        for i in which:
            self._post(i, messages[i])
        errors, answers = self._collect(which, "call")
        self._pending = None
        results = []
        for i in which:
            kind, value = answers[i]
            if kind == "error":
                errors.append(self._error(i, value))
            results.append(value)
        if errors:
            raise errors[0]
        return tuple(results)

    def close_extras(self, terminate=False, **kwargs):
        """Each worker: "close" (its env closes, it exits), joined by PID for CLOSE_JOIN s;
        then terminate, then kill; the learner's own sub-environment (local) closes here.
        `terminate`: skip the polite part."""
        if self._pending is not None and not terminate and self._broken is None:
            try:                               # a step cut short (Ctrl-C): let it finish
                for i in self._process:
                    if not self._done[i].acquire(True, 2.0):
                        terminate = True
                    elif self._status[i] == FOLLOWS and self._pipes[i].poll(2.0):
                        self._pipes[i].recv()
            except (EOFError, OSError):
                terminate = True
            self._pending = None
        for i, process in self._process.items():
            if not terminate and process.is_alive():
                try:
                    self._post(i, ("close",))
                except (OSError, ValueError, WorkerDiedError):
                    pass
        for process in self.processes:
            process.join(0 if terminate else CLOSE_JOIN)
            if process.is_alive():
                process.terminate()
                process.join(2.0)
            if process.is_alive():
                process.kill()
                process.join()
        for pipe in self._pipes.values():
            pipe.close()
        if self._local is not None:
            self._local.env.close()

    def close(self, **kwargs):
        if self.closed:
            return
        try:
            self.close_extras(**kwargs)
        finally:
            self.closed = True

    def __del__(self):
        if not getattr(self, "closed", True) and hasattr(self, "_process"):
            self.close(terminate=True)

    def __repr__(self):
        return "SharedMemoryVectorEnv(num_envs=%d)" % self.num_envs
