"""ROS processes: start them, talk to them, stop them (the demo, the batch runner, the
benchmarks and the grader all run ROS through these). One job a module:
  processes       free ports, child processes in their own groups, stopping them, orphans
  session         one ROS session: own master on a free port, simulator, spawn, controller,
                  rosbag, all stopped by PID
  zygote          a warm process that forks Python controllers with rospy already imported
  warm_rospy      rospy's idle waits shortened in the zygote's children, their own
                  remappings and namespace
  warm_launch     roslaunch PKG FILE in a zygote child: the file read as roslaunch reads it,
                  its Python nodes forked
  stale_nodes     nodes the master still lists after they ended, and forgetting them
  param_snapshot  the parameter server as a run found it, put back after the run
  commands        a controller's command line checked before any run starts
  cpu_meter       CPU seconds of named processes between the marks of a run
  gazebo          calls to the simulator's Gazebo services (pause, poses, set_model_state)
  gazebo_calls    reading the simulator's log of calls to its Gazebo services
  recorder        what a run hears (odometry, TF, case lines, contacts, the last scan)
"""
