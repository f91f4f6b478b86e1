"""A run's figures and pictures from recorded data, with no ROS: what the demo prints and
draws, and what the batch runner and the grader measure. One job a module:
  metrics         a run's measures (distance travelled, contacts, time to goal) and the
                  task's verdict
  summary         the demo's run summary: time in each case, collisions, its text
  scene           the world offline: obstacles cut at scan height, the robot's clearance
  picture         the top-down picture of a run
  batch_picture   a batch's pictures: every path, the start poses
  replays         recorded runs as pages of the browser view
"""
