"""The physics dynamic_reconfigure description, without a master: the parameters of gazebo_ros's
Physics.cfg (names, types, defaults, ranges) in the layout dynamic_reconfigure encodes."""
from dynamic_reconfigure.encoding import encode_config, encode_description

from pybullet_gazebo.ros.physics_reconfigure import ODE_FIELDS, physics_config_type

GAZEBO_PARAMETERS = {   # name: (type, default, min, max), as gazebo_ros's Physics.cfg declares
    "time_step": ("double", 0.001, 0, 10), "max_update_rate": ("double", 60, 0, 1000),
    "gravity_x": ("double", 0, -100, 100), "gravity_y": ("double", 0, -100, 100),
    "gravity_z": ("double", -9.8, -100, 100), "auto_disable_bodies": ("bool", False, False, True),
    "sor_pgs_precon_iters": ("int", 0, 0, 10000), "sor_pgs_iters": ("int", 20, 0, 10000),
    "sor_pgs_w": ("double", 1.3, 0, 5), "sor_pgs_rms_error_tol": ("double", -1, -1, 10000),
    "cfm": ("double", 0, 0, 10), "erp": ("double", 0.2, 0, 10),
    "contact_surface_layer": ("double", 0.001, 0, 10),
    "contact_max_correcting_vel": ("double", 100, 0, 10000000),
    "max_contacts": ("int", 100, 0, 10000000),
}


def test_parameters_are_gazebo_s():
    kind = physics_config_type()
    assert set(kind.defaults) == set(GAZEBO_PARAMETERS)
    for name, (type_, default, low, high) in GAZEBO_PARAMETERS.items():
        assert (kind.type[name], kind.defaults[name], kind.min[name], kind.max[name]) == \
            (type_, default, low, high), name
    assert set(ODE_FIELDS) == set(GAZEBO_PARAMETERS) - {"time_step", "max_update_rate",
                                                        "gravity_x", "gravity_y", "gravity_z"}


def test_description_encodes_as_dynamic_reconfigure_sends_it():
    kind = physics_config_type()
    message = encode_description(kind)
    names = [p.name for group in message.groups for p in group.parameters]
    assert sorted(names) == sorted(GAZEBO_PARAMETERS)
    defaults = encode_config(kind.defaults)
    assert {d.name: d.value for d in defaults.doubles}["gravity_z"] == -9.8
    assert {b.name: b.value for b in defaults.bools} == {"auto_disable_bodies": False}
