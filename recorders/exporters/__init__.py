"""Exporters: sgtool logs back into ROS.

- :mod:`sgtool.recorders.exporters.bagwriter`: a thin writer of ROS 1 / ROS 2 bags over
  ``rosbags`` with builders for common messages;
- :mod:`sgtool.recorders.exporters.ros_maps`: the derived layers (occupancy grid, Voronoi
  graph, rooms, objects, scene graph) as ``nav_msgs``, ``visualization_msgs`` and
  ``std_msgs`` messages;
- :mod:`sgtool.recorders.exporters.bag_export`: ``sgtool export bag``, a derived log as a bag
  that ROS tools (RViz, rosbag) understand.
"""
