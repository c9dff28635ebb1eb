"""``sgtool demo``: the README's first command, the whole pipeline on the demo house.

1. ``sgtool record``: the scripted robot explores the demo house in PyBullet (RGB-D and
   instance ids at 320x240, every door and container it meets opened) into
   ``OUT/demo.mcap``; ``sgtool info`` summarises the log;
2. ``sgtool replay --score``: the log is rebuilt into voxels, occupancy, a Voronoi graph,
   rooms, objects, frontiers and scene graphs (``OUT/derived.mcap``), scored against the
   house, and written as a Rerun recording (``OUT/view.rrd``);
3. ``sgtool bench``: a small symbolic benchmark (SymSearch roll-out) of the planners on
   generated evaluation houses, whose table ends the demo (``OUT/bench/``).

Everything runs offline; the same command gives the same logs. The steps are in
:mod:`sgtool.analysis.demo_pipeline`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from sgtool.commands.options import PathParam
from sgtool.errors import SgtoolError


@click.command("demo")
@click.option("-o", "--out", "out_dir", type=PathParam(file_okay=False), default="demo-out",
              show_default=True, help="Folder for the demo's logs and results.")
@click.option("--frames", type=click.IntRange(min=1), default=None,
              help="Stop the recording after this many frames (default: the whole tour).")
@click.option("--houses", type=click.IntRange(min=1), default=3, show_default=True,
              help="Evaluation houses of the closing benchmark.")
@click.option("--episodes", type=click.IntRange(min=1), default=10, show_default=True,
              help="Episodes per house of the closing benchmark.")
@click.option("--seeds", type=click.IntRange(min=1), default=2, show_default=True,
              help="Seeds of the closing benchmark.")
def command(out_dir: str, frames: int | None, houses: int, episodes: int, seeds: int) -> None:
    """Record the demo house in PyBullet, summarise the log, replay it into scene graphs
    (scored against the house, with a Rerun recording), then benchmark planners on the
    symbolic benchmark and print its table. Outputs go to OUT (overwritten)."""
    from sgtool.analysis.demo_pipeline import DemoRequest, run_demo
    from sgtool.analysis.replay_run import write_view

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SgtoolError(f"-o {out}: a file of that name exists")
    out.mkdir(parents=True, exist_ok=True)
    run_demo(DemoRequest(out=out, frames=frames, houses=houses, episodes=episodes,
                         seeds=seeds),
             show=click.echo, progress=sys.stderr.isatty(), write_view=write_view)
