"""``sgtool info LOG``: what a log holds."""

from __future__ import annotations

import click

from sgtool.analysis.rrd_contents import format_rrd, is_rrd, summarize_rrd
from sgtool.canonical import json_text
from sgtool.commands.options import PathParam
from sgtool.errors import SgtoolError
from sgtool.log.inspect import bag_problem, format_summary, summarize


@click.command("info")
@click.argument("log", type=PathParam(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (for scripts).")
def command(log: str, as_json: bool) -> None:
    """Summarise LOG: channels, schemas, message counts, time range, frame count, log
    schema version and the episode summary. Works on foreign MCAP files too (lists their
    topics, schemas and counts). A truncated file gives an error that points to
    `sgtool doctor`. A Rerun recording (.rrd, `sgtool view -o`) gives its stores, entities,
    rows and a digest of what it holds: two exports of one log have the same digest though
    their bytes differ."""
    if is_rrd(log):
        r = summarize_rrd(log)
        click.echo(json_text(r, indent=2, sort_keys=True) if as_json else format_rrd(r))
        return
    if (bag := bag_problem(log)) is not None:  # a recording sgtool imports: say how
        raise SgtoolError(bag)
    s = summarize(log)
    if as_json:
        click.echo(json_text(s, indent=2, sort_keys=True))
    else:
        click.echo(format_summary(s))
