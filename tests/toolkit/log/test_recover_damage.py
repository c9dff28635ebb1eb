"""Recovery keeps every intact byte and says what was lost; doctor says "complete" only
when every CRC and every index agrees (issue 14, items 1 and 3)."""

from __future__ import annotations

import struct

import pytest
from mcap.opcode import Opcode
from support.log_fuzz import layout
from support.logfixtures import write_log

from sgtool.errors import LogFormatError
from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.inspect import summarize
from sgtool.log.recover import recover, scan


@pytest.fixture(scope="module")
def log40(tmp_path_factory):
    """40 frames at 10 fps, a chunk per second: five chunks."""
    return write_log(tmp_path_factory.mktemp("dmg") / "l40.mcap", n=40)


def _flipped(src, tmp_path, pos, bit=0x10):
    data = bytearray(src.read_bytes())
    data[pos] ^= bit
    out = tmp_path / "damaged.mcap"
    out.write_bytes(bytes(data))
    return out


def test_a_flip_in_the_first_chunk_loses_only_that_chunk(log40, tmp_path):
    lay = layout(log40.read_bytes())
    first, rest = lay.chunks[0], lay.chunks[1:]
    assert len(lay.chunks) == 5 and len(first.messages) > 40
    bad = _flipped(log40, tmp_path, first.offset + 9 + first.length // 2)
    d = recover(bad, tmp_path / "rec.mcap")
    assert d.status == "corrupt" and d.lost_chunks == 1
    # the channels were defined in the damaged chunk: their summary copies are used
    assert d.readable_messages == sum(len(c.messages) for c in rest)
    assert d.lost_messages == len(first.messages) and not d.lost_unknown
    assert d.lost[S.DEPTH] == {"messages": 10, "first_ns": 0, "last_ns": 900_000_000}
    with LogReader(tmp_path / "rec.mcap") as r:
        assert r.frame_count() == 30 and r.frame_times()[0] == 1_000_000_000
        # the log wrote its calibration once, in the lost chunk: its frames are refused,
        # not read with a guessed field of view
        with pytest.raises(LogFormatError, match="no camera calibration"):
            list(r.frames())


def test_a_damaged_opening_magic_is_a_corrupt_log_that_recovers(log40, tmp_path):
    """One flipped bit in the opening magic: doctor said "not an MCAP file" (exit 2, the
    usage error's) and recovered nothing, though every chunk was intact."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    bad = _flipped(log40, tmp_path, 3)
    d = scan(bad)
    assert d.status == "corrupt" and d.lost_messages == 0
    assert d.problems[0].startswith("the opening magic bytes are damaged (89 4d 43 51")
    full = scan(log40)
    assert recover(bad, tmp_path / "rec.mcap").readable_messages == full.readable_messages
    assert scan(tmp_path / "rec.mcap").status == "complete"
    r = CliRunner().invoke(cli, ["info", str(bad)])
    assert r.exit_code == 2 and "its opening MCAP magic bytes are damaged" in r.output
    assert "--recover OUT.mcap` recovers" in r.output
    cut = tmp_path / "cut.mcap"  # damaged opening and cut short: still doctor's to recover
    cut.write_bytes(bad.read_bytes()[: bad.stat().st_size * 2 // 3])
    r = CliRunner().invoke(cli, ["info", str(cut)])
    assert r.exit_code == 2 and "its opening MCAP magic bytes are damaged" in r.output
    assert scan(cut).readable_messages > 0
    text = tmp_path / "t.mcap"
    text.write_bytes(b"not a log at all, just some text")
    with pytest.raises(LogFormatError, match="not an MCAP file"):
        scan(text)
    # a text file that happens to end with the magic bytes is no log either (it was called
    # one with a damaged opening, "the rest reads as MCAP", and then truncated)
    text.write_bytes(b"notes on the run\n" * 4 + bytes(bad.read_bytes()[-8:]))
    for args in (["info", str(text)], ["doctor", str(text)]):
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 2 and "not an MCAP file" in r.output, args
    wiped = tmp_path / "wiped.mcap"  # the opening and the header's opcode gone: its footer
    data = bytearray(log40.read_bytes())  # still says it is a log
    data[:9] = bytes(9)
    wiped.write_bytes(bytes(data))
    assert scan(wiped).status == "corrupt" and scan(wiped).lost_messages == 0


def test_doctor_reports_the_losses(log40, tmp_path):
    from click.testing import CliRunner

    from sgtool.cli import cli

    lay = layout(log40.read_bytes())
    bad = _flipped(log40, tmp_path, lay.chunks[0].offset + 100)
    r = CliRunner().invoke(cli, ["doctor", str(bad)])
    assert r.exit_code == 1 and "corrupt" in r.output
    assert f"  {S.DEPTH}: 10, log time 0.000 .. 0.900 s" in r.output
    assert "summary ok" in r.output


def _record(lay, opcode):
    return next(r for r in lay.top if r.opcode == opcode)


@pytest.mark.parametrize("opcode", [Opcode.STATISTICS, Opcode.CHUNK_INDEX,
                                    Opcode.ATTACHMENT_INDEX, Opcode.METADATA_INDEX,
                                    Opcode.SUMMARY_OFFSET, Opcode.FOOTER])
def test_damaged_summary_is_not_complete_and_not_read(log40, tmp_path, opcode):
    lay = layout(log40.read_bytes())
    rec = lay.footer[0] if opcode == Opcode.FOOTER else _record(lay, opcode).offset
    bad = _flipped(log40, tmp_path, rec + 9 + 1)  # the second byte of its first field
    assert scan(bad).status == "corrupt"
    with pytest.raises(LogFormatError, match="doctor"):
        summarize(bad)


def test_damaged_statistics_times_are_refused_not_printed(log40, tmp_path):
    """The old reader printed a time span of 72 million seconds."""
    lay = layout(log40.read_bytes())
    st = _record(lay, Opcode.STATISTICS)
    data = bytearray(log40.read_bytes())
    # message_count (8) schema_count (2) channel_count (4) attachment_count (4)
    # metadata_count (4) chunk_count (4), then message_start_time
    data[st.offset + 9 + 26 + 7] ^= 0x01
    bad = tmp_path / "stats.mcap"
    bad.write_bytes(bytes(data))
    d = scan(bad)
    assert d.status == "corrupt" and d.checks["summary"] == "mismatch"
    with pytest.raises(LogFormatError, match="summary section is damaged"):
        summarize(bad)


def test_damaged_attachment_is_found(log40, tmp_path):
    lay = layout(log40.read_bytes())
    att = _record(lay, Opcode.ATTACHMENT)
    bad = _flipped(log40, tmp_path, att.end - 10)  # inside the house JSON
    d = scan(bad)
    assert d.status == "corrupt" and any("attachment" in p for p in d.problems)
    with LogReader(bad) as r, pytest.raises(LogFormatError, match="attachment"):
        r.house_json()


def test_damaged_message_index_is_found(log40, tmp_path):
    lay = layout(log40.read_bytes())
    mi = _record(lay, Opcode.MESSAGE_INDEX)
    bad = _flipped(log40, tmp_path, mi.end - 3)  # the offset of its last entry
    assert scan(bad).status == "corrupt"


def test_damaged_chunk_length_is_an_error_not_a_memory_error(log40, tmp_path):
    lay = layout(log40.read_bytes())
    c = lay.chunks[2]
    data = bytearray(log40.read_bytes())
    clen = struct.unpack_from("<I", data, c.offset + 9 + 28)[0]
    rl = c.offset + 9 + 32 + clen  # the chunk's records length field
    data[rl + 6] = 0x7F  # about 2**55 bytes
    bad = tmp_path / "len.mcap"
    bad.write_bytes(bytes(data))
    try:  # the reader clamps the read to the file: the chunk may still decode
        with LogReader(bad) as r:
            assert len(list(r.frames())) == 40
    except LogFormatError as e:
        assert "doctor" in str(e)
    d = recover(bad, tmp_path / "rec.mcap")
    assert d.status == "corrupt"
    assert d.readable_messages >= sum(len(x.messages) for x in lay.chunks if x is not c)


def _nav2(shared_data_dir):
    p = shared_data_dir / "logs" / "rosbag2-mcap" / "evo_nav2_turtlebot.mcap"
    if not p.exists():
        pytest.skip(f"{p} is absent")
    return p


def _mcap_messages(path):
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(c.topic, m.log_time, m.data) for _, c, m in make_reader(f).iter_messages(
            log_time_order=False)]


def test_damaged_header_length_of_a_ros2_mcap_loses_nothing(shared_data_dir, tmp_path):
    src = _nav2(shared_data_dir)
    bad = _flipped(src, tmp_path, 8 + 1 + 2, bit=0x01)  # header record length += 65536
    d = recover(bad, tmp_path / "rec.mcap")
    assert d.status == "corrupt" and d.readable_messages == 8197 and d.lost_messages == 0
    assert sorted(_mcap_messages(tmp_path / "rec.mcap")) == sorted(_mcap_messages(src))


def test_ros2_mcap_cut_inside_its_only_chunk_gives_the_prefix(shared_data_dir, tmp_path):
    src = _nav2(shared_data_dir)
    data = src.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 60 // 100])
    d = recover(cut, tmp_path / "rec.mcap")
    assert d.status == "truncated" and d.lost_unknown
    assert d.readable_messages > 6000  # of 8197, all in one zstd chunk
    got = _mcap_messages(tmp_path / "rec.mcap")
    assert len(got) == d.readable_messages
    # what comes back is exactly the first messages of the original, in file order
    assert sorted(got) == sorted(_mcap_messages(src)[: len(got)])


def test_a_record_written_malformed_is_found_and_left_out(tmp_path):
    """A log whose CRCs all hold but whose writer wrote one empty episode record: doctor
    calls it corrupt (replay would refuse it) and --recover copies everything else, so the
    copy replays."""
    from support.logfixtures import synthetic_frame

    from sgtool.log import LogWriter

    log = tmp_path / "bad.mcap"
    kind = S.RECORDS["episode"]
    with LogWriter(log, seed=1) as w:
        for i in range(3):
            k, rgb, depth, ids, pose, _ = synthetic_frame(i)
            w.write_frame(i * 100_000_000, depth=depth, pose=pose, intrinsics=k, rgb=rgb)
        c = w.copy_channel(kind.topic, kind.schema_name, "jsonschema", kind.schema_bytes(),
                           "json")
        w.write_raw(c, 250_000_000, b"")
    d = scan(log)
    assert d.status == "corrupt" and d.dropped_messages == 1
    assert any("/sgtool/episode were written malformed" in p for p in d.problems)
    out = tmp_path / "fixed.mcap"
    r = recover(log, out)
    assert r.readable_messages == d.readable_messages and r.dropped_messages == 1
    with LogReader(out) as rd:
        assert rd.frame_count() == 3 and list(rd.records("episode")) == []
    assert scan(out).status == "complete"
