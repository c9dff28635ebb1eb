"""Importers: foreign recordings (ROS 1/2 bags, RGB-D image folders) into sgtool logs.

- :func:`sgtool.recorders.importers.bag.import_bag` reads ROS 1 ``.bag``, ROS 2 sqlite3 and
  ROS 2 MCAP recordings through ``rosbags``: depth (and colour, instance-id) images, camera
  info and the ``/tf`` + ``/tf_static`` tree, resolved to a world-to-camera pose per image
  by interpolation in time.
- :func:`sgtool.recorders.importers.rgbd.import_rgbd` reads RGB-D folders in the TUM RGB-D,
  7-Scenes and Open3D/Redwood layouts.
- :mod:`sgtool.recorders.importers.odometry` estimates poses with Open3D's RGB-D odometry
  when a source has none and measures drift against ground truth.
- :mod:`sgtool.recorders.importers.upright` turns the source's world frame into sgtool's
  z-up world with the floor near z = 0.

Imported logs carry no instance ids unless the source has them (a bag's ``--ids`` topic).
"""
