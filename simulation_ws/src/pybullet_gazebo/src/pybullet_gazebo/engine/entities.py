"""What the World holds: models (Entity), the robots among them (Robot) and what a step
yields (Reading). Plain records; the World and its helpers fill them in."""
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from .part import Part
from .transforms import Pose


@dataclass
class Robot:
    """A model spawned from a URDF, with the parts its `<gazebo>` tags ask for."""
    name: str
    body_id: int
    namespace: str
    joints: Dict[str, int]          # URDF joint name -> Bullet joint index
    links: Dict[str, int]           # URDF link name -> Bullet link index (root: -1)
    initial_pose: Pose
    parts: List[Part] = field(default_factory=list)

    def parts_with(self, key: str) -> List[Part]:
        """The robot's parts that stand in for `key` (a Part KEY: a `<plugin filename>` or
        a `<sensor type>`, e.g. DiffDrive.KEY, RaySensor.KEY), in the order they were built."""
        return [part for part in self.parts if part.KEY == key]


@dataclass
class Entity:
    """A model in the world: its Bullet bodies (one per link) and where it started."""
    name: str
    body_ids: List[int]
    link_offsets: List[Pose]        # each body's link frame in the model frame
    inertial_offsets: List[Pose]    # each body's inertial frame in its link frame
    initial_pose: Pose              # model frame in the world at load/spawn
    static: bool
    is_ground: bool = False
    robot: Optional[Robot] = None
    # a world model's collision shapes per body, as getCollisionShapeData reports them
    # (which pybullet cannot do for maximal bodies): see bodies.shape_data. Empty for a robot.
    shapes: List[list] = field(default_factory=list)
    # Gazebo's link names, one per body (a robot: its root link), and a world model's
    # LinkSpecs (see model_access)
    link_names: List[str] = field(default_factory=list)
    link_specs: list = field(default_factory=list)


@dataclass(frozen=True)
class Reading:
    """A part's output that is due this step (a scan, an odometry)."""
    robot: Robot
    part: Part
    data: object
