"""``sgtool export bag DERIVED.mcap -o OUT``: an sgtool log back into ROS.

The work is done in :mod:`sgtool.recorders.exporters`; this module parses options and prints
the messages written per topic.
"""

from __future__ import annotations

import click


@click.group("export")
def command() -> None:
    """Export sgtool logs to other tools' formats."""


@command.command("bag")
@click.argument("log", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, type=click.Path(),
              help="The bag to write: a ROS 1 .bag file, or a ROS 2 bag folder (MCAP storage).")
@click.option("--format", "fmt", type=click.Choice(["ros1", "ros2"]), default="ros2",
              show_default=True, help="ROS 1 bag or ROS 2 bag (MCAP storage).")
@click.option("--force", is_flag=True, help="Replace an existing OUT.")
def bag(log: str, output: str, fmt: str, force: bool) -> None:
    """Write LOG (a derived log of `sgtool replay`, or any sgtool log) as a ROS bag that
    RViz, `ros2 bag`, Foxglove and Rerun's ROS importers understand: the occupancy as
    nav_msgs/OccupancyGrid, the Voronoi graph, rooms and objects as
    visualization_msgs/MarkerArray, the scene graph as std_msgs/String JSON, the camera
    images, CameraInfo and /tf.

    \b
    Example:
      sgtool replay run.mcap -o derived.mcap
      sgtool export bag derived.mcap -o derived_bag --format ros2
    """
    from sgtool.recorders.exporters.bag_export import export_bag

    for line in export_bag(log, output, fmt, force).lines():
        click.echo(line)
