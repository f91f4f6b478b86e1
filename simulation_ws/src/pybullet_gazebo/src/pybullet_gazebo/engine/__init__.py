"""The engine core: worlds, models, sensors, drives and stepping. Imports pybullet and numpy,
never rospy or any *_msgs package, so it runs and is tested without a ROS master."""
