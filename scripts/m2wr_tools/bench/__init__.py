"""Speed figures (scripts/bench.sh and the programs it runs beside the simulator), printed,
never asserted; docs/performance.md holds the current values. One job a module:
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
"""
