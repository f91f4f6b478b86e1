"""Action spaces and what each action publishes on /cmd_vel.

- "continuous": Box [(-0.6, -1.0), (0.6, 1.0)]: (linear.x [m/s], angular.z [rad/s]) exactly as
  published on /cmd_vel. Which way a positive angular.z turns m2wr is the drive's business
  (the `turning` option): with Gazebo's drive (the default) it turns m2wr clockwise.
- "discrete": openai_ros-style Discrete(3): 0 forward, 1 turn left, 2 turn right, as the robot
  sees it (left = counter-clockwise from above); the angular.z sign for "left" follows the
  `turning` option, so the same action index turns the robot the same way in both modes.

An action outside the space or with NaN is an error naming it (InvalidAction).
"""
import math

import numpy as np
from gymnasium import spaces

KINDS = ("continuous", "discrete")
MAX_LINEAR = 0.6            # [m/s] the tutorial's forward speed
MAX_ANGULAR = 1.0           # [rad/s]
FORWARD = (MAX_LINEAR, 0.0)  # [m/s], [rad/s]: the tutorial's 0.6 m/s (left is +angular in REP 103)
TURN = (0.1, 0.8)           # slow forward while turning, as openai_ros's turtlebot does
NAMES = ("forward", "left", "right")
TURNINGS = ("gazebo", "legacy")


class InvalidAction(ValueError):
    """An action the environment cannot take; the message names it."""


def left_sign(turning):
    """angular.z sign that turns m2wr counter-clockwise: Gazebo's diff drive applies its
    formula to the joints as named and m2wr's 'right' joint sits on its left, so -1; Kinetic's
    legacyMode swapped the formulas: +1."""
    return -1.0 if turning == "gazebo" else 1.0


def discrete_table(turning):
    """(3, 2) rows of (linear.x, angular.z) for forward, left, right."""
    s = left_sign(turning)
    return np.array([FORWARD, (TURN[0], s * TURN[1]), (TURN[0], -s * TURN[1])], dtype=np.float64)


def space(kind):
    if kind == "discrete":
        return spaces.Discrete(len(NAMES))
    return spaces.Box(low=np.array([-MAX_LINEAR, -MAX_ANGULAR], dtype=np.float32),
                      high=np.array([MAX_LINEAR, MAX_ANGULAR], dtype=np.float32),
                      dtype=np.float32)


_COMMANDS = {left_sign(turning): tuple((float(v), float(w)) for v, w in discrete_table(turning))
             for turning in TURNINGS}  # discrete_table's rows as Python floats, by left_sign
_LINEAR_LIMIT = MAX_LINEAR + 1e-6     # [m/s] the bounds with to_command's tolerance
_ANGULAR_LIMIT = MAX_ANGULAR + 1e-6   # [rad/s]


def to_command(kind, action, turning):
    """(linear.x, angular.z) for an action; InvalidAction naming it when it is not one.

    A continuous action given as a float16/32/64 array of shape (2,) within the bounds (what
    the space's sample() and most policies give) takes a short way to the same result;
    anything else, and every error, goes through the full checks (once per environment step:
    ~1 us instead of ~5)."""
    if (kind == "continuous" and type(action) is np.ndarray and action.shape == (2,)
            and action.dtype.char in "efd"):
        v, w = action.tolist()                 # Python floats, exactly the array's values
        if abs(v) <= _LINEAR_LIMIT and abs(w) <= _ANGULAR_LIMIT:    # False for NaN and inf
            return v, w
    return _checked_command(kind, action, turning)


def _checked_command(kind, action, turning):
    if kind == "discrete":
        try:
            index = int(action)
            valid = index == action and 0 <= index < len(NAMES)
        except (TypeError, ValueError, OverflowError):
            valid = False
        if not valid:
            raise InvalidAction("action %r is not one of 0 (forward), 1 (left), 2 (right)"
                                % (action,))
        return _COMMANDS[left_sign(turning)][index]
    try:
        values = np.asarray(action, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidAction("action %r is not two numbers (linear.x, angular.z)" % (action,)) \
            from None
    if values.shape != (2,):
        raise InvalidAction("action %r has %d values; give (linear.x [m/s], angular.z [rad/s])"
                            % (action, values.size))
    if not np.all(np.isfinite(values)):
        raise InvalidAction("action %r holds NaN or inf" % (action,))
    v, w = values
    if abs(v) > _LINEAR_LIMIT or abs(w) > _ANGULAR_LIMIT:
        raise InvalidAction("action %r is out of range: |linear.x| <= %g m/s, |angular.z| <= %g "
                            "rad/s" % (action, MAX_LINEAR, MAX_ANGULAR))
    return float(v), float(w)


def is_finite(command):
    return all(math.isfinite(c) for c in command)
