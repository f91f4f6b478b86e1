"""Rewards and endings of the two tasks, per environment step of dt [s] of sim time.

avoid (episode 5's task: wander without touching anything)
  reward = forward distance travelled [m] (the displacement along the robot's mean heading;
           backing up counts negative)
         - NEAR_WEIGHT * (NEAR_DISTANCE - nearest laser return) / NEAR_DISTANCE when something
           is within NEAR_DISTANCE [m] of the laser (0 .. NEAR_WEIGHT per step)
         - CONTACT_PENALTY on contact, which ends the episode (terminated)
goal (reach a goal point, as go_to_point and the bug programs do)
  reward = the decrease of the distance to the goal [m], the same near-obstacle penalty,
           + GOAL_REWARD when within goal_tolerance (terminated),
           - CONTACT_PENALTY on contact (terminated)
Both are truncated after max_episode_seconds of sim time.
"""
import math

from pybullet_gazebo.engine.transforms import wrap_angle

NEAR_DISTANCE = 0.6        # [m] of laser range
NEAR_WEIGHT = 0.05         # per step at contact distance
CONTACT_PENALTY = 5.0
GOAL_REWARD = 5.0


def near_penalty(nearest):
    if nearest >= NEAR_DISTANCE:
        return 0.0
    return NEAR_WEIGHT * (NEAR_DISTANCE - max(nearest, 0.0)) / NEAR_DISTANCE


def forward_distance(before, after):
    """Displacement [m] from pose `before` to `after` ((x, y, yaw)) along the mean heading."""
    heading = before[2] + wrap_angle(after[2] - before[2]) / 2.0
    return (after[0] - before[0]) * math.cos(heading) + (after[1] - before[1]) * math.sin(heading)


def avoid_reward(before, after, nearest, touched):
    reward = forward_distance(before, after) - near_penalty(nearest)
    if touched:
        return reward - CONTACT_PENALTY, True
    return reward, False


def goal_reward(before, after, goal, tolerance, nearest, touched):
    d0 = math.hypot(goal[0] - before[0], goal[1] - before[1])
    d1 = math.hypot(goal[0] - after[0], goal[1] - after[1])
    reward = (d0 - d1) - near_penalty(nearest)
    if touched:
        return reward - CONTACT_PENALTY, True
    if d1 <= tolerance:
        return reward + GOAL_REWARD, True
    return reward, False
