"""The project's tooling: the commands of scripts/ (demo.sh, evaluate.sh, grade.sh, bench.sh)
and what they share, one sub-package a job. Index:

  demo              scripts/demo.sh: the tutorial's episode 5 end to end, summary and picture
  names             topic, node, service and launch names the tools look up
  paths             the checkout's root, world files, model folders, the robot's URDF
  tool_exit         how every tool ends: one line on stderr and an exit status
  usage             how every tool answers --help: its name as typed, defaults, examples
  tutorial_scripts  motion_plan's scripts (the tutorial's programs) loaded as modules

  running/          ROS processes: start them, talk to them, stop them
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

  analysis/         a run's figures and pictures from recorded data (no ROS)
    metrics         a run's measures (distance travelled, contacts, time to goal) and the
                    task's verdict
    summary         the demo's run summary: time in each case, collisions, its text
    scene           the world offline: obstacles cut at scan height, the robot's clearance
    picture         the top-down picture of a run
    batch_picture   a batch's pictures: every path, the start poses
    replays         recorded runs as pages of the browser view

  batch/            evaluating a controller over many runs (scripts/evaluate.sh)
    evaluate        scripts/evaluate.sh's command line
    cluster         the batch on Dask: an embedded LocalCluster or a scheduler's cluster
    rig             the worker side: one simulator per worker, one run on it
    scenarios       a batch's runs: worlds, start poses (list, grid, random), seeds
    results         results.json and results.csv, resume, the summary table
    compare         the batches of several controllers side by side (Markdown)
    gym_evaluate    a policy against obstacle_avoidance.py in process, through m2wr_gym

  bench/            speed figures (scripts/bench.sh), printed, never asserted
    cli             scripts/bench.sh's command line: episode 5's figures side by side
    arithmetic      the benchmark's arithmetic and its table
    engine          the engine alone (no ROS): stepping and one scan's cost
    loop            the whole loop in lockstep and free-running, launch to first scan, soak
    web             what watching the live page costs the lockstep loop
    web_watch       a stand-in for browser pages watching the live view
    loop_avoidance  obstacle_avoidance.py on a rospy.Rate loop of its own, as learners write it
    switched_off_beside  obstacle_avoidance.py beside a switched-off busy loop, as bug 0-2 run
    series_runs     the series' later programs in lockstep and at real time: reached or not
    bug             scripts/bench.sh --bug: the series' bug-2 runs in lockstep
    grade           scripts/bench.sh --grade: a class graded, runs a minute, the overhead
    gym             m2wr_gym's environments: steps a second

  grade/            the class grader (scripts/grade.sh), on the batch runner
    cli             scripts/grade.sh's command line: the batch, the report, replays
    spec            the YAML spec of the tasks (spec_default.yaml: episodes 5-10)
    classroom       the class folder: each student's package or loose scripts
    grading         the class's batch: every submission staged, checked and run on Dask
    runner          one graded run on a Dask worker (the batch's rig, extended)
    sandbox         a run's user, limits, watchdog and end
    rules           what a controller may use of the simulator; findings and the verdict
    launch_filter   a student's launch file without the world and robot it would start
    scoring         records -> each student's task scores, total, rank; grades.csv
    report          the static site: the class table, a page per student, pictures
    replay          scripts/grade.sh --replay: one graded run again, drawn
    replay_view     each graded run's replay page in the report

Layers, from the ground up: names, paths, tool_exit, usage and tutorial_scripts; analysis/ (none
of running/, batch/, bench/); running/ (analysis/ only for the recorder's case lines); batch/;
grade/ (on batch/); bench/ and demo, the commands, on top. Geometry (poses, quaternions, yaw) is the engine's:
pybullet_gazebo.engine.transforms. The tools stand above the project's ROS packages and use
them, never the other way round: pybullet_gazebo (the engine), m2wr_gym (the environments),
motion_plan (its scripts, run by rosrun or loaded by tutorial_scripts), my_worlds,
m2wr_description, gazebo_msgs. Installed editable by scripts/setup.sh (scripts/pyproject.toml).
"""
