"""Gymnasium environments for m2wr on the pybullet stand-in (see env.py and options.py).

    import gymnasium
    env = gymnasium.make("m2wr_gym:M2wrAvoid-v0")            # episode 5's task, world02
    env = gymnasium.make("m2wr_gym:M2wrGoal-v0", goal=(2, -3))
    env = gymnasium.make("m2wr_gym:M2wrAvoidRos-v0")         # a running simulator, lockstep

The ids register on import of this package (gymnasium imports it for the "m2wr_gym:" prefix).
"""
from gymnasium.envs.registration import register

_ENTRY = "m2wr_gym.env:M2wrEnv"

register(id="M2wrAvoid-v0", entry_point=_ENTRY, kwargs={"task": "avoid"})
register(id="M2wrGoal-v0", entry_point=_ENTRY, kwargs={"task": "goal"})
register(id="M2wrAvoidRos-v0", entry_point=_ENTRY, kwargs={"task": "avoid", "backend": "ros"})
register(id="M2wrGoalRos-v0", entry_point=_ENTRY, kwargs={"task": "goal", "backend": "ros"})
