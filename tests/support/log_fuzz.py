"""Seeded mutants of a log file (bit flips, overwrites, truncations), crafted logs
(tests/support/crafted_logs.py: wrong schemas and encodings, bad house attachments, /tf
trees with cycles or without the camera link, instance tables out of range) and the
judgement of what a command did with one: for tests/toolkit/log/test_fuzz.py (in-process)
and tools/fuzz_cli.py (through the CLI).

A mutant knows which bytes it changed, so the chunks it left whole are known from the
original's layout: recovery must give back at least their messages. A "complete" verdict
is judged against what a reader sees: the channels, every message (topic, time, bytes) and
the attachments of the mutant must equal the original's. Header and metadata values are
left out of that view: the MCAP files sgtool (and rosbag2) write carry no CRC over them, so
no reader can tell a changed one.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

from sgtool.log.file_walk import Layout, walk

KINDS = ("flip", "flip-record-head", "overwrite", "truncate")


@dataclass(frozen=True)
class Mutant:
    name: str
    kind: str
    data: bytes
    start: int  # first changed byte (the cut for a truncation)
    end: int  # after the last changed byte (the original size for a truncation)


def layout(data: bytes) -> Layout:
    lay = Layout(len(data))
    for _ in walk(data, lay):
        pass
    return lay


def record_offsets(lay: Layout) -> list[int]:
    out = [8] + [r.offset for r in lay.top] + [c.offset for c in lay.chunks]
    if lay.footer is not None:
        out.append(lay.footer[0])
    return sorted(set(out))


def mutants(data: bytes, n: int, seed: int) -> list[Mutant]:
    """``n`` mutants of ``data``, the four kinds in turn; the same seed gives the same
    mutants."""
    rng = random.Random(seed)
    heads = record_offsets(layout(data))
    out = []
    for i in range(n):
        kind = KINDS[i % len(KINDS)]
        b = bytearray(data)
        if kind == "truncate":
            cut = rng.randrange(8, len(data))
            out.append(Mutant(f"{i:03d}-cut@{cut}", kind, bytes(data[:cut]), cut, len(data)))
            continue
        if kind == "overwrite":
            pos = rng.randrange(len(data))
            k = min(rng.randint(1, 64), len(data) - pos)
            b[pos:pos + k] = bytes(rng.randrange(256) for _ in range(k))
        else:
            if kind == "flip":
                pos = rng.randrange(len(data))
            else:  # the opcode, length and first fields of a record
                pos = min(rng.choice(heads) + rng.randrange(40), len(data) - 1)
            b[pos] ^= 1 << rng.randrange(8)
            k = 1
        out.append(Mutant(f"{i:03d}-{kind}@{pos}", kind, bytes(b), pos, pos + k))
    return out


@dataclass(frozen=True)
class Campaign:
    """The mutants of a log, with what judging them needs: the original's layout (for
    :func:`intact_messages`) and reader view (for a "complete" verdict)."""

    layout: Layout
    view: tuple
    mutants: list[Mutant]

    def complete_is_wrong(self, path: Path) -> bool:
        """A "complete" verdict on ``path`` is wrong when a reader sees it differently."""
        return view_or_none(path) != self.view

    def too_few(self, m: Mutant, recovered: int) -> bool:
        return recovered < intact_messages(self.layout, m)


def campaign(src: Path, n: int, seed: int) -> Campaign:
    original = src.read_bytes()
    return Campaign(layout(original), reader_view(src), mutants(original, n, seed))


def intact_messages(lay: Layout, m: Mutant) -> int:
    """Messages of the original's chunks that ``m`` left byte for byte whole."""
    total = 0
    for c in lay.chunks:
        lo, hi = c.offset, c.offset + 9 + c.length
        if m.kind == "truncate":
            whole = hi <= m.start
        else:
            whole = hi <= m.start or lo >= m.end
        total += len(c.messages) if whole else 0
    return total


def reader_view(path: Path) -> tuple:
    """What a reader sees of a log: channels, messages and attachments."""
    from sgtool.log import LogReader

    with LogReader(path, check_version=False) as r:
        channels = sorted((c.topic, c.schema_name, c.message_encoding, c.message_count)
                          for c in r.channels())
        messages = [(ch.topic, int(m.log_time), bytes(m.data))
                    for _, ch, m in r.raw_messages()]
        return channels, messages, sorted(r.attachments().items()), r.time_range()


def view_or_none(path: Path) -> tuple | None:
    from sgtool.errors import SgtoolError

    try:
        return reader_view(path)
    except SgtoolError:
        return None


# crafted logs (tests/support/crafted_logs.py): what replay (with and without --score)
# must do with each; "error" is a one-line refusal. Every other command may read or refuse
# one (never a traceback); doctor must call each "complete" (they are valid MCAP files) and
# recovery must keep every message.
_READ_BY_REPLAY = {"valid", "tf-huge-quaternion", "no-house", "house-not-json", "house-deep",
                   "house-not-utf8", "house-invalid"}
_SCORED = {"valid", "tf-huge-quaternion"}


def crafted_expectation(name: str) -> dict[str, str]:
    """{"replay": "clean" | "error", "score": ...} for the crafted log ``name``."""
    return {"replay": "clean" if name in _READ_BY_REPLAY else "error",
            "score": "clean" if name in _SCORED else "error"}


def crafted_report_problem(name: str, cmd: str, status: str, problems: list[str],
                           readable: int, dropped: int, total: int) -> str | None:
    """What is wrong with doctor's (``cmd`` "doctor") or recovery's ("recover") report on
    the crafted log ``name`` of ``total`` messages, None when it is right: doctor calls a
    valid file complete, or corrupt when every problem is a message written malformed (a
    log replay refuses); recovery accounts for every message, kept or dropped."""
    if cmd == "doctor" and status != "complete" and not (
            status == "corrupt" and crafted_expectation(name)["replay"] == "error"
            and all("were written malformed" in p for p in problems)):
        return f"{status} {problems[:2]}"
    if cmd == "recover" and readable + dropped != total:
        return f"{readable} messages kept, {dropped} dropped of {total}"
    return None


def crafted_logs(work: Path) -> list[tuple[str, Path]]:
    """Every crafted log of :data:`support.crafted_logs.CRAFTS`, written under ``work``."""
    from support.crafted_logs import CRAFTS

    return [(name, build(work / f"crafted-{i:02d}.mcap"))
            for i, (name, build) in enumerate(CRAFTS.items())]


def message_count(path: Path) -> int:
    """Messages of a valid log, as a reader counts them."""
    from sgtool.log import LogReader

    with LogReader(path, check_version=False) as r:
        return sum(1 for _ in r.raw_messages())
