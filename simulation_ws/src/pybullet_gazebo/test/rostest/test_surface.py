#!/usr/bin/env python3
"""rostest: the running stand-in (world02, m2wr spawned) offers exactly the topics and services
it documents, with their types, and listens on localhost only.

What node /gazebo publishes, subscribes and serves is read from the master (getSystemState)
and from the node itself (ROS slave API: getPublications, getSubscriptions; service probes for
type and md5sum), then compared with Gazebo's API (gazebo_api.yaml, which the services'
docstrings must list too) plus what m2wr's plugins add (laser scan, odometry, TF, cmd_vel).
/gazebo/contacts is off (opt-in, contacts:=true). Sockets: every listening TCP socket and
bound UDP socket the simulator process owns (its /proc/<pid>/fd inodes, looked up in
/proc/<pid>/net/*) is on a loopback address, as env.sh's ROS_HOSTNAME=localhost asks.
"""
import os
import re
import socket
import sys
import unittest
import xmlrpc.client

import rosgraph
import rospkg
import rospy
import rosservice
import rostest
import yaml
from sensor_msgs.msg import LaserScan

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import node_pid   # noqa: E402
from pybullet_gazebo.ros import (physics_reconfigure, physics_services,   # noqa: E402
                                 property_services, spawn_services, state_services,
                                 wrench_services)
from pybullet_gazebo.ros.testing import wait_for_message   # noqa: E402

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "gazebo_api.yaml")) as _f:
    GAZEBO_API = yaml.safe_load(_f)


def _noetic_md5sums():
    path = os.path.join(rospkg.RosPack().get_path("gazebo_msgs"), "test", "unit",
                        "noetic_md5sums.txt")
    with open(path) as source:
        rows = [line.split() for line in source if line.strip() and not line.startswith("#")]
    return {"gazebo_msgs/" + kind.split("/")[1]: md5sum for kind, md5sum in rows}


NOETIC = _noetic_md5sums()
EMPTY_MD5 = "d41d8cd98f00b204e9800998ecf8427e"        # std_srvs/Empty
RECONFIGURE_MD5 = "bb125d226a21982a4a98760418dc2672"   # dynamic_reconfigure/Reconfigure
ROSPY_SERVICES = {"/gazebo/get_loggers": "roscpp/GetLoggers",
                  "/gazebo/set_logger_level": "roscpp/SetLoggerLevel"}
SERVICES = {  # name -> (type, md5sum): Gazebo's, gazebo_msgs md5sums ROS Noetic's
    s["name"]: (s["type"], NOETIC.get(s["type"], EMPTY_MD5 if s["type"] == "std_srvs/Empty"
                                      else RECONFIGURE_MD5))
    for s in GAZEBO_API["services"] if s["name"] not in ROSPY_SERVICES}
GAZEBO_PUBLICATIONS = {t["name"]: t["type"] for t in GAZEBO_API["topics"]
                       if t["publishers"] == 1}
PUBLICATIONS = dict(GAZEBO_PUBLICATIONS, **{
    "/m2wr/laser/scan": "sensor_msgs/LaserScan",     # m2wr's laser topicName
    "/odom": "nav_msgs/Odometry",                      # its odometryTopic
    "/tf": "tf2_msgs/TFMessage",                       # odom -> link_chassis
    "/joint_states": "sensor_msgs/JointState"})        # its wheels, for rviz
ROSPY_PUBLICATIONS = {"/rosout": "rosgraph_msgs/Log"}
SUBSCRIPTIONS = {"/cmd_vel": "geometry_msgs/Twist",   # m2wr's commandTopic
                 "/gazebo/set_model_state": "gazebo_msgs/ModelState",
                 "/gazebo/set_link_state": "gazebo_msgs/LinkState"}
# none from rospy: the simulator publishes /clock and does not listen to it
SERVICE_MODULES = (physics_reconfigure, physics_services, property_services, spawn_services,
                   state_services, wrench_services)


def loopback(address):
    """Whether a /proc/net/{tcp,udp}{,6} local address (hex, as the kernel writes it) is a
    loopback address: 127.0.0.0/8, ::1 or ::ffff:127.x.y.z."""
    raw = bytes.fromhex(address)
    if len(raw) == 4:
        return socket.inet_ntop(socket.AF_INET, raw[::-1]).startswith("127.")
    words = b"".join(raw[i:i + 4][::-1] for i in range(0, 16, 4))   # host-order words
    text = socket.inet_ntop(socket.AF_INET6, words)
    return text == "::1" or text.startswith("::ffff:127.")


def sockets_of(pid):
    """[(protocol, local address text, listening)] of the sockets process `pid` owns."""
    inodes = set()
    for fd in os.listdir("/proc/%d/fd" % pid):
        try:
            target = os.readlink("/proc/%d/fd/%s" % (pid, fd))
        except OSError:
            continue
        match = re.fullmatch(r"socket:\[(\d+)\]", target)
        if match:
            inodes.add(match.group(1))
    found = []
    for protocol in ("tcp", "tcp6", "udp", "udp6"):
        with open("/proc/%d/net/%s" % (pid, protocol)) as table:
            for line in table.readlines()[1:]:
                fields = line.split()
                if fields[9] in inodes:
                    address, port = fields[1].split(":")
                    listening = fields[3] == "0A" if protocol.startswith("tcp") else True
                    found.append((protocol, address, int(port, 16), listening))
    return found


class SurfaceTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_surface")
        wait_for_message("/m2wr/laser/scan", LaserScan, timeout=30)   # m2wr is in
        cls.master = rosgraph.Master("/test_surface")
        cls.node = xmlrpc.client.ServerProxy(cls.master.lookupNode("/gazebo"))

    def test_sets_the_rosout_topics_parameter_rospy_logging_needs_cached(self):
        # unset, every rospy.loginfo of every node asks the master for it (ros_comm 2337)
        self.assertIs(rospy.get_param("/rosout_disable_topics_generation"), False)

    def test_documented_services_are_the_ones_listed_here(self):
        documented = set()      # every ~name in the first paragraph of each module's docstring
        for module in SERVICE_MODULES:
            head = module.__doc__.split("\n\n")[0]
            documented |= {"/gazebo/" + name for name in re.findall(r"~(\w+)", head)}
        self.assertEqual(documented, set(SERVICES) | {"/gazebo/parameter_descriptions",
                                                      "/gazebo/parameter_updates"})

    def test_publishes_exactly_its_topics_with_their_types(self):
        code, _, publications = self.node.getPublications("/test_surface")
        self.assertEqual(code, 1)
        self.assertEqual(dict(publications), dict(PUBLICATIONS, **ROSPY_PUBLICATIONS))
        publishers, _, _ = self.master.getSystemState()
        by_master = {topic for topic, nodes in publishers if "/gazebo" in nodes}
        self.assertEqual(by_master, set(PUBLICATIONS) | set(ROSPY_PUBLICATIONS))

    def test_subscribes_exactly_its_topics_with_their_types(self):
        code, _, subscriptions = self.node.getSubscriptions("/test_surface")
        self.assertEqual(code, 1)
        self.assertEqual(dict(subscriptions), SUBSCRIPTIONS)
        _, subscribers, _ = self.master.getSystemState()
        by_master = {topic for topic, nodes in subscribers if "/gazebo" in nodes}
        self.assertEqual(by_master, set(SUBSCRIPTIONS))

    def test_serves_exactly_its_services_with_their_types_and_md5sums(self):
        _, _, services = self.master.getSystemState()
        served = {name for name, nodes in services if "/gazebo" in nodes}
        self.assertEqual(served, set(SERVICES) | set(ROSPY_SERVICES))
        for name in sorted(served):
            header = rosservice.get_service_headers(name, self.master.lookupService(name))
            if name in SERVICES:
                self.assertEqual((header["type"], header["md5sum"]), SERVICES[name], name)
            else:
                self.assertEqual(header["type"], ROSPY_SERVICES[name])

    def test_every_socket_of_the_simulator_is_on_localhost(self):
        pid = node_pid("/gazebo")
        with open("/proc/%d/cmdline" % pid) as source:
            self.assertIn("gazebo_world", source.read())
        found = sockets_of(pid)
        listening = [s for s in found if s[3]]
        self.assertGreaterEqual(len(listening), 2)      # XML-RPC and TCPROS servers at least
        uri_port = int(rosgraph.Master("/test_surface").lookupNode("/gazebo").split(":")[-1]
                       .strip("/"))
        self.assertIn(uri_port, [port for _, _, port, _ in listening])
        for protocol, address, port, _ in listening:
            self.assertTrue(loopback(address), "%s port %d listens on %s, not loopback"
                            % (protocol, port, address))


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "surface", SurfaceTest)
