"""Plain descriptions of what to simulate, parsed from Gazebo world files (SDF) and from the
`<gazebo>` tags of a URDF. No pybullet here: these are data, built by the loaders and turned
into Bullet bodies and components by `world.World`.
"""
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple
import xml.etree.ElementTree as ET

import numpy as np

from .transforms import Pose


# --- collision geometry (SDF / URDF primitives) -----------------------------------------------
@dataclass(frozen=True)
class Box:
    size: Tuple[float, float, float]          # full extents x y z [m]


@dataclass(frozen=True)
class Cylinder:
    radius: float                             # [m]
    length: float                             # [m], along the shape's local z axis


@dataclass(frozen=True)
class Sphere:
    radius: float                             # [m]


@dataclass(frozen=True)
class Plane:
    normal: Tuple[float, float, float] = (0.0, 0.0, 1.0)
    size: Tuple[float, float] = (100.0, 100.0)  # [m]; Bullet's plane is infinite


@dataclass(frozen=True)
class Mesh:
    """A mesh collision whose file could not be found or read: the World leaves it out."""
    uri: str
    scale: Tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class TriangleMesh:
    """A mesh collision read from its file: triangles in the collision frame, scaled."""
    uri: str
    path: str                                 # the file read
    vertices: np.ndarray = field(compare=False, repr=False)   # (n, 3) [m]
    faces: np.ndarray = field(compare=False, repr=False)      # (m, 3) vertex indices

    def triangles(self):
        """(m, 3, 3) corners of each triangle [m]."""
        return self.vertices[self.faces]


@dataclass(frozen=True)
class CollisionSpec:
    name: str
    geometry: object                          # Box | Cylinder | Sphere | Plane | TriangleMesh | Mesh
    pose: Pose = Pose()                       # in the link frame
    mu: float = 1.0                           # Gazebo's (ODE) default friction
    mu2: float = 1.0
    kp: float = 1e12                          # [N/m] <contact><ode><kp>, SDF's default
    kd: float = 1.0                           # [N s/m] <contact><ode><kd>, SDF's default


@dataclass(frozen=True)
class InertialSpec:
    mass: float = 1.0                         # [kg]
    pose: Pose = Pose()                       # centre of mass in the link frame
    inertia: Tuple[float, float, float] = (1.0, 1.0, 1.0)   # ixx iyy izz [kg m^2]


@dataclass(frozen=True)
class LinkSpec:
    name: str
    pose: Pose = Pose()                       # in the model frame
    inertial: InertialSpec = InertialSpec()
    collisions: Tuple[CollisionSpec, ...] = ()
    colour: Optional[Tuple[float, float, float, float]] = None   # RGBA of its visual, GUI only


@dataclass(frozen=True)
class ModelSpec:
    """A model of a world file (an SDF <model> or a resolved <include>)."""
    name: str
    pose: Pose = Pose()                       # in the world frame
    static: bool = False
    links: Tuple[LinkSpec, ...] = ()


@dataclass(frozen=True)
class PhysicsSpec:
    max_step_size: float = 0.001              # [s]
    real_time_factor: float = 1.0
    real_time_update_rate: float = 1000.0     # [Hz]
    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.8)   # [m/s^2]


@dataclass(frozen=True)
class WorldSpec:
    name: str
    source: str                               # the file it came from
    physics: PhysicsSpec = PhysicsSpec()
    models: Tuple[ModelSpec, ...] = ()
    warnings: Tuple[str, ...] = ()            # unsupported elements, meshes replaced, ...


# --- what a URDF's <gazebo> tags ask for ------------------------------------------------------
@dataclass(frozen=True)
class PluginSpec:
    """A `<plugin>` of a `<gazebo>` block: its filename picks the component; params are the
    plugin's child tags as text, exactly as written."""
    name: str
    filename: str
    params: Dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class RaySensorSpec:
    """A `<sensor type="ray">` on a link, with its gazebo_ros_laser plugin."""
    name: str
    link: str
    pose: Pose = Pose()                       # in the link frame
    update_rate: float = 0.0                  # [Hz]; 0 = every step, as Gazebo
    samples: int = 640
    min_angle: float = 0.0                    # [rad]
    max_angle: float = 0.0                    # [rad]
    range_min: float = 0.0                    # [m]
    range_max: float = 10.0                   # [m]
    resolution: float = 0.0                   # [m]
    noise_mean: float = 0.0                   # [m]
    noise_stddev: float = 0.0                 # [m]
    plugin: Optional[PluginSpec] = None       # libgazebo_ros_laser.so: topicName, frameName
    visualize: bool = False                   # <visualize>: Gazebo's GUI draws its beams


@dataclass(frozen=True)
class RobotSpec:
    """What the stand-in takes from a URDF beyond what pybullet's URDF loader reads itself."""
    name: str
    root_link: str
    plugins: Tuple[PluginSpec, ...] = ()
    sensors: Tuple[RaySensorSpec, ...] = ()
    # link: (mu1, mu2) from <gazebo reference> <mu1>/<mu2> (a missing one is 1, SDF's default)
    link_friction: Dict[str, Tuple[float, float]] = field(default_factory=dict)
    # link: (kp [N/m], kd [N s/m]) from <gazebo reference> <kp>/<kd>, each None when not given
    link_contact: Dict[str, Tuple[Optional[float], Optional[float]]] = field(default_factory=dict)
    warnings: Tuple[str, ...] = ()
    links: Tuple[str, ...] = ()               # link names, in file order
    joints: Dict[str, Tuple[str, str]] = field(default_factory=dict)   # name: (parent, child)
    urdf: Optional[ET.Element] = field(default=None, compare=False, repr=False)  # parsed text
