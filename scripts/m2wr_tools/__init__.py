"""The project's tooling, shared by scripts/demo.sh, scripts/bench.sh and the batch runner:

  names        topic, node, service and launch names the tools look up
  paths        the checkout's root, world files, model folders, the robot's URDF
  processes    free ports, child processes in their own groups, stopping them, orphans
  session      one ROS session: own master on a free localhost port, simulator, spawn,
               controller, rosbag, all stopped by PID
  gazebo       calls to the simulator's Gazebo services (pause, poses, set_model_state)
  recorder     what a run hears (odometry, case lines, contacts, the last scan)
  summary      a run's maths and text (distance, touches, time in each case)
  scene        the world offline: obstacles cut at scan height, the robot's clearance
  picture      the top-down picture of a run
  benchmath    the benchmark's arithmetic and table
  demo, bench  the command lines behind demo.sh and bench.sh (bench_engine, bench_loop)
  tutorial_scripts  motion_plan's scripts (the tutorial's programs) loaded as modules
  gym_bench    m2wr_gym's speed figures: `python -m m2wr_tools.gym_bench`
  gym_evaluate a policy against obstacle_avoidance.py in process, through m2wr_gym's env:
               `python -m m2wr_tools.gym_evaluate`

Geometry (poses, quaternions, yaw) is the engine's: pybullet_gazebo.engine.transforms.
The tools stand above the project's ROS packages and use them, never the other way round:
pybullet_gazebo (the engine), m2wr_gym (the environments), motion_plan (its scripts, run by
rosrun or loaded by tutorial_scripts), my_worlds, m2wr_description, gazebo_msgs.
Installed editable by scripts/setup.sh (scripts/pyproject.toml).
"""
