"""The tools' calls to the simulator's Gazebo services (a rospy node must be initialised):
pause/unpause/reset (std_srvs/Empty), every model's pose, placing a model and spawning one."""
from ..names import (GET_MODEL_STATE_SERVICE, SET_MODEL_STATE_SERVICE, SPAWN_SERVICE,
                     WORLD_PROPERTIES_SERVICE)


def call_empty(name, timeout=10.0):
    """Calls the std_srvs/Empty service `name`, waiting up to `timeout` [s] for it."""
    import rospy
    from std_srvs.srv import Empty
    rospy.wait_for_service(name, timeout=timeout)
    rospy.ServiceProxy(name, Empty)()


def model_poses():
    """{name: Pose} of every model, from /gazebo/get_world_properties and get_model_state."""
    import rospy
    from gazebo_msgs.srv import GetModelState, GetWorldProperties
    from pybullet_gazebo.engine.transforms import Pose
    names = rospy.ServiceProxy(WORLD_PROPERTIES_SERVICE, GetWorldProperties)().model_names
    get = rospy.ServiceProxy(GET_MODEL_STATE_SERVICE, GetModelState)
    poses = {}
    for name in names:
        state = get(name, "")
        if state.success:
            p, q = state.pose.position, state.pose.orientation
            poses[name] = Pose((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
    return poses


def set_model_pose(name, x, y, z, yaw, timeout=10.0):
    """Places model `name` at (x, y, z) [m] heading `yaw` [rad], at rest, through
    /gazebo/set_model_state; RuntimeError with the simulator's answer when it refuses."""
    import rospy
    from gazebo_msgs.msg import ModelState
    from gazebo_msgs.srv import SetModelState
    from pybullet_gazebo.engine.transforms import quaternion_from_rpy
    rospy.wait_for_service(SET_MODEL_STATE_SERVICE, timeout=timeout)
    state = ModelState(model_name=name, reference_frame="world")
    state.pose.position.x, state.pose.position.y, state.pose.position.z = x, y, z
    q = quaternion_from_rpy(0.0, 0.0, yaw)
    o = state.pose.orientation
    o.x, o.y, o.z, o.w = q
    answer = rospy.ServiceProxy(SET_MODEL_STATE_SERVICE, SetModelState)(state)
    if not answer.success:
        raise RuntimeError("set_model_state(%s) failed: %s" % (name, answer.status_message))


class Services:
    """The simulator's pause/unpause/reset and set_model_state over persistent connections
    (a fresh proxy costs a master lookup and a TCP handshake per call; the batch makes
    five calls a run). A broken connection (the simulator was relaunched) is opened again
    once per call, after waiting up to `timeout` [s] for the service."""

    def __init__(self, timeout=10.0):
        self.timeout = timeout
        self._proxies = {}

    def _call(self, name, kind, *args):
        import rospy
        for attempt in (0, 1):
            proxy = self._proxies.get(name)
            if proxy is None:
                rospy.wait_for_service(name, timeout=self.timeout)
                proxy = self._proxies[name] = rospy.ServiceProxy(name, kind, persistent=True)
            try:
                return proxy(*args)
            except (rospy.ServiceException, rospy.exceptions.TransportException, OSError):
                self.close(name)
                if attempt:
                    raise

    def empty(self, name):
        from std_srvs.srv import Empty
        self._call(name, Empty)

    def set_model_pose(self, name, x, y, z, yaw):
        """As set_model_pose() above."""
        from geometry_msgs.msg import Pose
        from pybullet_gazebo.engine.transforms import quaternion_from_rpy
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = x, y, z
        o = pose.orientation
        o.x, o.y, o.z, o.w = quaternion_from_rpy(0.0, 0.0, yaw)
        self.place(name, pose)

    def place(self, name, pose):
        """Model `name` at `pose` (geometry_msgs/Pose in the world frame), at rest."""
        from gazebo_msgs.msg import ModelState
        from gazebo_msgs.srv import SetModelState
        state = ModelState(model_name=name, reference_frame="world", pose=pose)
        answer = self._call(SET_MODEL_STATE_SERVICE, SetModelState, state)
        if not answer.success:
            raise RuntimeError("set_model_state(%s) failed: %s" % (name, answer.status_message))

    def model_pose(self, name):
        """Model `name`'s pose (geometry_msgs/Pose in the world frame)."""
        from gazebo_msgs.srv import GetModelState
        answer = self._call(GET_MODEL_STATE_SERVICE, GetModelState, name, "")
        if not answer.success:
            raise RuntimeError("get_model_state(%s) failed: %s" % (name, answer.status_message))
        return answer.pose

    def close(self, name=None):
        for key in [name] if name else list(self._proxies):
            proxy = self._proxies.pop(key, None)
            if proxy is not None:
                proxy.close()


def spawn_urdf_model(name, urdf_xml, x, y, z, yaw, timeout=10.0):
    """Spawns model `name` from `urdf_xml` at (x, y, z) [m] heading `yaw` [rad] in the world
    frame and the root namespace, as `spawn_model -urdf` does by default; RuntimeError with
    the simulator's answer when it refuses."""
    import rospy
    from gazebo_msgs.srv import SpawnModel
    from geometry_msgs.msg import Pose
    from pybullet_gazebo.engine.transforms import quaternion_from_rpy
    rospy.wait_for_service(SPAWN_SERVICE, timeout=timeout)
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = float(x), float(y), float(z)
    o = pose.orientation
    o.x, o.y, o.z, o.w = quaternion_from_rpy(0.0, 0.0, yaw)
    answer = rospy.ServiceProxy(SPAWN_SERVICE, SpawnModel)(name, urdf_xml, "/", pose, "")
    if not answer.success:
        raise RuntimeError("%s refused %s: %s" % (SPAWN_SERVICE, name, answer.status_message))
