"""gazebo_ros_args: the one line that names gazebo_ros's empty_world.launch arguments the
stand-in accepts without effect, and which of them a user set to something else."""
import os
import xml.etree.ElementTree as ET

from pybullet_gazebo.ros.gazebo_ros_args import WITHOUT_EFFECT, describe

SRC = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
SHIM_LAUNCH = os.path.join(SRC, "gazebo_ros", "launch", "empty_world.launch")
# Every argument Noetic's gazebo_ros/launch/empty_world.launch declares, with its default
NOETIC_ARGS = {
    "paused": "false", "use_sim_time": "true", "extra_gazebo_args": "", "gui": "true",
    "recording": "false", "headless": "false", "debug": "false", "physics": "ode",
    "verbose": "false", "output": "screen", "world_name": "worlds/empty.world",
    "respawn_gazebo": "false", "use_clock_frequency": "false", "pub_clock_frequency": "100",
    "enable_ros_network": "true", "server_required": "false", "gui_required": "false",
}


def defaults():
    return {name: default for name, (default, _) in WITHOUT_EFFECT.items()}


def test_all_at_gazebo_defaults_is_one_info_line_naming_them():
    level, line = describe(defaults())
    assert level == "info"
    assert line == ("gazebo_ros empty_world.launch arguments accepted without effect here: "
                    "enable_ros_network, extra_gazebo_args, gui_required, headless, physics, "
                    "recording, respawn_gazebo, server_required")


def test_a_changed_argument_is_a_warning_with_its_value_and_why():
    received = defaults()
    received.update(physics="dart", recording="True")
    level, line = describe(received)
    assert level == "warn"
    assert line.endswith("set to something other than Gazebo's default: physics:=dart "
                         "(Bullet steps every world); recording:=True (no Gazebo state log; "
                         "use rosbag record)")


def test_nothing_received_says_nothing():
    assert describe({}) is None


def test_shim_declares_every_noetic_argument_with_its_default():
    root = ET.parse(SHIM_LAUNCH).getroot()
    declared = {arg.get("name"): arg.get("default") for arg in root.findall("arg")}
    assert declared == NOETIC_ARGS


def test_shim_reports_exactly_the_arguments_it_does_not_pass_on():
    root = ET.parse(SHIM_LAUNCH).getroot()
    group = root.find("group[@ns='gazebo/gazebo_ros_args_without_effect']")
    reported = {param.get("name") for param in group.findall("param")}
    assert reported == set(WITHOUT_EFFECT)
    passed = " ".join(arg.get("value", "") + " " + arg.get("if", "")
                      for arg in root.find("include").findall("arg"))
    for name in NOETIC_ARGS:
        if name in reported and name != "headless":      # headless: passed, and no effect
            assert "arg('%s')" % name not in passed and "$(arg %s)" % name not in passed
        elif name not in reported:
            assert "arg('%s')" % name in passed or "$(arg %s)" % name in passed, name
