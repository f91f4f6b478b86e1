"""Gazebo's state services and topics:
  ~get_model_state (gazebo_msgs/GetModelState), ~set_model_state (gazebo_msgs/SetModelState)
  ~get_link_state (gazebo_msgs/GetLinkState), ~set_link_state (gazebo_msgs/SetLinkState)
  topics in: ~set_model_state (gazebo_msgs/ModelState), ~set_link_state (gazebo_msgs/LinkState)
Poses [m] and twists [m/s, rad/s] are in the reference frame named by the request (a model or
a `model::link`; "", "world", "map" = the world), as Gazebo computes them. set_model_state
normalizes the quaternion (all zeros = the identity, as Gazebo) and sets the twist. A request
that cannot be honoured answers success false naming the input and changes nothing; a topic
message that cannot is dropped with a warning naming it (each distinct reason at once, the
same reason again at most every 5 s).
"""
import rospy
from gazebo_msgs.msg import LinkState, ModelState
from gazebo_msgs.srv import (GetLinkState, GetLinkStateResponse, GetModelState,
                             GetModelStateResponse, SetLinkState, SetLinkStateResponse,
                             SetModelState, SetModelStateResponse)

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.engine.world import ModelNotFound
from pybullet_gazebo.ros import conversions
from pybullet_gazebo.ros.gazebo_answers import refuses


def _vector(v):
    return (v.x, v.y, v.z)


class StateServices:
    def __init__(self, sim):
        self.sim = sim
        self._get_model_count = {}          # model -> requests answered (Gazebo's header.seq)
        self.services = [          # rospy.Service objects (gazebo_services logs their callers)
            rospy.Service("~get_model_state", GetModelState, self.get_model_state),
            rospy.Service("~set_model_state", SetModelState, self.set_model_state),
            rospy.Service("~get_link_state", GetLinkState, self.get_link_state),
            rospy.Service("~set_link_state", SetLinkState, self.set_link_state),
        ]
        self._subscribers = [
            rospy.Subscriber("~set_model_state", ModelState, self._on_model_state, queue_size=10),
            rospy.Subscriber("~set_link_state", LinkState, self._on_link_state, queue_size=10),
        ]

    # --- models ---------------------------------------------------------------------------------
    @refuses("GetModelState", GetModelStateResponse)
    def get_model_state(self, req):
        response = GetModelStateResponse()
        world = self.sim.world
        with self.sim.lock:
            if req.model_name not in world.entities:
                raise ModelNotFound("model '%s' does not exist; models are: %s"
                                    % (req.model_name, ", ".join(world.model_names())))
            state = model_access.model_state(world, req.model_name)
            frame = model_access.frame_state(world, req.relative_entity_name)
            pose, linear, angular = model_access.relative_state(state, frame)
            stamp = self.sim.stamp()
        count = self._get_model_count.get(req.model_name, 0) + 1
        self._get_model_count[req.model_name] = count
        response.header.seq = count
        response.header.stamp = stamp
        response.header.frame_id = req.relative_entity_name
        response.pose = conversions.pose_to_msg(pose)
        response.twist = conversions.twist_to_msg(linear, angular)
        response.success = True
        response.status_message = "GetModelState: got properties"
        return response

    @refuses("SetModelState", SetModelStateResponse)
    def set_model_state(self, req):
        state = req.model_state
        self._set_model_state(state)
        return SetModelStateResponse(True, "SetModelState: set model state done")

    def _set_model_state(self, state):
        world = self.sim.world
        pose = conversions.pose_from_msg(state.pose)
        with self.sim.lock:
            world.entity(state.model_name)             # unknown model: said first
            frame = model_access.frame_state(world, state.reference_frame)
            pose, linear, angular = model_access.absolute_state(
                pose, _vector(state.twist.linear), _vector(state.twist.angular), frame)
            world.set_model_state(state.model_name, pose, tuple(linear), tuple(angular))

    def _on_model_state(self, msg):
        try:
            self._set_model_state(msg)
        except (LookupError, ValueError) as err:
            rospy.logwarn_throttle_identical(5.0, "/gazebo/set_model_state message ignored: %s" % err)

    # --- links ----------------------------------------------------------------------------------
    @refuses("GetLinkState", GetLinkStateResponse)
    def get_link_state(self, req):
        response = GetLinkStateResponse()
        world = self.sim.world
        with self.sim.lock:
            ref = model_access.find_link(world, req.link_name)
            state = model_access.link_state(world, ref)
            frame = model_access.frame_state(world, req.reference_frame)
            pose, linear, angular = model_access.relative_state(state, frame)
        response.link_state.link_name = req.link_name
        response.link_state.pose = conversions.pose_to_msg(pose)
        response.link_state.twist = conversions.twist_to_msg(linear, angular)
        response.link_state.reference_frame = req.reference_frame
        response.success = True
        response.status_message = "GetLinkState: got state"
        return response

    @refuses("SetLinkState", SetLinkStateResponse)
    def set_link_state(self, req):
        self._set_link_state(req.link_state)
        return SetLinkStateResponse(True, "SetLinkState: success")

    def _set_link_state(self, state):
        world = self.sim.world
        pose = conversions.pose_from_msg(state.pose)
        with self.sim.lock:
            ref = model_access.find_link(world, state.link_name)
            frame = model_access.frame_state(world, state.reference_frame)
            pose, linear, angular = model_access.absolute_state(
                pose, _vector(state.twist.linear), _vector(state.twist.angular), frame)
            model_access.set_link_state(world, ref, pose, linear, angular)

    def _on_link_state(self, msg):
        try:
            self._set_link_state(msg)
        except (LookupError, ValueError) as err:
            rospy.logwarn_throttle_identical(5.0, "/gazebo/set_link_state message ignored: %s" % err)
