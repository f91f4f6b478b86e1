"""A trained policy as a plain numpy file (.npz), run with numpy alone: what the ROS node
motion_plan/learned_avoidance.py loads, so the ROS side never imports torch.

File contents (all numpy arrays):
  format            "m2wr_gym.mlp/1"
  observation       "regions" | "scan";  downsample (int) for "scan"
  obs_scale         (n_in,) the observation is multiplied by it first
  W0, b0, ..., Wk, bk   layer weights, W_i of shape (out, in); tanh between layers
  actions           (n_actions, 2): the (linear.x [m/s], angular.z [rad/s]) of each discrete
                    action, as published on /cmd_vel; the policy picks the argmax
  control_period    [s] sim time between two decisions (the environment's dt)
  task, world, turning   what it was trained on (for the user; not checked)
"""
import numpy as np

FORMAT = "m2wr_gym.mlp/1"


class PolicyFileError(ValueError):
    """A policy file that cannot be run; the message names the file and what is wrong."""


class NumpyPolicy:
    def __init__(self, layers, obs_scale, actions, observation, downsample=1,
                 control_period=0.1, meta=None, source="(in memory)"):
        self.layers = [(np.asarray(w, dtype=np.float64), np.asarray(b, dtype=np.float64))
                       for w, b in layers]
        self.obs_scale = np.asarray(obs_scale, dtype=np.float64)
        self.actions = np.asarray(actions, dtype=np.float64)
        self.observation = str(observation)
        self.downsample = int(downsample)
        self.control_period = float(control_period)
        self.meta = dict(meta or {})
        self.source = source
        self._check()

    @property
    def input_size(self):
        return self.layers[0][0].shape[1]

    def _check(self):
        where = "policy file %s" % self.source
        if not self.layers:
            raise PolicyFileError("%s: no layers (W0, b0, ...)" % where)
        previous = None
        for i, (w, b) in enumerate(self.layers):
            if w.ndim != 2 or b.shape != (w.shape[0],):
                raise PolicyFileError("%s: layer %d has W%d %s and b%d %s; W must be (out, in) "
                                      "and b (out,)" % (where, i, i, w.shape, i, b.shape))
            if previous is not None and w.shape[1] != previous:
                raise PolicyFileError("%s: layer %d takes %d inputs but layer %d gives %d"
                                      % (where, i, w.shape[1], i - 1, previous))
            if not (np.all(np.isfinite(w)) and np.all(np.isfinite(b))):
                raise PolicyFileError("%s: layer %d holds NaN or inf" % (where, i))
            previous = w.shape[0]
        if self.obs_scale.shape != (self.input_size,):
            raise PolicyFileError("%s: obs_scale has shape %s; the first layer takes %d inputs"
                                  % (where, self.obs_scale.shape, self.input_size))
        if self.actions.ndim != 2 or self.actions.shape[1] != 2 \
                or self.actions.shape[0] != previous:
            raise PolicyFileError("%s: actions has shape %s; the last layer gives %d outputs, so "
                                  "(%d, 2) rows of (linear.x, angular.z) are needed"
                                  % (where, self.actions.shape, previous, previous))
        if self.observation not in ("regions", "scan"):
            raise PolicyFileError("%s: observation '%s' is neither regions nor scan"
                                  % (where, self.observation))
        if not self.control_period > 0.0:
            raise PolicyFileError("%s: control_period %s must be > 0 s"
                                  % (where, self.control_period))

    def scores(self, observation):
        x = np.asarray(observation, dtype=np.float64).reshape(-1)
        if x.shape != (self.input_size,):
            raise ValueError("observation of %d values given to %s, which takes %d (%s)"
                             % (x.size, self.source, self.input_size, self.observation))
        x = x * self.obs_scale
        for i, (w, b) in enumerate(self.layers):
            x = w @ x + b
            if i < len(self.layers) - 1:
                x = np.tanh(x)
        return x

    def act(self, observation):
        """Index of the discrete action for one observation."""
        return int(np.argmax(self.scores(observation)))

    def command(self, observation):
        """(linear.x [m/s], angular.z [rad/s]) to publish on /cmd_vel."""
        v, w = self.actions[self.act(observation)]
        return float(v), float(w)

    def save(self, path):
        arrays = {"format": np.array(FORMAT), "observation": np.array(self.observation),
                  "downsample": np.array(self.downsample), "obs_scale": self.obs_scale,
                  "actions": self.actions, "control_period": np.array(self.control_period)}
        for i, (w, b) in enumerate(self.layers):
            arrays["W%d" % i], arrays["b%d" % i] = w, b
        for key, value in self.meta.items():
            arrays[key] = np.array(value)
        with open(path, "wb") as f:          # np.savez would append .npz to other names
            np.savez(f, **arrays)


def load(path):
    """A NumpyPolicy from a .npz file; PolicyFileError naming the file when it is not one."""
    try:
        data = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise PolicyFileError("policy file %s not found; pass _policy:=FILE with a .npz "
                              "written by scripts/train.sh" % path) from None
    except Exception as err:
        raise PolicyFileError("policy file %s is not a numpy .npz archive (%s)" % (path, err)) \
            from None
    with data:
        keys = set(data.files)
        if "format" not in keys or str(data["format"]) != FORMAT:
            raise PolicyFileError("policy file %s: format is %s, expected %s (written by "
                                  "scripts/train.sh)" % (path, data["format"] if "format" in keys
                                                         else "missing", FORMAT))
        missing = [k for k in ("observation", "obs_scale", "actions", "W0", "b0")
                   if k not in keys]
        if missing:
            raise PolicyFileError("policy file %s lacks %s" % (path, ", ".join(missing)))
        layers, i = [], 0
        while "W%d" % i in keys:
            if "b%d" % i not in keys:
                raise PolicyFileError("policy file %s has W%d but no b%d" % (path, i, i))
            layers.append((data["W%d" % i], data["b%d" % i]))
            i += 1
        meta = {k: str(data[k]) for k in ("task", "world", "turning") if k in keys}
        return NumpyPolicy(layers, data["obs_scale"], data["actions"], str(data["observation"]),
                           int(data["downsample"]) if "downsample" in keys else 1,
                           float(data["control_period"]) if "control_period" in keys else 0.1,
                           meta, source=str(path))
