"""``sgtool demo``: the README's first command, the whole pipeline on the demo house.

1. ``sgtool record``: the scripted robot explores the demo house in PyBullet (RGB-D and
   instance ids at 320x240, every door and container it meets opened) into
   ``OUT/demo.mcap``; ``sgtool info`` summarises the log;
2. ``sgtool replay --score``: the log is rebuilt into voxels, occupancy, a Voronoi graph,
   rooms, objects, frontiers and scene graphs (``OUT/derived.mcap``), scored against the
   house, and written as a Rerun recording (``OUT/view.rrd``);
3. ``sgtool bench``: a small symbolic benchmark (SymSearch roll-out) of the planners on
   generated evaluation houses, whose table ends the demo (``OUT/bench/``).

Everything runs offline; the same command gives the same logs.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from sgtool.errors import SgtoolError

DEMO_PLANNERS = ("random", "greedy", "sbert", "scout")


def _step(text: str) -> None:
    click.echo(f"\n== {text}")


@click.command("demo")
@click.option("-o", "--out", "out_dir", type=click.Path(file_okay=False), default="demo-out",
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
    from tqdm import tqdm

    from sgtool.analysis.bench import run_bench
    from sgtool.commands.replay import write_view
    from sgtool.datasets import demo_house
    from sgtool.log.inspect import format_summary, summarize
    from sgtool.recorders.sim import RecordOptions, record_house
    from sgtool.replayers.derived_log import replay
    from sgtool.replayers.score import score, score_lines

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SgtoolError(f"-o {out}: a file of that name exists")
    out.mkdir(parents=True, exist_ok=True)
    log, derived, rrd = out / "demo.mcap", out / "derived.mcap", out / "view.rrd"
    show = sys.stderr.isatty()

    _step(f"sgtool record -o {log}: the demo house in PyBullet")
    with tqdm(total=frames, unit="frame", desc="record", file=sys.stderr, leave=False,
              disable=not show, dynamic_ncols=True) as bar:
        rep = record_house(demo_house(), log, RecordOptions(frames=frames), house_id="demo",
                           progress=bar)
    for line in rep.lines():
        click.echo(line)
    _step(f"sgtool info {log}")
    click.echo(format_summary(summarize(log)))

    _step(f"sgtool replay {log} -o {derived} --rrd {rrd} --score")
    final: dict[str, object] = {}
    with tqdm(total=rep.frames, unit="frame", desc="replay", file=sys.stderr, leave=False,
              disable=not show, dynamic_ncols=True) as bar:
        rrep = replay(log, derived, progress=bar,
                      on_refresh=lambda r, s: final.update(ref=r, stream=s))
    for line in rrep.lines():
        click.echo(line)
    ref, stream = final["ref"], final["stream"]
    for line in score_lines(score(demo_house(), stream.builder.instances,  # type: ignore[attr-defined]
                                  ref.layers, ref.graph)):  # type: ignore[attr-defined]
        click.echo(line)
    write_view(derived, rrd, show)
    click.echo(f"wrote {rrd}; open it with: rerun {rrd}")

    _step(f"sgtool bench --planners {','.join(DEMO_PLANNERS)} --houses {houses} "
          f"--episodes {episodes} --seeds {seeds} -o {out / 'bench'}")
    click.echo(run_bench(DEMO_PLANNERS, houses=houses, episodes=episodes, seeds=seeds,
                         out_dir=out / "bench", progress=show))
