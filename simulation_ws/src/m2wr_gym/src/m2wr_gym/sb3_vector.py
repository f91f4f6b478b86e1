"""SharedMemoryVecEnv: SharedMemoryVectorEnv (shared_vector.py) seen as a stable-baselines3
VecEnv, in place of SB3's SubprocVecEnv (needs stable-baselines3, the training extra).

It gives what SubprocVecEnv gives: reset() -> observations (seeds from seed(), one per
environment), step -> (observations, rewards, dones, [info]) with done = terminated or
truncated, info["TimeLimit.truncated"] on every step, and at an episode's end the ended
episode's info with info["terminal_observation"], the observation returned being the next
episode's first (the vector env runs in SAME_STEP autoreset mode); reset_infos holds each
environment's last reset info.
"""
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from .shared_vector import SharedMemoryVectorEnv


def _is_wrapped(env, wrapper_class):
    while env is not None:
        if isinstance(env, wrapper_class):
            return True
        env = getattr(env, "env", None)
    return False


class SharedMemoryVecEnv(VecEnv):
    """`env_fns`: functions that make the environments; `options`: SharedMemoryVectorEnv's."""

    def __init__(self, env_fns, **options):
        self.vector = SharedMemoryVectorEnv(env_fns, autoreset_mode=AutoresetMode.SAME_STEP,
                                            **options)
        super().__init__(len(env_fns), self.vector.single_observation_space,
                         self.vector.single_action_space)
        self._actions = None

    @property
    def processes(self):
        return self.vector.processes

    def reset(self):
        options = [dict(o) if o else None for o in self._options]
        observations, self.reset_infos = self.vector.reset_each(self._seeds, options)
        self._reset_seeds()
        self._reset_options()
        return observations

    def step_async(self, actions):
        self._actions = actions

    def step_wait(self):
        observations, rewards, terminated, truncated, infos = self.vector.step_each(self._actions)
        for i, info in enumerate(infos):
            if "final_obs" in info:
                ended = info.pop("final_info")
                ended["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
                ended["terminal_observation"] = info.pop("final_obs")
                self.reset_infos[i] = info
                infos[i] = ended
            else:
                info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return observations, rewards, terminated | truncated, infos

    def close(self):
        self.vector.close()

    def get_attr(self, attr_name, indices=None):
        return list(self.vector.call_at(self._get_indices(indices), attr_name))

    def set_attr(self, attr_name, value, indices=None):
        self.vector.set_attr_at(self._get_indices(indices), attr_name, value)

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        return list(self.vector.call_at(self._get_indices(indices), method_name, *method_args,
                                        **method_kwargs))

    def env_is_wrapped(self, wrapper_class, indices=None):
        return list(self.vector.apply(_is_wrapped, wrapper_class,
                                      indices=self._get_indices(indices)))

    def get_images(self):
        return list(self.vector.render())
