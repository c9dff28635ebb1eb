"""``sgtool view LOG [-o view.rrd]``: look at a log in Rerun."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import click

from sgtool.commands.options import PathParam, check_output
from sgtool.errors import SgtoolError


@click.command("view")
@click.argument("log", type=PathParam(dir_okay=False))
@click.option("-o", "--out", type=PathParam(dir_okay=False),
              help="Write a Rerun recording (.rrd) instead of opening the viewer.")
@click.option("--force", is_flag=True, help="Overwrite the -o file.")
@click.option("--every", type=click.IntRange(min=1), default=1, show_default=True,
              help="Log one camera frame in K (maps, graphs and actions are always logged).")
@click.option("--max-frames", type=click.IntRange(min=1), default=None,
              help="Stop after this many camera frames (the maps, graphs and actions "
                   "logged after them are left out too).")
@click.option("--voxels/--no-voxels", default=True, show_default=True,
              help="Rebuild and show the semantic voxel map (needs the mapping pipeline and "
              "depth images; a log without them is shown without it).")
@click.option("--rerun", "rerun_to", default=None,
              metavar="spawn|connect[:URL]|serve[:WEB_PORT[:GRPC_PORT]]",
              help="Where to stream instead of -o: spawn a viewer (the default without -o), "
              "connect to a running one, or serve a web viewer from here (headless "
              "machines; waits for Ctrl-C).")
def command(log: str, out: str | None, every: int, max_frames: int | None,
            voxels: bool, force: bool = False, rerun_to: str | None = None) -> None:
    """Show LOG in Rerun: camera with RGB, depth and segmentation, the voxel map, BEV
    occupancy, the Voronoi graph coloured by room, room labels, objects, doors, frontiers,
    the robot's path, its actions and the episode (query, outcome), on a frame timeline.
    Derived layers appear when LOG is the output of `sgtool replay`.

    Without -o the Rerun viewer is spawned (it needs a display); with -o the recording is
    written to a file that `rerun view.rrd` opens later (`rerun rrd verify` checks it); on
    a headless machine `--rerun serve` serves a web viewer (port 9090, gRPC 9876).

    Opening a derived .mcap directly in Rerun (its own MCAP import) or in ROS tools does
    not show the maps: they do not read foxglove.Grid/SceneUpdate. This command draws them;
    for ROS tools, `sgtool export bag DERIVED.mcap -o OUT` writes them as
    nav_msgs/OccupancyGrid and visualization_msgs/MarkerArray."""
    from sgtool.analysis.view_run import ViewRequest, view_log

    live = _target(log, out, force, rerun_to)
    view_log(ViewRequest(log=log, output=out, every=every,
                         max_frames=max_frames, voxels=voxels, live=live),
             show=click.echo, note=lambda m: click.echo(m, err=True))


def _target(log: str, out: str | None, force: bool, rerun_to: str | None) -> Any:
    """The output check: ``-o`` through :func:`check_output` (not the input log), else the
    live target of ``--rerun`` (default: spawn a viewer, which needs a display and the
    ``rerun`` program); None when writing a file."""
    from sgtool.analysis.rerun_live import LiveTarget, parse_target

    if rerun_to is not None and out is not None:
        raise SgtoolError("-o writes a file, --rerun streams: give one of them")
    if out is not None:
        if Path(out).resolve() == Path(log).resolve():
            raise SgtoolError("the output must not be the input log")
        check_output(out, force=force, suffixes=(".rrd",), what="Rerun recording")
        return None
    live = parse_target(rerun_to) if rerun_to is not None else LiveTarget("spawn")
    if live.mode == "spawn" and not (os.environ.get("DISPLAY")
                                     or os.environ.get("WAYLAND_DISPLAY")):
        raise SgtoolError("no display to open the Rerun viewer on; write a file with "
                          "-o view.rrd and open it with `rerun view.rrd` elsewhere, or "
                          "serve a web viewer from here with --rerun serve")
    if live.mode == "spawn" and shutil.which("rerun") is None:
        raise SgtoolError("the `rerun` viewer is not on PATH; use -o view.rrd or "
                          "--rerun serve")
    return live
