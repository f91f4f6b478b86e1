"""Unit tests of learned_avoidance.py's decisions without ROS: it decides once per
control_period of the policy file by the scans' stamps, answers every scan with the current
command, decides at once after a simulation reset, and refuses a policy that needs more
than m2wr's scan."""
import numpy as np
import pytest
from m2wr_gym import actions, observation
from m2wr_gym.policy import NumpyPolicy, PolicyFileError


def small_policy(rng, n_in=5, hidden=8):
    layers = [(rng.normal(size=(hidden, n_in)), rng.normal(size=hidden)),
              (rng.normal(size=(3, hidden)), rng.normal(size=3))]
    return NumpyPolicy(layers, np.full(n_in, 0.1), actions.discrete_table("gazebo"), "regions")


class _Msg:
    def __init__(self, stamp, ranges):
        class _Stamp:
            def to_sec(self_inner):
                return stamp
        self.header = type("H", (), {"stamp": _Stamp()})()
        self.ranges = ranges
        self.range_max = 10.0


def test_node_decides_every_control_period_and_answers_every_scan(load_script):
    node_module = load_script("learned_avoidance.py")
    published = []

    class Node(node_module.LearnedAvoidance):
        def __init__(self, policy):           # no ROS: the decision logic only
            self.policy, self.command = policy, (0.0, 0.0)
            self.next_decision, self.last_stamp = None, None

        def publish(self, v, w):
            published.append((v, w))
    decisions = []
    policy = small_policy(np.random.default_rng(3))
    original = policy.command
    policy.command = lambda o: decisions.append(o) or original(o)
    node = Node(policy)
    ranges = [1.0] * 720
    for k in range(6):                        # scans every 0.05 s: a decision every 0.1 s
        node.on_scan(_Msg(0.005 + 0.05 * k, ranges))
    assert len(published) == 6 and len(decisions) == 3
    assert np.allclose(decisions[0], observation.regions(np.ones(720)))
    node.on_scan(_Msg(0.005, ranges))         # the simulation was reset: decide at once
    assert len(decisions) == 4
    goal_policy = small_policy(np.random.default_rng(4), n_in=7)
    with pytest.raises(PolicyFileError, match="takes 7 inputs.*gives 5"):
        node_module.check(goal_policy)
