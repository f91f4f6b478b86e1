"""Names the tools look up in the ROS graph: the tutorial's topics and nodes, the simulator's
node and services, and the packages/launch files a session starts. One place, so that a
rename is one edit (the tutorial's own programs spell theirs out, as printed)."""

# nodes
SIMULATOR_NODE = "/gazebo"                 # the stand-in answers under Gazebo's node name
CONTROLLER_NODE = "/reading_laser"         # obstacle_avoidance.py's and reading_laser.py's node
ROBOT = "m2wr"                             # the model spawn.launch creates

# topics
SCAN_TOPIC = "/m2wr/laser/scan"            # sensor_msgs/LaserScan, 20 Hz of sim time
COMMAND_TOPIC = "/cmd_vel"                 # geometry_msgs/Twist, the controller's answer
ODOM_TOPIC = "/odom"                       # nav_msgs/Odometry (true pose of link_chassis)
CLOCK_TOPIC = "/clock"                     # rosgraph_msgs/Clock
TF_TOPIC = "/tf"                           # tf2_msgs/TFMessage: odom -> link_chassis
BASE_FRAME = "link_chassis"                # m2wr's base frame (the diff drive's robotBaseFrame)
CONTACTS_TOPIC = "/gazebo/contacts"        # gazebo_msgs/ContactsState: what the robot touches
ROSOUT_TOPIC = "/rosout"                   # rosgraph_msgs/Log, each node's log lines
MODEL_STATES_TOPIC = "/gazebo/model_states"  # gazebo_msgs/ModelStates
JOINT_STATES_TOPIC = "/joint_states"       # sensor_msgs/JointState: m2wr's wheels
ROBOT_DESCRIPTION_PARAM = "/robot_description"   # m2wr's URDF, as spawn.launch sets it

# services (Gazebo's names and types)
SPAWN_SERVICE = "/gazebo/spawn_urdf_model"
PAUSE_SERVICE = "/gazebo/pause_physics"
UNPAUSE_SERVICE = "/gazebo/unpause_physics"
RESET_SIMULATION_SERVICE = "/gazebo/reset_simulation"
RESET_WORLD_SERVICE = "/gazebo/reset_world"
GET_MODEL_STATE_SERVICE = "/gazebo/get_model_state"
SET_MODEL_STATE_SERVICE = "/gazebo/set_model_state"
WORLD_PROPERTIES_SERVICE = "/gazebo/get_world_properties"

# what a session launches
WORLD_LAUNCH = ("my_worlds", "launch_world.launch")
SPAWN_LAUNCH = ("m2wr_description", "spawn.launch")
SPAWN_NODE = "/spawn_m2wr"                 # spawn.launch's node (it ends once m2wr is in)
TUTORIAL_CONTROLLER = ("rosrun", "motion_plan", "obstacle_avoidance.py")
DEFAULT_WORLD = "world02"                  # the world episode 5 means
DEFAULT_START = (0.0, 8.0, 0.0)            # x [m], y [m], yaw [rad]: the tutorial's y:=8
