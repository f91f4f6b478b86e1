"""Says, in one log line, which of gazebo_ros's empty_world.launch arguments the stand-in
accepts but cannot honour.

`$(find gazebo_ros)/launch/empty_world.launch` (the shim package gazebo_ros) declares every
argument of Noetic's file. Those that mean something here go on to pybullet_gazebo's
launch/empty_world.launch; the others are set, as strings, under the simulator's private
parameter

  ~gazebo_ros_args_without_effect   {name: value as the launch file received it}

and the simulator reports them once at start: at INFO when each holds Gazebo's default, at
WARN naming those set to something else (a user asked for something that does not happen).
Without that parameter (our own launch files) nothing is logged.
"""
import rospy

PARAM = "~gazebo_ros_args_without_effect"

# name: (Noetic's default, why it does nothing here)
WITHOUT_EFFECT = {
    "headless": ("false", "it does nothing in Gazebo either"),
    "physics": ("ode", "Bullet steps every world"),
    "recording": ("false", "no Gazebo state log; use rosbag record"),
    "extra_gazebo_args": ("", "there is no gzserver command line"),
    "respawn_gazebo": ("false", "the simulator is never respawned"),
    "server_required": ("false", "the simulator node is always required: when it ends, "
                                 "the launch ends"),
    "gui_required": ("false", "the GUI is not a process of its own"),
    "enable_ros_network": ("true", "Gazebo's topics and services are always offered"),
}


def describe(received):
    """(level, line) for the arguments in `received` ({name: value}), or None when empty.
    level is "warn" when one of them differs from Noetic's default, "info" otherwise."""
    if not received:
        return None
    names = sorted(received)
    changed = []
    for name in names:
        default, why = WITHOUT_EFFECT.get(name, (None, "the stand-in does not know it"))
        value = str(received[name]).strip()
        if default is None or value.lower() != default:
            changed.append("%s:=%s (%s)" % (name, value or "''", why))
    line = ("gazebo_ros empty_world.launch arguments accepted without effect here: %s"
            % ", ".join(names))
    if changed:
        return "warn", line + "; set to something other than Gazebo's default: " + "; ".join(changed)
    return "info", line


def report_gazebo_ros_args_without_effect():
    """Logs describe()'s line for the parameter PARAM once; nothing when it is not set."""
    received = rospy.get_param(PARAM, None)
    if not isinstance(received, dict):
        return
    described = describe(received)
    if described:
        level, line = described
        (rospy.logwarn if level == "warn" else rospy.loginfo)("%s", line)
