"""The class grader (scripts/grade.sh): every student's motion_plan package graded on a
spec's tasks by the batch runner (m2wr_tools.batch.cluster, m2wr_tools.batch.rig), each run
isolated and its rules enforced, and the results as a static site, a gradebook CSV and a JSON file.
One job a module:
  spec       the YAML spec of the tasks (and spec_default.yaml, episodes 5-10)
  classroom  the class folder: a student's package or loose scripts; their overlay
  rules      what a controller may use of the simulator; findings and the verdict
  sandbox    a run's user, limits, watchdog and end
  launch_filter  a student's launch file without what would touch the grader's world
  grading    the class's batch: submissions staged, runs checked, sent to Dask, gathered
  runner     one graded run on a Dask worker (the batch runner's rig, extended)
  scoring    records -> each student's task scores, total, rank; grades.csv
  report     index.html, a page per student, trajectory pictures (SVG)
  replay_view  each graded run's browser replay in the report
  replay     `grade.sh --replay`: one graded run again, as it was graded
  cli        the command line
"""
