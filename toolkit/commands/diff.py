"""``sgtool diff A.mcap B.mcap``: what differs, layer by layer, between two logs' scene
graphs (:mod:`sgtool.replayers.golden_diff`)."""

from __future__ import annotations

import click

from sgtool.canonical import json_text
from sgtool.commands.golden import make_options, replay_options
from sgtool.commands.options import FiniteFloatRange, PathParam


@click.command("diff")
@click.argument("a", type=PathParam(dir_okay=False))
@click.argument("b", type=PathParam(dir_okay=False))
@replay_options("for a log without scene graphs: the log's, else the replay default")
@click.option("--tolerance", type=FiniteFloatRange(min=0.0), default=0.0, show_default=True,
              help="Let differences up to this pass: positions and distances (m), room "
              "areas (m²), category scores, the robot's yaw (rad) (0: the graphs must be "
              "byte-identical).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of text.")
def command(a: str, b: str, every: int | None, classifier: str | None,
            min_points: int | None, voxel_size: float | None, max_frames: int | None,
            tolerance: float, as_json: bool) -> None:
    """Compare the scene graphs of two logs: derived logs (`sgtool replay -o`) or
    closed-loop logs as they are, other logs replayed with the options given. Prints the
    first refresh that differs (frame, log time) and what differs in it layer by layer
    (rooms added, removed, merged or split with areas, categories, objects, doors,
    frontiers, Voronoi graph size), the quality figures of both when both were replayed
    from logs with their house, and the first logged action that differs. Exit 0 when
    they are the same, 1 when they differ, 2 on an error.

    Example: `sgtool replay A.mcap -o d1.mcap; sgtool replay A.mcap -o d2.mcap --voxel-size
    0.06; sgtool diff d1.mcap d2.mcap`."""
    from sgtool.replayers.golden_diff import diff_logs

    given = any(x is not None for x in (every, classifier, min_points, voxel_size, max_frames))
    d = diff_logs(a, b, make_options(every, classifier, min_points, voxel_size, max_frames),
                  tolerance)
    if given and d.a.source == "logged" and d.b.source == "logged":
        click.echo("sgtool: note: both logs hold their scene graphs, compared as they are: "
                   "the replay options given were not used", err=True)
    if as_json:
        click.echo(json_text(d.to_dict(), sort_keys=True))
    else:
        for line in d.report():
            click.echo(line)
    if not d.same:
        raise click.exceptions.Exit(1)
