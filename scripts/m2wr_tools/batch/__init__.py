"""Evaluating a controller over many runs (scripts/evaluate.sh), in parallel on Dask; the
grader runs its classes through the same cluster and rig. One job a module:
  evaluate        scripts/evaluate.sh's command line
  cluster         the batch on Dask: an embedded LocalCluster or a scheduler's cluster
  rig             the worker side: one simulator per worker, one run on it
  scenarios       a batch's runs: worlds, start poses (list, grid, random), seeds
  results         results.json and results.csv, resume, the summary table
  compare         the batches of several controllers side by side (Markdown)
  gym_evaluate    a policy against obstacle_avoidance.py in process, through m2wr_gym
"""
