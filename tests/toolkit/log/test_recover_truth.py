"""Recovery tells the truth: a message whose bytes no CRC covers (its chunk has no CRC, or
was cut or damaged) is decoded and checked against its schema before it is copied; those
that fail are dropped and counted, the others are counted as copied unverified and go
into chunks of the copy written without a CRC, so ``sgtool doctor`` on the copy says
"unverified", never "complete" over garbage."""

from __future__ import annotations

import struct
from pathlib import Path

from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from support.log_fuzz import layout
from support.logfixtures import DT, write_log

from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.message_check import message_problem
from sgtool.log.recover import recover, scan
from sgtool.replayers.derived_log import ReplayOptions, replay

N = 12


def _uncompressed(tmp_path: Path) -> tuple[Path, bytes]:
    path = write_log(tmp_path / "log.mcap", n=N, compression="none",
                     flush_interval_ns=300_000_000)
    return path, path.read_bytes()


def _without_crcs(data: bytes) -> bytearray:
    """``data`` with every chunk's CRC zeroed (as a writer that wrote none)."""
    b = bytearray(data)
    for c in layout(data).chunks:
        struct.pack_into("<I", b, c.offset + 9 + 24, 0)  # after start, end, size
    return b


def _message(path: Path, topic: str, t_ns: int) -> bytes:
    with LogReader(path) as r:
        return next(bytes(m.data) for _, ch, m in r.raw_messages([topic])
                    if m.log_time == t_ns)


def _replace(b: bytearray, old: bytes, new: bytes) -> None:
    assert len(old) == len(new) and b.count(old) == 1
    i = b.index(old)
    b[i:i + len(old)] = new


def test_messages_no_crc_covers_are_checked_dropped_and_counted(tmp_path):
    """A depth image whose width no longer fits its data and an episode record that is no
    longer JSON, in a log written without chunk CRCs: the copy used to hold both under
    fresh CRCs, certified complete, and replay refused it."""
    src, data = _uncompressed(tmp_path)
    b = _without_crcs(data)
    depth = _message(src, S.DEPTH, 2 * DT)
    bad = RawImage.FromString(depth)
    bad.width += 1  # 64 -> 65: the same length, a row no longer fits the step
    _replace(b, depth, bad.SerializeToString())
    ended = _message(src, S.RECORDS["episode"].topic, N * DT)
    _replace(b, ended, b"[" + ended[1:])
    log, out = tmp_path / "damaged.mcap", tmp_path / "copy.mcap"
    log.write_bytes(bytes(b))
    total = scan(src).readable_messages

    d = scan(log)
    assert d.status == "corrupt" and d.dropped_messages == 2
    assert d.readable_messages == d.unverified_messages == total - 2
    text = " ".join(d.problems)
    assert f"{S.DEPTH} that no CRC covers dropped" in text and "field step" in text
    assert "/sgtool/episode" in text and "not JSON" in text

    rd = recover(log, out)
    assert (rd.readable_messages, rd.unverified_messages, rd.dropped_messages) == (
        total - 2, total - 2, 2)
    copy = scan(out)
    assert copy.status == "unverified" and copy.readable_messages == total - 2
    assert copy.checks["chunks"] == "no CRCs written"
    assert replay(out, None, ReplayOptions(every=100, voxel_size=0.2)).frames == N - 1


def test_a_log_with_crcs_copies_verified(tmp_path):
    """The control: every message covered, none checked away, the copy complete."""
    src, _ = _uncompressed(tmp_path)
    rd = recover(src, tmp_path / "copy.mcap")
    assert rd.status == "complete" and rd.unverified_messages == rd.dropped_messages == 0
    assert scan(tmp_path / "copy.mcap").status == "complete"


def test_messages_of_a_cut_chunk_are_copied_unverified(tmp_path):
    """A log cut inside its third chunk (uncompressed: the walk reads the messages before
    the cut): they are copied into a chunk without a CRC (the copy used to certify them
    complete); the messages of the whole chunks keep theirs."""
    src, data = _uncompressed(tmp_path)
    c = layout(data).chunks[2]
    log, out = tmp_path / "cut.mcap", tmp_path / "copy.mcap"
    log.write_bytes(data[:c.offset + 9 + c.length // 2])
    rd = recover(log, out)
    assert rd.status in ("truncated", "corrupt") and rd.unverified_messages > 0
    assert rd.dropped_messages == 0
    copy = scan(out)
    assert copy.status == "unverified" and copy.readable_messages == rd.readable_messages
    whole = len(layout(data).chunks[0].messages) + len(layout(data).chunks[1].messages)
    assert rd.readable_messages - rd.unverified_messages == whole


def test_message_problem_reads_as_the_reader_does(tmp_path):
    src, _ = _uncompressed(tmp_path)
    with LogReader(src) as r:
        for schema, ch, m in r.raw_messages():
            assert message_problem(schema, ch, m.data) is None, ch.topic
        schema, ch, m = next(x for x in r.raw_messages([S.RECORDS["instances"].topic]))
    assert "instances[0].id" in message_problem(
        schema, ch, b'{"instances": [{"id": 1180591620717411303424, "category": "a", '
        b'"kind": "object"}]}')


def test_doctor_recover_says_what_was_copied_unverified_and_dropped(tmp_path):
    from click.testing import CliRunner

    from sgtool.commands.doctor import command

    src, data = _uncompressed(tmp_path)
    b = _without_crcs(data)
    depth = _message(src, S.DEPTH, 2 * DT)
    bad = RawImage.FromString(depth)
    bad.height += 1
    _replace(b, depth, bad.SerializeToString())
    log, out = tmp_path / "damaged.mcap", tmp_path / "copy.mcap"
    log.write_bytes(bytes(b))
    total = scan(src).readable_messages
    res = CliRunner().invoke(command, [str(log), "--recover", str(out)])
    assert res.exit_code == 1, res.output  # the input is corrupt
    assert "dropped: 1 messages that fail their check" in res.output
    assert (f"recovered {total - 1} messages into {out}; {total - 1} of them copied "
            "unverified") in res.output and "; 1 dropped" in res.output
    res = CliRunner().invoke(command, [str(out)])
    assert res.exit_code == 0 and f"{out}: unverified" in res.output
