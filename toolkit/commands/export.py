"""``sgtool export bag DERIVED.mcap -o OUT``: an sgtool log back into ROS.

The work is done in :mod:`sgtool.recorders.exporters`; this module parses options and prints
the messages written per topic.
"""

from __future__ import annotations

import re

import click

from sgtool.commands.options import FINITE_FLOAT, PathParam
from sgtool.errors import SgtoolError


@click.group("export")
def command() -> None:
    """Export sgtool logs to other tools' formats."""


_ROS_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_/]*")  # a tf frame id ROS tools accept


def _frames(style: str, pairs: tuple[str, ...], log: str) -> dict[str, str]:
    """The frame renaming of ``--frames STYLE`` and ``--frame OLD=NEW`` pairs: OLD one of
    the log's frames by sgtool's name or by the name ``--frames`` gives it in this log
    (``map`` with rep105; ``base_link`` for a trajectory of a robot base), NEW a ROS name,
    no two frames under one name."""
    from sgtool.log import schemas as S
    from sgtool.recorders.exporters.bag_export import default_frames

    frames = (S.WORLD_FRAME, S.BASE_FRAME, S.CAMERA_FRAME)
    names = default_frames(log) if style == "rep105" else {}
    styled = {n: f for f, n in names.items()}
    given: dict[str, str] = {}  # frame -> the pair that renamed it
    for pair in pairs:
        old, sep, new = (x.strip() for x in pair.partition("="))
        if not sep or not old or not new:
            raise SgtoolError(f"--frame {pair!r}: give OLD=NEW, e.g. camera=camera_link")
        old = styled.get(old, old)  # the --frames name of a frame: the same frame
        if old not in frames:
            shown = ", ".join(f"{f} ({names[f]})" if f in names else f for f in frames)
            raise SgtoolError(f"--frame {pair!r}: {old!r} is no frame of an sgtool log "
                              f"(those are {shown})")
        if not _ROS_NAME.fullmatch(new):
            raise SgtoolError(f"--frame {pair!r}: {new!r} is not a ROS frame name (a letter "
                              "or '_', then letters, digits, '_' or '/')")
        if old in given:
            raise SgtoolError(f"--frame {pair!r} and --frame {given[old]!r} rename the same "
                              f"frame ({old}); give one")
        given[old] = pair
        names[old] = new
    final = [names.get(f, f) for f in frames]
    if len(set(final)) < len(final):
        twice = sorted({n for n in final if final.count(n) > 1})
        raise SgtoolError(f"--frame: two frames would be named {', '.join(twice)} (a tf "
                          "tree needs one name per frame)")
    return names


@command.command("bag")
@click.argument("log", type=PathParam(dir_okay=False))
@click.option("-o", "--output", required=True, type=PathParam(),
              help="The bag to write: NAME.bag is a ROS 1 bag file, any other name a ROS 2 "
                   "bag folder (MCAP storage).")
@click.option("--format", "fmt", type=click.Choice(["ros1", "ros2"]), default=None,
              help="ROS 1 bag or ROS 2 bag (MCAP storage) [default: from -o's name].")
@click.option("--distro", type=click.Choice(["humble", "jazzy"]), default="humble",
              show_default=True,
              help="ROS 2 distribution whose metadata.yaml layout and types are written "
                   "(a humble bag also plays on jazzy).")
@click.option("--time-base", "time_base", type=FINITE_FLOAT, default=None,
              metavar="SECONDS",
              help="Bag time and header stamps = log time + SECONDS (keeps every message off "
                   "stamp 0). Default: 1 for a log whose time starts within a second of 0 "
                   "(recorded in simulation), else 0 (an imported recording keeps its own "
                   "stamps and plays beside the original).")
@click.option("--frames", "frame_style", type=click.Choice(["rep105", "sgtool"]),
              default="rep105", show_default=True,
              help="Frame names: REP-105 (map, base_link, camera_optical_frame) or sgtool's "
                   "(world, base, camera). A trajectory imported from a bag keeps its "
                   "source's frame names under rep105 (e.g. odom -> base_link).")
@click.option("--frame", "frame_pairs", multiple=True, metavar="OLD=NEW",
              help="Rename one frame (repeatable), named as sgtool names it (world, base, "
              "camera) or as --frames does (map, base_link, camera_optical_frame), e.g. "
              "--frame map=odom.")
@click.option("--compression", type=click.Choice(["zstd", "lz4", "bz2", "none"]),
              default=None,
              help="Chunk compression [default: zstd for ros2, lz4 for ros1; ros2 takes zstd "
                   "or none, ros1 lz4, bz2 or none].")
@click.option("--topics", "topics", default=None, metavar="T1,T2,...",
              help="Only these topics (ROS or sgtool names, comma-separated); an sgtool "
                   "topic selects every ROS topic made from it (/tf: /tf and /tf_static, "
                   "the links that never move).")
@click.option("--progress/--no-progress", default=True,
              help="Show a progress bar [default: when stderr is a terminal].")
@click.option("--force", is_flag=True,
              help="Replace an existing OUT: a ROS 1 bag, or the files sgtool wrote in a ROS "
                   "2 bag folder (other files there stay).")
def bag(log: str, output: str, fmt: str | None, distro: str, time_base: float | None,
        frame_style: str, frame_pairs: tuple[str, ...], compression: str | None,
        topics: str | None, progress: bool, force: bool) -> None:
    """Write LOG (a derived log of `sgtool replay`, or any sgtool log) as a ROS bag for
    RViz, `ros2 bag`, image_proc and Foxglove (Rerun's ROS importer reads its maps, images
    and /tf, not its markers): the occupancy as nav_msgs/OccupancyGrid, the Voronoi graph,
    rooms, scene graph (objects, doors, frontiers, edges) and objects as
    visualization_msgs/MarkerArray, the scene graph as std_msgs/String JSON, the camera
    images each with a CameraInfo of the same stamp, /tf and a latched /tf_static for the
    fixed transforms. Maps and /tf_static are latched (transient-local QoS in ROS 2).

    \b
    Example:
      sgtool replay run.mcap -o derived.mcap
      sgtool export bag derived.mcap -o derived_bag            # ROS 2 (humble)
      sgtool export bag derived.mcap -o derived.bag            # ROS 1
      sgtool export bag derived.mcap -o maps --topics /map/occupancy,/tf
    """
    from tqdm import tqdm

    from sgtool.recorders.exporters.bag_export import export_bag

    names = [t.strip() for t in topics.split(",") if t.strip()] if topics else None
    if topics is not None and not names:
        raise SgtoolError("--topics: give at least one topic")
    with tqdm(unit="msg", desc="export", disable=None if progress else True,
              leave=False) as bar:
        report = export_bag(log, output, fmt, force, time_base_s=time_base,
                            frames=_frames(frame_style, frame_pairs, log), distro=distro,
                            compression=compression, topics=names, progress=bar)
    for line in report.lines():
        click.echo(line)


@command.command("foxglove-layout")
@click.option("-o", "--output", required=True, type=PathParam(dir_okay=False),
              help="Where to write the layout (JSON).")
@click.option("--follow", type=click.Choice(["base", "camera", "world"]), default="base",
              show_default=True,
              help="The frame the 3D panel follows: base (the robot of a simulated or "
              "closed-loop log), camera (an imported recording, which has no base frame) or "
              "world (a fixed view).")
@click.option("--force", is_flag=True, help="Overwrite OUT.")
def foxglove_layout(output: str, follow: str, force: bool) -> None:
    """Write the Foxglove layout shipped with sgtool: a 3D panel with the maps and the
    scene graph (/map/occupancy, /map/voronoi, /map/rooms, /map/graph) following the
    robot, the RGB, depth and instance images, and the scene graph and action records.
    Import it in Foxglove with Layouts > Import from file, then open a log or a derived
    log."""
    import json
    from importlib.resources import files

    from sgtool.commands.options import check_output
    from sgtool.files import atomic_write

    check_output(output, force=force, suffixes=(".json",), what="layout")
    layout = json.loads(files("sgtool").joinpath(LAYOUT).read_text(encoding="utf-8"))
    layout["configById"]["3D!sgtool"]["followTf"] = follow
    atomic_write(output, json.dumps(layout, indent=2) + "\n")
    click.echo(f"wrote {output}; import it in Foxglove: Layouts > Import from file")


LAYOUT = "foxglove_layout.json"  # package data of sgtool
