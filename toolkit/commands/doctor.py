"""``sgtool doctor LOG [--recover OUT]``: is a log complete, truncated or corrupt?"""

from __future__ import annotations

from pathlib import Path

import click

from sgtool.canonical import json_text
from sgtool.commands.options import PathParam
from sgtool.errors import SgtoolError
from sgtool.files import quoted
from sgtool.log.inspect import bag_problem
from sgtool.log.recover import Diagnosis, recover, scan
from sgtool.log.writer import partial_files


def _s(t_ns: int | None) -> str:
    return f"{(t_ns or 0) / 1e9:.3f}"


def _report(d: Diagnosis) -> str:
    lines = [f"{d.path}: {d.status} ({d.size} bytes)"]
    span = ""
    if d.first_time_ns is not None and d.last_time_ns is not None:
        span = f", log time {d.first_time_ns / 1e9:.3f} .. {d.last_time_ns / 1e9:.3f} s"
    lines.append(
        f"readable: {d.readable_messages} messages on {d.channels} channels, "
        f"{d.attachments} attachments{span}"
    )
    if d.salvaged_messages:
        lines.append(f"  of which {d.salvaged_messages} were decoded from cut or damaged "
                     "chunks, up to the cut or the damage (no CRC covers them)")
    if d.unverified_messages:
        lines.append(f"  of which {d.unverified_messages} no CRC covers: each was decoded and "
                     "checked against its schema (where sgtool can decode its encoding)")
    if d.dropped_messages:
        lines.append(f"dropped: {d.dropped_messages} messages that fail their check (damaged "
                     "where no CRC covers them, or written malformed; not copied)")
    checks = ", ".join(f"{k} {v}" for k, v in d.checks.items())
    if checks:
        lines.append(f"CRCs: {checks}")
    if d.lost_chunks:
        lines.append(f"damaged or cut chunks: {d.lost_chunks}")
    lines += _lost_lines(d)
    for p in d.problems[:10]:
        lines.append(f"  - {p}")
    if len(d.problems) > 10:
        lines.append(f"  ... and {len(d.problems) - 10} more problems")
    return "\n".join(lines)


def _lost_lines(d: Diagnosis) -> list[str]:
    """What the report says of the messages lost (none: no line), per topic."""
    if not (d.lost_messages or d.lost_unknown):
        return []
    if not d.lost_unknown:
        lines = [f"lost: {d.lost_messages} messages"]
    elif d.lost_messages:
        lines = [f"lost: {d.lost_messages} messages, and more that no index counts"]
    else:
        lines = ["lost: messages that no index counts (the cut or damaged data has no index)"]
    for topic, e in sorted(d.lost.items()):
        span = ""
        if e["first_ns"] is not None and e["last_ns"] is not None:
            span = f", log time {_s(e['first_ns'])} .. {_s(e['last_ns'])} s"
        lines.append(f"  {topic}: {e['messages']}{span}")
    return lines


def _refuse_no_log(log: str) -> None:
    """One line for a LOG that is not there but its partial files are (a killed writer
    leaves LOG.XXXXXXXX.partial, never LOG), or that is a bag sgtool imports."""
    found = [] if Path(log).exists() else partial_files(log)
    if found:
        raise SgtoolError(f"{log} does not exist; partial files: "
                          f"{', '.join(map(str, found))} (recover one with: sgtool doctor "
                          f"{quoted(found[0])} --recover {quoted(log)})")
    if (bag := bag_problem(log)) is not None:
        raise SgtoolError(bag)


def _recovered(d: Diagnosis, out: str) -> str:
    """The copy's verdict: what it holds, what of it no CRC vouched for, what was dropped."""
    line = f"recovered {d.readable_messages} messages into {out}"
    if d.unverified_messages:
        line += (f"; {d.unverified_messages} of them copied unverified (no CRC covered them; "
                 "the copy's chunks holding them carry no CRC either, so `sgtool doctor` "
                 "calls the copy unverified)")
    if d.dropped_messages:
        line += f"; {d.dropped_messages} dropped (they fail their check)"
    return line


@click.command("doctor")
@click.argument("log", type=PathParam(dir_okay=False))
@click.option(
    "--recover", "out", type=PathParam(dir_okay=False), metavar="OUT",
    help="Write every readable message to OUT as a valid, indexed MCAP file "
    "(never the input file).",
)
@click.option("--force", is_flag=True, help="Overwrite OUT if it exists.")
@click.option("--json", "as_json", is_flag=True, help="Print the diagnosis as JSON.")
def command(log: str, out: str | None, force: bool, as_json: bool) -> None:
    """Check LOG record by record and say whether it is complete, truncated (a recorder
    killed mid-write, a copy cut short) or corrupt (damaged bytes), how many messages are
    readable and which were lost (per channel, with their log time range, as far as the
    indexes and statistics tell). "complete" means every CRC the file carries is right
    (chunks, attachments, summary, data section) and every index, the statistics and the
    summary copies agree with the records. With --recover OUT, copy what is readable into
    a new log: damaged records are skipped up to the next valid one, channels whose
    definition is damaged are read with their summary copy, and the readable prefix of a
    cut or damaged compressed chunk is decoded. Every message is checked against its
    schema as replay reads it: one that fails is dropped (a file written with one is
    corrupt); those no CRC covers are copied into chunks without a CRC, so the copy is
    "unverified", never "complete", when it holds them.

    A file whose writer wrote no CRCs over its messages (many ROS 2 recordings) is at best
    "unverified": nothing is found wrong, but damage inside a message cannot be seen.

    Exit code 0 for a complete or unverified file, 1 for a truncated or corrupt one (also
    after a successful recovery), 2 for a usage error.
    """
    _refuse_no_log(log)
    d = recover(log, out, overwrite=force) if out else scan(log)
    if as_json:
        click.echo(json_text(d.as_dict() | ({"recovered_to": out} if out else {}), indent=2,
                             sort_keys=False))
    else:
        click.echo(_report(d))
        if out:
            click.echo(_recovered(d, out))
        elif d.status == "unverified":
            click.echo("unverified: every record reads and every index agrees, but the "
                       "writer wrote no CRCs over (some of) the messages, so damage inside "
                       "them cannot be detected")
        elif d.status != "complete":
            click.echo(f"recover with: sgtool doctor {quoted(log)} --recover OUT.mcap")
    if d.status not in ("complete", "unverified"):
        raise click.exceptions.Exit(1)
