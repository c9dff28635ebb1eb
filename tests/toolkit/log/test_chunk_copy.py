"""Chunks copied from one log into another as they are (sgtool.log.chunk_copy): the copy
reads back with the same messages, passes every check of `sgtool doctor`, and is refused
where it would not be exact."""

from __future__ import annotations

import dataclasses

from mcap.reader import make_reader
from mcap.records import Channel, Schema
from mcap.summary import Summary

from sgtool.log import LogReader, LogWriter
from sgtool.log.chunk_copy import ids_problem, in_sequence, raw_chunk, writer_supported
from sgtool.log.chunk_stream import read_chunk
from sgtool.log.recover import scan

S_NS = 1_000_000_000


def source_log(path, compression="zstd"):
    """Two JSON-free raw channels, 3 s of messages at 4 Hz: one chunk per second."""
    with LogWriter(path, compression=compression) as w:
        a = w.copy_channel("/a", "A", "jsonschema", b"{}", "json")
        b = w.copy_channel("/b", "", "", b"", "raw")
        for i in range(12):
            w.write_raw(a, i * S_NS // 4, b'{"i": %d}' % i)
            if i % 3 == 0:
                w.write_raw(b, i * S_NS // 4, bytes([i]) * 50)
    return path


def all_messages(path):
    """(topic, log time, publish time, sequence, bytes) as the mcap package reads them."""
    with open(path, "rb") as f:
        return [(c.topic, m.log_time, m.publish_time, m.sequence, bytes(m.data))
                for _, c, m in make_reader(f).iter_messages(log_time_order=True)]


def copy_log(src, dst, compression="zstd", extra=True):
    """Every chunk of ``src`` copied into ``dst``; with ``extra`` a message of a new
    channel between the chunks, written by the writer itself. Returns the copies made."""
    copied = 0
    with LogReader(src) as r, LogWriter(dst, compression=compression) as w:
        assert w.copy_channels(r.summary)
        c = w.copy_channel("/c", "", "", b"", "raw")
        for i, ci in enumerate(sorted(r.summary.chunk_indexes,
                                      key=lambda ci: ci.chunk_start_offset)):
            chunk = raw_chunk(r._f, ci, read_chunk(r._f, ci))
            assert chunk is not None
            copied += w.copy_chunk(chunk)
            if extra:
                w.write_raw(c, ci.message_end_time, b"derived %d" % i)
    return copied


def test_copied_chunks_read_back_the_same_and_pass_doctor(tmp_path):
    src = source_log(tmp_path / "in.mcap")
    dst = tmp_path / "out.mcap"
    with LogReader(src) as r:
        n_chunks = len(r.summary.chunk_indexes)
    assert n_chunks == 3
    assert copy_log(src, dst) == 3
    got = all_messages(dst)
    assert [m for m in got if m[0] != "/c"] == all_messages(src)
    # the writer's own message of each chunk's end time comes after that chunk's messages
    assert [m[4] for m in got if m[0] == "/c"] == [b"derived 0", b"derived 1", b"derived 2"]
    # chunk 0 holds /a at 0, 0.25, 0.5, 0.75 s and /b at 0 and 0.75 s
    assert got.index(next(m for m in got if m[4] == b"derived 0")) == 6
    for log in (src, dst):  # no attachments: an empty summary group is no damage
        d = scan(log)
        assert d.status == "complete", d.problems
        assert d.checks["data"] == "ok"  # the copied bytes are in the data-section CRC
    with LogReader(dst, verify=True) as r:
        st = r.summary.statistics
        assert st.message_count == 12 + 4 + 3 and st.chunk_count == 6
        assert st.channel_message_counts == {1: 12, 2: 4, 3: 3}
        assert (st.message_start_time, st.message_end_time) == (0, 11 * S_NS // 4)
        assert [m for _, ch, m in r.raw_messages() if ch.topic == "/a"][3].data == b'{"i": 3}'
    # the chunk records are in the output byte for byte
    src_bytes, dst_bytes = src.read_bytes(), dst.read_bytes()
    with LogReader(src) as r:
        for ci in r.summary.chunk_indexes:
            start = ci.chunk_start_offset
            assert src_bytes[start:start + ci.chunk_length] in dst_bytes


def test_a_chunk_compressed_otherwise_is_not_copied(tmp_path):
    src = source_log(tmp_path / "in.mcap", compression="lz4")
    dst = tmp_path / "out.mcap"
    assert copy_log(src, dst, extra=False) == 0
    with LogReader(dst) as r:
        assert r.summary.statistics.message_count == 0


def test_damaged_message_indexes_are_not_copied(tmp_path):
    src = source_log(tmp_path / "in.mcap")
    with LogReader(src) as r:
        ci = r.summary.chunk_indexes[0]
        record = read_chunk(r._f, ci)
        chunk = raw_chunk(r._f, ci, record)
        assert chunk is not None and chunk.counts == {1: 4, 2: 2}
        moved = dataclasses.replace(ci, message_index_offsets={
            k: v + 1 for k, v in ci.message_index_offsets.items()})
        assert raw_chunk(r._f, moved, record) is None
        assert raw_chunk(r._f, dataclasses.replace(ci, message_index_length=5), record) is None
        # a chunk record whose own length field disagrees with the index
        bad_length = record[:1] + (len(record) - 8).to_bytes(8, "little") + record[9:]
        assert raw_chunk(r._f, ci, bad_length) is None


def test_no_copy_into_a_writer_without_the_state_it_updates(tmp_path):
    """Copying writes into the mcap writer's private state (chunk indexes, statistics,
    the running data-section CRC): a writer that has it not takes no copies (replay then
    writes message by message)."""
    src = source_log(tmp_path / "in.mcap")
    with LogReader(src) as r:
        with LogWriter(tmp_path / "ok.mcap") as w:
            assert writer_supported(w._mcap)
        with LogWriter(tmp_path / "crc.mcap") as w:
            crc = w._mcap.__dict__.pop("_Writer__data_section_crc")
            assert not writer_supported(w._mcap) and not w.copy_channels(r.summary)
            w._mcap._Writer__data_section_crc = crc  # let it close
        with LogWriter(tmp_path / "renamed.mcap") as w:
            w._mcap._renamed = w._mcap.__dict__.pop("_Writer__chunk_indices")
            assert not writer_supported(w._mcap) and not w.copy_channels(r.summary)
            w._mcap._Writer__chunk_indices = w._mcap._renamed  # let it close


def test_a_copy_into_a_writer_without_data_crcs_writes_none(tmp_path):
    """A writer that keeps no data-section CRC (as ``mcap``'s default) takes copies and
    writes a CRC of 0 ("not written"), never one that misses the copied bytes."""
    src = source_log(tmp_path / "in.mcap")
    dst = tmp_path / "out.mcap"
    with LogReader(src) as r, LogWriter(dst) as w:
        w._mcap._Writer__enable_data_crcs = False  # as if made so: no CRC of the start
        w._mcap._Writer__data_section_crc = 0
        assert w.copy_channels(r.summary)
        for ci in r.summary.chunk_indexes:
            assert w.copy_chunk(raw_chunk(r._f, ci, read_chunk(r._f, ci)))
    d = scan(dst)
    assert d.status == "complete" and d.checks["data"] == "not written"
    assert all_messages(dst) == all_messages(src)


def test_a_flipped_byte_outside_every_chunk_is_found(tmp_path):
    """Metadata and attachments sit outside chunks: the data-section CRC that sgtool
    writes is what shows a byte of them changed (the chunk CRCs cannot)."""
    log = source_log(tmp_path / "in.mcap")
    data = bytearray(log.read_bytes())
    at = data.index(b"sgtool_version")  # in the metadata record, before every chunk
    data[at] ^= 0x20
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    assert scan(log).checks["data"] == "ok"
    d = scan(bad)
    assert d.checks["data"] == "mismatch" and d.status == "corrupt"
    assert any("data section CRC" in p for p in d.problems)


def summary(schemas, channels, chunks):
    out = Summary()
    out.schemas, out.channels, out.chunk_indexes = schemas, channels, chunks
    return out


def test_ids_must_be_one_to_n_and_chunks_in_sequence(tmp_path):
    sch = Schema(id=1, name="A", encoding="jsonschema", data=b"{}")
    ch = Channel(id=1, topic="/a", message_encoding="json", schema_id=1, metadata={})
    with LogReader(source_log(tmp_path / "in.mcap")) as r:
        chunks = r.summary.chunk_indexes
    assert ids_problem(summary({1: sch}, {1: ch}, chunks)) is None
    assert ids_problem(summary({1: sch}, {1: ch}, [])) == "the log has no chunks"
    assert ids_problem(summary({2: sch}, {1: ch}, chunks)) == "schema ids are not 1..N"
    assert ids_problem(summary({1: sch}, {3: ch}, chunks)) == "channel ids are not 1..N"
    assert in_sequence(chunks)
    late = dataclasses.replace(chunks[0], chunk_start_offset=chunks[-1].chunk_start_offset + 1)
    assert not in_sequence([late, *chunks[1:]])


def test_copy_channels_only_into_an_empty_writer(tmp_path):
    src = source_log(tmp_path / "in.mcap")
    with LogReader(src) as r, LogWriter(tmp_path / "out.mcap") as w:
        w.copy_channel("/z", "", "", b"", "raw")
        assert not w.copy_channels(r.summary)
