"""lfd_tools: what the lfd scripts share, each written once.

  master   a private ROS master (roscore on a free port) and process-group shutdown
  config   the config/ files (evaluation.yaml: the segmentation protocol), read and checked
  tasks    the tasks: their demonstrated and unseen scenes, success criteria, skills
  judge    the one judge of segmentation success and of physical success (pure Python)
  bags     the bag and ground-truth readers (/lfd/phase, ground-truth files, demo outcomes)
  report   the result records the producers write and report.json holds
  lockstep the work cell and the executor's action, the simulation stepped while a goal moves
"""
