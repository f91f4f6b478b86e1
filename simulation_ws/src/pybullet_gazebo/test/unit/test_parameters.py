"""One reader for plugin tags and node parameters: typed values, ranges, and errors that name
the parameter, the value and what is allowed."""
import math

import pytest

from pybullet_gazebo.engine.parameters import (ROS_BOOLEANS, ParameterError, ParameterReader)
from pybullet_gazebo.ros.params import SimulatorParams


def tags(**values):
    return ParameterReader(values, "plugin 'p' (lib.so)", label="<%s>")


def test_absent_values_take_the_default_and_text_is_stripped():
    read = tags(topic="  /scan ")
    assert read.text("topic", "x") == "/scan"
    assert read.text("frame", "base") == "base"
    assert read.number("rate", 20.0) == 20.0
    assert read.boolean("flag", True) is True
    assert not read.given("rate") and read.given("topic")


@pytest.mark.parametrize("raw, kwargs, expected", [
    ("0.4", {}, 0.4), (" 2 ", {"above": 0.0}, 2.0), ("0", {"minimum": 0.0}, 0.0),
    (3, {}, 3.0), ("5", {"maximum": 5.0}, 5.0)])
def test_numbers_within_range_are_read(raw, kwargs, expected):
    assert tags(v=raw).number("v", None, **kwargs) == expected


@pytest.mark.parametrize("raw, kwargs, requirement", [
    ("big", {}, "give a number"), ("nan", {}, "give a finite number"),
    ("inf", {}, "give a finite number"), ("0", {"above": 0.0}, "it must be > 0.0"),
    ("-1", {"minimum": 0.0}, "it must be >= 0.0"), ("6", {"maximum": 5.0}, "it must be <= 5.0"),
    (True, {}, "give a number")])
def test_bad_numbers_name_parameter_value_and_range(raw, kwargs, requirement):
    with pytest.raises(ParameterError) as err:
        tags(wheelDiameter=raw).number("wheelDiameter", 1.0, **kwargs)
    assert str(err.value) == "plugin 'p' (lib.so): <wheelDiameter> is %s; %s" % (raw, requirement)


def test_integers_must_be_whole():
    assert tags(n="720").integer("n", 1) == 720
    with pytest.raises(ParameterError, match=r"<n> is 7.5; give a whole number"):
        tags(n="7.5").integer("n", 1)


def test_sdf_booleans_are_true_false_1_0_only():
    assert tags(a="true", b="0", c=" FALSE ").boolean("a", False) is True
    assert tags(b="0").boolean("b", True) is False
    assert tags(c=" FALSE ").boolean("c", True) is False
    with pytest.raises(ParameterError, match=r"<c> is yes; write true or false"):
        tags(c="yes").boolean("c", False)


def test_ros_booleans_also_take_yes_and_no_and_real_bools():
    read = ParameterReader({"a": "yes", "b": False}, "gazebo", "~%s", booleans=ROS_BOOLEANS)
    assert read.boolean("a", False) is True and read.boolean("b", True) is False


def test_node_parameters_are_read_and_checked_by_the_same_reader():
    params = SimulatorParams.from_values({"real_time_factor": 0, "seed": "3", "gui": "false",
                                          "lockstep": True, "max_step_size": 0.001},
                                         use_sim_time=True, where="/gazebo")
    assert params.real_time_factor == 0.0 and params.seed == 3 and params.gui is False
    assert params.lockstep is True and params.max_step_size == 0.001
    assert SimulatorParams.from_values({}).real_time_factor is None     # the world file's
    with pytest.raises(ParameterError) as err:
        SimulatorParams.from_values({"pub_clock_frequency": 0}, where="/gazebo")
    assert str(err.value) == "/gazebo: ~pub_clock_frequency is 0; it must be > 0.0"
    with pytest.raises(ParameterError, match=r"~seed is -1; it must be >= 0"):
        SimulatorParams.from_values({"seed": -1})
    with pytest.raises(ParameterError, match=r"~lockstep_timeout is nan; give a finite"):
        SimulatorParams.from_values({"lockstep_timeout": math.nan})
    assert SimulatorParams.from_values({}).watch_rate == 30.0               # [Hz] wall
    assert SimulatorParams.from_values({"watch_rate": 0}).watch_rate == 0.0  # no limit
    with pytest.raises(ParameterError, match=r"~watch_rate is -5; it must be >= 0"):
        SimulatorParams.from_values({"watch_rate": -5})


def test_a_word_parameter_takes_one_of_its_words_and_names_them_when_not():
    read = ParameterReader({"a": " SDF", "b": True, "c": "maybe"}, "/gazebo", "~%s",
                           booleans=ROS_BOOLEANS)
    assert read.choice("a", "x", ("sdf", "true", "false")) == "sdf"
    assert read.choice("b", "x", ("sdf", "true", "false")) == "true"    # roslaunch's bool
    assert read.choice("d", "sdf", ("sdf", "true", "false")) == "sdf"
    with pytest.raises(ParameterError) as err:
        SimulatorParams.from_values({"gui_rays": "maybe"}, where="/gazebo")
    assert str(err.value) == "/gazebo: ~gui_rays is maybe; write one of: sdf, true, false"
