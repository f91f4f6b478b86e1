"""pybullet_gazebo: a Bullet-driven stand-in for Gazebo for the m2wr tutorial.

`pybullet_gazebo.engine` is the simulator core (pybullet + numpy, no ROS);
`pybullet_gazebo.ros` is the thin ROS adapter around it.
"""
