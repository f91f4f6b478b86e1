"""The thin ROS adapter around the engine: parameters, topics, services, /clock and pacing."""
