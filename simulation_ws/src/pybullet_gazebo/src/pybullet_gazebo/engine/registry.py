"""The stand-in's robot parts, keyed by what they stand in for in a URDF's `<gazebo>` tags:
a `<plugin filename=...>` or a `<sensor type=...>`. A key that is not here is reported by
name at spawn (robot_loader's job), never silently ignored. The ROS adapter's bindings
(ros/bindings.py) are keyed by the same KEYs.
"""
from .diff_drive import DiffDrive
from .joint_states import JointStatePublisher
from .ray_sensor import RaySensor

# <gazebo><plugin filename="..."> -> Part class
PLUGIN_PARTS = {
    DiffDrive.KEY: DiffDrive,
    JointStatePublisher.KEY: JointStatePublisher,
}

# <gazebo reference="link"><sensor type="..."> -> Part class
SENSOR_PARTS = {
    RaySensor.KEY: RaySensor,
}

# Plugins a sensor block carries that its sensor part already implements.
SENSOR_PLUGINS = {
    "libgazebo_ros_laser.so": RaySensor.KEY,
}
