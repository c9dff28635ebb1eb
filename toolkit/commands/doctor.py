"""``sgtool doctor LOG [--recover OUT]``: is a log complete, truncated or corrupt?"""

from __future__ import annotations

import json

import click

from sgtool.log.recover import Diagnosis, recover, scan


def _report(d: Diagnosis) -> str:
    lines = [f"{d.path}: {d.status} ({d.size} bytes)"]
    span = ""
    if d.first_time_ns is not None and d.last_time_ns is not None:
        span = f", log time {d.first_time_ns / 1e9:.3f} .. {d.last_time_ns / 1e9:.3f} s"
    lines.append(
        f"readable: {d.readable_messages} messages on {d.channels} channels, "
        f"{d.attachments} attachments{span}"
    )
    if d.lost_chunks:
        lines.append(f"lost: {d.lost_chunks} damaged chunks")
    for p in d.problems[:10]:
        lines.append(f"  - {p}")
    if len(d.problems) > 10:
        lines.append(f"  ... and {len(d.problems) - 10} more problems")
    return "\n".join(lines)


@click.command("doctor")
@click.argument("log", type=click.Path(dir_okay=False))
@click.option(
    "--recover", "out", type=click.Path(dir_okay=False),
    help="Write every readable message to OUT as a valid, indexed MCAP file "
    "(never the input file).",
)
@click.option("--force", is_flag=True, help="Overwrite OUT if it exists.")
@click.option("--json", "as_json", is_flag=True, help="Print the diagnosis as JSON.")
def command(log: str, out: str | None, force: bool, as_json: bool) -> None:
    """Check LOG record by record and say whether it is complete, truncated (a recorder
    killed mid-write, a copy cut short) or corrupt (damaged bytes), and how many messages
    are readable. With --recover OUT, copy what is readable into a new log.

    Exit code 0 for a complete file, 1 for a truncated or corrupt one (also after a
    successful recovery), 2 for a usage error.
    """
    d = recover(log, out, overwrite=force) if out else scan(log)
    if as_json:
        click.echo(json.dumps(d.as_dict() | ({"recovered_to": out} if out else {}), indent=2))
    else:
        click.echo(_report(d))
        if out:
            click.echo(f"recovered {d.readable_messages} messages into {out}")
        elif d.status != "complete":
            click.echo(f"recover with: sgtool doctor {log} --recover OUT.mcap")
    if d.status != "complete":
        raise click.exceptions.Exit(1)
