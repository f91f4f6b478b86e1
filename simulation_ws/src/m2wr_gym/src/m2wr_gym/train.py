"""Train a policy with stable-baselines3 (PPO, or DQN) and export it as a numpy .npz that the
ROS node motion_plan/learned_avoidance.py runs (see policy.py). Run through scripts/train.sh,
which installs the training extra (requirements-train.txt: torch CPU, stable-baselines3) on
first use.

Prints progress every --report-every timesteps (episodes, mean return and length, env steps
per second, time left); writes OUT/policy.npz, OUT/learning_curve.png, OUT/model.zip (the
SB3 model, to go on training) and OUT/N.monitor.csv (one row per episode per environment).
Observations are multiplied by 1/10 before the network (obs_scale in the .npz), so the
network sees values in [0, 1]. With --envs > 1 the environments run in m2wr_gym's
shared-memory vector env (sb3_vector.py; the same episodes and results as SB3's
SubprocVecEnv, which --vec-env subproc picks): in worker processes, the first one in this
process when there are no more environments than cores (--vec-env workers: all in workers).
"""
import argparse
import csv
import math
import os
import sys
import time

import numpy as np


EXAMPLES = """examples:
  scripts/train.sh                                  # avoid, world02, PPO, 2 envs
  scripts/train.sh --timesteps 20000 --out /tmp/x   # a quick try
  scripts/train.sh --task goal --observation scan --downsample 8

Exit status: 0 when the policy was written; 1 when training failed; 2 for bad arguments."""


class HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """The tools' --help convention (scripts/m2wr_tools/usage.py, which this library may not
    import): the text as written, `(default: X)` after each option's help."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "(default" in text or action.default is None or action.default is False \
                or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="scripts/train.sh", description=__doc__.strip(),
                                epilog=EXAMPLES, formatter_class=HelpFormatter)
    p.add_argument("--task", default="avoid", choices=("avoid", "goal"),
                   help="avoid: drive without touching anything (episode 5's task); goal: "
                   "reach a goal drawn each episode")
    p.add_argument("--world", default="world02", help="world01, world02 or a .world path")
    p.add_argument("--algo", default="ppo", choices=("ppo", "dqn"),
                   help="stable-baselines3's algorithm")
    p.add_argument("--timesteps", type=int, default=300000, help="environment steps in all")
    p.add_argument("--envs", type=int, default=2, help="environments (1: in this process; "
                   "more: in workers, the first here when they fit the cores)")
    p.add_argument("--vec-env", default="shared", choices=("shared", "workers", "subproc"),
                   help="with --envs > 1: m2wr_gym's shared-memory vector env (sb3_vector.py; "
                        "the first env in this process when the envs fit the cores), the same "
                        "with every env in a worker (on a machine busy with other programs), "
                        "or SB3's SubprocVecEnv")
    p.add_argument("--observation", default="regions", choices=("regions", "scan"),
                   help="regions: episode 4's five, as reading_laser.py computes them; scan: "
                   "the 720 beams")
    p.add_argument("--downsample", type=int, default=1,
                   help="with --observation scan: the minimum of each group of this many "
                   "beams (a divisor of 720)")
    p.add_argument("--episode-seconds", type=float, default=60.0,
                   help="sim time of a training episode [s]")
    p.add_argument("--seed", type=int, default=0,
                   help="seed of the algorithm and of the episodes' start poses")
    p.add_argument("--hidden", type=int, nargs="+", default=[64, 64],
                   help="MLP layer sizes (default: 64 64)")
    p.add_argument("--out", default=os.path.join(os.environ.get("M2WR_ROOT", "."), "output",
                                                 "train"),
                   help="output folder (default: output/train)")
    p.add_argument("--report-every", type=int, default=10000, help="timesteps between lines")
    args = p.parse_args(argv)
    if args.timesteps < 1 or args.envs < 1:
        p.error("--timesteps and --envs must be >= 1")
    return args


def env_kwargs(args):
    """Training episodes start from free poses drawn anew each episode (so the policy does
    not learn one path), discrete actions (forward / left / right)."""
    kwargs = dict(task=args.task, world=args.world, start="random", observation=args.observation,
                  action="discrete", max_episode_seconds=args.episode_seconds)
    if args.observation == "scan":
        kwargs["downsample"] = args.downsample
    return kwargs


OBS_SCALE = 0.1          # [1/m]
SPIN = 0.002             # [s] the shared-memory vector env's polling when each side has a core


def make_env(kwargs, monitor_path=None):
    def build():
        import gymnasium
        from gymnasium.wrappers import TransformObservation
        from stable_baselines3.common.monitor import Monitor
        import m2wr_gym  # noqa: F401  (registers the ids)
        env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", **kwargs)
        space = env.observation_space
        scaled = type(space)(space.low * OBS_SCALE, space.high * OBS_SCALE, dtype=space.dtype)
        env = TransformObservation(env, lambda o: (o * OBS_SCALE).astype(np.float32), scaled)
        return Monitor(env, monitor_path)
    return build


def export(model, kwargs, args, dt, path):
    """The SB3 model's deterministic policy as a NumpyPolicy .npz (argmax of the logits)."""
    import torch
    from . import actions
    from .policy import NumpyPolicy
    layers = []
    if args.algo == "ppo":
        modules = list(model.policy.mlp_extractor.policy_net) + [model.policy.action_net]
    else:
        modules = list(model.q_net.q_net)
    for module in modules:
        if isinstance(module, torch.nn.Linear):
            layers.append((module.weight.detach().cpu().numpy(), module.bias.detach().cpu().numpy()))
        elif not isinstance(module, (torch.nn.Tanh, torch.nn.ReLU)):
            raise RuntimeError("cannot export layer %r" % module)
    activation = "tanh" if any(isinstance(m, torch.nn.Tanh) for m in modules) else "relu"
    if activation != "tanh":
        raise RuntimeError("the .npz format runs tanh MLPs; train with activation tanh")
    n_in = layers[0][0].shape[1]
    policy = NumpyPolicy(layers, np.full(n_in, OBS_SCALE), actions.discrete_table("gazebo"),
                         kwargs["observation"], kwargs.get("downsample", 1), dt,
                         meta={"task": kwargs["task"], "world": str(kwargs["world"]),
                               "turning": "gazebo"}, source=path)
    policy.save(path)
    return policy


def read_monitor(paths):
    """(timestep at episode end, return) of every episode, in order of wall time."""
    rows = []
    for path in paths:
        if not os.path.exists(path):
            continue
        with open(path) as f:
            next(f)                                   # the JSON header line
            for row in csv.DictReader(f):
                rows.append((float(row["t"]), int(row["l"]), float(row["r"])))
    rows.sort()
    steps = np.cumsum([r[1] for r in rows])
    return steps, np.array([r[2] for r in rows])


def duration(seconds):
    """A wall time for a title: seconds under a minute, else minutes ("17 s", "49 min")."""
    return "%.0f s" % seconds if seconds < 59.5 else "%.0f min" % (seconds / 60.0)


def plot_curve(steps, returns, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.5), dpi=100)
    ax.plot(steps, returns, ".", ms=2, alpha=0.3, color="tab:blue", label="episode return")
    if len(returns) >= 5:
        window = max(5, len(returns) // 30)
        smooth = np.convolve(returns, np.ones(window) / window, mode="valid")
        ax.plot(steps[window - 1:], smooth, color="tab:blue", lw=2, label="mean of %d" % window)
    ax.set_xlabel("environment steps")
    ax.set_ylabel("return")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv=None):
    args = parse_args(argv)
    try:
        import torch
        from stable_baselines3 import DQN, PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv
    except ImportError as err:
        sys.stderr.write("train: %s; run scripts/train.sh, which installs "
                         "requirements-train.txt first\n" % err)
        return 2
    torch.set_num_threads(1)                 # 2 shared cores: the envs need them more
    os.makedirs(args.out, exist_ok=True)
    kwargs = env_kwargs(args)
    from .env import M2wrEnv
    probe = M2wrEnv(**kwargs)                # checks the options before any process starts
    dt = probe.dt
    probe.close()
    monitors = [os.path.join(args.out, "%d.monitor.csv" % i) for i in range(args.envs)]
    builders = [make_env(kwargs, monitors[i]) for i in range(args.envs)]
    if args.envs == 1:
        venv = DummyVecEnv(builders)
    elif args.vec_env in ("shared", "workers"):
        from .sb3_vector import SharedMemoryVecEnv
        # forkserver, as SubprocVecEnv: workers are not forks of a process running torch.
        # With no more envs than cores, this process steps the first env itself and both
        # sides poll rather than sleep (each has a core): 1.15x the throughput of envs all
        # in workers on an idle machine, 0.93x with another program busy (README, Speed)
        fits = args.vec_env == "shared" and args.envs <= len(os.sched_getaffinity(0))
        venv = SharedMemoryVecEnv(builders, context="forkserver", local=fits,
                                  spin=SPIN if fits else 0.0)
    else:
        venv = SubprocVecEnv(builders)
    venv.seed(args.seed)
    hidden = list(args.hidden)
    if args.algo == "ppo":
        n_steps = max(64, min(1024, args.timesteps // args.envs))     # short runs: one rollout
        model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=256 if n_steps == 1024 else n_steps * args.envs,
                    n_epochs=10,
                    learning_rate=3e-4, gamma=0.99, gae_lambda=0.95, ent_coef=0.01,
                    policy_kwargs=dict(net_arch=dict(pi=hidden, vf=hidden),
                                       activation_fn=torch.nn.Tanh),
                    seed=args.seed, verbose=0, device="cpu")
    else:
        model = DQN("MlpPolicy", venv, learning_rate=5e-4, buffer_size=100000,
                    learning_starts=5000, exploration_fraction=0.3, target_update_interval=2000,
                    policy_kwargs=dict(net_arch=hidden, activation_fn=torch.nn.Tanh),
                    seed=args.seed, verbose=0, device="cpu")

    class Progress(BaseCallback):
        def __init__(self):
            super().__init__()
            self.started = time.monotonic()
            self.next_report = args.report_every

        def _on_step(self):
            # SB3 finishes its last rollout past `timesteps`: one line for the end, not one
            # per step of that rollout
            if self.num_timesteps >= self.next_report or (
                    self.num_timesteps >= args.timesteps and self.next_report < math.inf):
                self.next_report = math.inf if self.num_timesteps >= args.timesteps \
                    else self.next_report + args.report_every
                elapsed = time.monotonic() - self.started
                rate = self.num_timesteps / max(elapsed, 1e-9)
                _, returns = read_monitor(monitors)
                recent = returns[-50:]
                print("[train] %7d/%d steps  %4d episodes  mean return (last %d) %7.2f  "
                      "%5.0f steps/s  %5.0f s elapsed, ~%4.0f s left"
                      % (self.num_timesteps, args.timesteps, len(returns), len(recent),
                         recent.mean() if len(recent) else math.nan, rate, elapsed,
                         max(args.timesteps - self.num_timesteps, 0) / max(rate, 1e-9)),
                      flush=True)
            return True

    started = time.monotonic()
    print("[train] %s on %s in %s, %d environment(s), %d steps of %.2f s sim time; output %s"
          % (args.algo.upper(), args.task, args.world, args.envs, args.timesteps, dt, args.out),
          flush=True)
    try:
        model.learn(total_timesteps=args.timesteps, callback=Progress())
    except KeyboardInterrupt:
        print("[train] interrupted: exporting what was learned so far", flush=True)
    finally:
        venv.close()
    wall = time.monotonic() - started
    model_path = os.path.join(args.out, "model.zip")
    model.save(model_path)
    policy_path = os.path.join(args.out, "policy.npz")
    export(model, kwargs, args, dt, policy_path)
    steps, returns = read_monitor(monitors)
    curve = os.path.join(args.out, "learning_curve.png")
    plot_curve(steps, returns, curve, "%s %s, %s, %d steps in %s wall time"
               % (args.algo.upper(), args.task, args.world, int(steps[-1]) if len(steps) else 0,
                  duration(wall)))
    written = [policy_path, curve, model_path] + monitors
    print("[train] done in %.0f s; wrote %s" % (wall, ", ".join(written)), flush=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
