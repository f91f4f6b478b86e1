#!/usr/bin/env python3
"""rostest: an empty world offers exactly Gazebo's ROS API (gazebo_api.yaml, the surface of
gzserver with gazebo_ros's api plugin): every topic with its type, its number of publishers
and, where a message flows, its md5sum on the wire; every service with its type and md5sum
(from the service's own connection header); and no topic or service beyond the list.

"Beyond the list" is judged over the whole ROS graph, leaving out what the test harness
brings (the master's /rosout node and its /rosout_agg, this test node's own services), as
gazebo_ros's ros_network checker does with `strict: true`.
"""
import os
import unittest
import xmlrpc.client

import rosgraph
import rospkg
import rospy
import rosservice
import rostest
import yaml
from roslib.message import get_message_class, get_service_class

from pybullet_gazebo.ros.testing import wait_until

HERE = os.path.dirname(os.path.abspath(__file__))
HARNESS_NODES = ("/rosout",)


def noetic_md5sums():
    path = os.path.join(rospkg.RosPack().get_path("gazebo_msgs"), "test", "unit",
                        "noetic_md5sums.txt")
    table = {}
    with open(path) as source:
        for line in source:
            if line.strip() and not line.startswith("#"):
                kind, md5sum = line.split()
                table["gazebo_msgs/" + kind.split("/")[1]] = md5sum
    return table


def expected_md5(type_name, service):
    table = noetic_md5sums()
    if type_name in table:
        return table[type_name]
    kind = get_service_class(type_name) if service else get_message_class(type_name)
    return kind._md5sum


class GazeboApiConformance(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("gazebo_api_conformance")
        with open(os.path.join(HERE, "gazebo_api.yaml")) as source:
            cls.api = yaml.safe_load(source)
        cls.me = rospy.get_name()
        cls.master = rosgraph.Master(cls.me)
        # /clock flows once the world runs
        wait_until(lambda: rospy.get_rostime().to_sec(), 30, "a first /clock", interval=0.1)
        cls.state = cls.master.getSystemState()

    # --- the list, item by item ----------------------------------------------------------------
    def test_every_topic_is_there_with_its_type_and_publishers(self):
        types = dict(self.master.getTopicTypes())
        publishers = {topic: [n for n in nodes if n != self.me] for topic, nodes in self.state[0]}
        for topic in self.api["topics"]:
            name = topic["name"]
            self.assertEqual(types.get(name), topic["type"], name)
            if topic["publishers"] >= 0:
                self.assertEqual(len(publishers.get(name, [])), topic["publishers"],
                                 "%s: publishers %s" % (name, publishers.get(name)))

    def test_every_flowing_topic_carries_gazebo_md5sums(self):
        for topic in self.api["topics"]:
            if topic["publishers"] != 1 or topic["name"] == "/rosout":
                continue
            message = rospy.wait_for_message(topic["name"], rospy.AnyMsg, timeout=10.0)
            header = message._connection_header
            self.assertEqual((header["type"], header["md5sum"]),
                             (topic["type"], expected_md5(topic["type"], False)), topic["name"])

    def test_the_state_setters_listen_with_gazebo_types(self):
        uri = self.master.lookupNode("/gazebo")
        code, _, subscriptions = xmlrpc.client.ServerProxy(uri).getSubscriptions(self.me)
        self.assertEqual(code, 1)
        subscriptions = dict(subscriptions)
        for topic in self.api["topics"]:
            if topic["publishers"] == 0:
                self.assertEqual(subscriptions.get(topic["name"]), topic["type"], topic["name"])
                self.assertEqual(get_message_class(topic["type"])._md5sum,
                                 expected_md5(topic["type"], False), topic["name"])

    def test_every_service_is_there_with_its_type_and_md5sum(self):
        for service in self.api["services"]:
            name = service["name"]
            uri = self.master.lookupService(name)
            header = rosservice.get_service_headers(name, uri)
            self.assertEqual(header["type"], service["type"], name)
            if not service["type"].startswith("roscpp/"):
                self.assertEqual(header["md5sum"], expected_md5(service["type"], True), name)

    # --- nothing beyond it ---------------------------------------------------------------------
    def test_no_topic_beyond_the_list(self):
        publishers, subscribers, _ = self.state
        graph = {}
        for topic, nodes in publishers + subscribers:
            graph.setdefault(topic, set()).update(nodes)
        extra = {topic for topic, nodes in graph.items()
                 if nodes - set(HARNESS_NODES) - {self.me}}
        self.assertEqual(extra - {t["name"] for t in self.api["topics"]}, set())

    def test_no_service_beyond_the_list(self):
        offered = {name for name, nodes in self.state[2]
                   if set(nodes) - set(HARNESS_NODES) - {self.me}}
        self.assertEqual(offered - {s["name"] for s in self.api["services"]}, set())


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "gazebo_api_conformance", GazeboApiConformance)
