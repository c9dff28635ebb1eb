"""The chunk-by-chunk ordered reader gives exactly the mcap reader's log-time order, and
checks chunk CRCs only when asked."""

from __future__ import annotations

import random

import pytest
import zstandard
from mcap.data_stream import RecordBuilder
from mcap.reader import SeekingReader
from mcap.records import Chunk, ChunkIndex
from mcap.writer import CompressionType, Writer
from support.logfixtures import write_log

from sgtool.errors import LogFormatError
from sgtool.log import LogReader
from sgtool.log.chunk_stream import ChunkBuffers, ChunkError, chunk_data, ordered_messages


def _overlapping_log(path, seed: int, compression: CompressionType) -> None:
    """Three channels, 400 messages at shuffled times (many ties), tiny chunks, so chunks
    overlap in time and messages inside a chunk are out of order."""
    rng = random.Random(seed)
    with open(path, "wb") as f:
        w = Writer(f, chunk_size=300, compression=compression)
        w.start()
        sid = w.register_schema("s", "jsonschema", b"{}")
        cids = [w.register_channel(f"/t{i}", "json", sid) for i in range(3)]
        for i in range(400):
            t = rng.randrange(0, 60) * 1000
            w.add_message(rng.choice(cids), log_time=t, publish_time=t,
                          data=f'{{"i": {i}}}'.encode(), sequence=i)
        w.finish()


def _view(items) -> list[tuple[str, int, int, bytes]]:  # noqa: ANN001
    return [(c.topic, m.log_time, m.sequence, bytes(m.data)) for _, c, m in items]


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("compression", [CompressionType.ZSTD, CompressionType.LZ4,
                                         CompressionType.NONE])
def test_order_equals_the_mcap_reader_on_overlapping_chunks(tmp_path, seed, compression):
    path = tmp_path / "o.mcap"
    _overlapping_log(path, seed, compression)
    with open(path, "rb") as f:
        r = SeekingReader(f)
        s = r.get_summary()
        assert len(s.chunk_indexes) > 10
        for topics, start, end in [(None, None, None), (["/t0", "/t2"], None, None),
                                   (None, 10_000, 30_000), (["/t1"], 5_000, 5_001)]:
            want = _view(r.iter_messages(topics=topics, starting_at=start,
                                         ending_before=end, log_time_order=True))
            got = _view(ordered_messages(f, s, topics, start_ns=start, end_ns=end))
            assert got == want and (len(want) > 0 or topics == ["/t1"])


def test_crc_is_checked_only_when_asked(tmp_path):
    """A flipped byte inside a stored (uncompressed) chunk: the CRC catches it with
    verify=True; without, the image decodes and the frames come back (doctor finds it)."""
    path = write_log(tmp_path / "a.mcap", n=6, compression="none")
    data = bytearray(path.read_bytes())
    with LogReader(path) as r:
        ci = r.summary.chunk_indexes[-1]
    at = ci.chunk_start_offset + ci.chunk_length - 40  # inside the last message's data
    data[at] ^= 0x01
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    with LogReader(bad) as r:
        assert len(list(r.frames())) == 6
    with LogReader(bad, verify=True) as r, pytest.raises(LogFormatError, match="doctor"):
        list(r.frames())


def test_replay_refuses_a_damaged_chunk(tmp_path):
    """`sgtool replay` checks the input's CRCs (also without an output, and so does
    `golden pin`): one line naming `sgtool doctor`, no output written; `--no-verify`
    reads what the chunks hold."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    path = write_log(tmp_path / "a.mcap", n=6, compression="none")
    data = bytearray(path.read_bytes())
    with LogReader(path) as r:
        ci = r.summary.chunk_indexes[-1]
    data[ci.chunk_start_offset + ci.chunk_length - 40] ^= 0x01
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    out = tmp_path / "d.mcap"
    res = CliRunner().invoke(cli, ["replay", str(bad), "-o", str(out), "--verify"])
    assert res.exit_code == 2 and "Traceback" not in res.output and "doctor" in res.output
    assert len(res.output.strip().splitlines()) == 1 and "CRC" in res.output
    assert not out.exists() and not list(tmp_path.glob("d.mcap*"))
    for args in (["replay", str(bad)], ["golden", "pin", str(bad), "--dir", str(tmp_path / "g")]):
        res = CliRunner().invoke(cli, args)
        assert res.exit_code == 2 and "CRC" in res.output and "doctor" in res.output, res.output
    assert not (tmp_path / "g").exists()
    res = CliRunner().invoke(cli, ["replay", str(bad), "--no-verify", "--json"])
    assert "CRC" not in res.output  # here the flipped byte is in the episode's JSON
    assert res.exit_code == 2 and "is not JSON" in res.output, res.output


def test_buffers_are_reused_only_when_no_view_of_them_lives():
    pool = ChunkBuffers(keep=2)
    a = pool.take(100)
    view = memoryview(a)[10:20]  # what a message's data is
    del a
    b = pool.take(50)
    assert b is not None and len(b) == 50  # the second buffer
    assert pool.take(10) is None  # both taken: the caller decompresses into a new one
    del view
    c = pool.take(200)  # the first one again, grown
    assert c is not None and len(c) == 200
    assert pool.take(10) is None  # ``b`` still lives
    del b, c
    assert pool.take(10) is not None
    assert ChunkBuffers(max_bytes=1000).take(1001) is None  # huge chunks: not kept


@pytest.mark.parametrize("compression", [CompressionType.ZSTD, CompressionType.LZ4])
def test_views_into_reused_buffers_keep_their_bytes(tmp_path, compression):
    path = tmp_path / "o.mcap"
    _overlapping_log(path, 4, compression)
    with open(path, "rb") as f:
        r = SeekingReader(f)
        s = r.get_summary()
        want = _view(r.iter_messages(log_time_order=True))
        pool = ChunkBuffers(keep=3)
        # every view kept to the end: the pool runs dry and falls back to fresh buffers
        kept = list(ordered_messages(f, s, views=True, buffers=pool))
        assert all(isinstance(m.data, memoryview) for _, _, m in kept)
        assert _view(kept) == want
        # views dropped as they are read: buffers are reused, bytes still right
        got = [(c.topic, m.log_time, m.sequence, bytes(m.data))
               for _, c, m in ordered_messages(f, s, views=True, buffers=pool)]
        assert got == want


def _zstd_chunk(body: bytes, size: int) -> tuple[bytes, ChunkIndex]:
    """A zstd chunk record of ``body`` whose header says ``size`` bytes, and its index."""
    comp = zstandard.compress(body)
    b = RecordBuilder()
    Chunk(message_start_time=0, message_end_time=0, uncompressed_size=size,
          uncompressed_crc=0, compression="zstd", data=comp).write(b)
    raw = b.end()
    return raw, ChunkIndex(message_start_time=0, message_end_time=0, chunk_start_offset=0,
                           chunk_length=len(raw), message_index_offsets={},
                           message_index_length=0, compression="zstd",
                           compressed_size=len(comp), uncompressed_size=size)


def test_a_zstd_chunk_longer_or_shorter_than_its_header_says_is_damage():
    body = bytes(range(200)) * 3
    for pool in (None, ChunkBuffers()):
        assert bytes(chunk_data(*_zstd_chunk(body, 600), False, pool)) == body
        for size in (599, 601):
            with pytest.raises((ChunkError, zstandard.ZstdError)):
                chunk_data(*_zstd_chunk(body, size), False, pool)
