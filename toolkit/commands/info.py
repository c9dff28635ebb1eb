"""``sgtool info LOG``: what a log holds."""

from __future__ import annotations

import click

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
    `sgtool doctor`."""
    if (bag := bag_problem(log)) is not None:  # a recording sgtool imports: say how
        raise SgtoolError(bag)
    s = summarize(log)
    if as_json:
        click.echo(json_text(s, indent=2, sort_keys=True))
    else:
        click.echo(format_summary(s))
