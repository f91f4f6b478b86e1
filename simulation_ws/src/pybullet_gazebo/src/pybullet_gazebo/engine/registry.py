"""The stand-in's components, keyed by what they stand in for in a URDF's `<gazebo>` tags:
a `<plugin filename=...>` or a `<sensor type=...>`. A key that is not here is reported by
name at spawn (the World's job), never silently ignored.
"""
from .diff_drive import DiffDrive
from .ray_sensor import RaySensor

# <gazebo><plugin filename="..."> -> component class
PLUGINS = {
    DiffDrive.KEY: DiffDrive,
}

# <gazebo reference="link"><sensor type="..."> -> component class
SENSORS = {
    RaySensor.KEY: RaySensor,
}

# Plugins a sensor block carries that its sensor component already implements.
SENSOR_PLUGINS = {
    "libgazebo_ros_laser.so": RaySensor.KEY,
}
