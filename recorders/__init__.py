"""Sources of sgtool logs.

- :mod:`sgtool.recorders.sim`: the PyBullet house simulation (an RGB-D + instance camera on
  a kinematic base, skills for planners, scripted exploration, sensor faults) and its
  recording into MCAP logs (``sgtool record``);
- :mod:`sgtool.recorders.importers`: foreign recordings (ROS 1/2 bags, RGB-D folders) into
  sgtool logs (``sgtool import``).
"""
