"""`sgtool import bag` on bare ROS 2 MCAP files that other tools write: the same messages in
MCAP layouts the specification allows but the ROS bag reader (``rosbags``) does not follow
import as the bag folder does; schemas named ``pkg/Type`` import as ``pkg/msg/Type``
ones do; messages compressed one by one (rosbag2's message compression) outside their bag
folder are named as such."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from mcap.reader import make_reader
from mcap.writer import IndexType, Writer
from support.bag_export import write_log_as_bag
from support.logfixtures import synthetic_frame

from sgtool.cli import cli
from sgtool.log import LogReader, LogWriter
from sgtool.recorders.importers.bag import BagOptions, import_bag

TOPICS = dict(depth="/camera/depth/image_raw", rgb="/camera/rgb/image_raw",
              info="/camera/depth/camera_info")
OPTS = dict(**TOPICS, up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)


def write_sgtool_log(path: Path, n: int) -> Path:
    with LogWriter(path, seed=1) as w:
        for i in range(n):
            k, rgb, depth, _, pose, _ = synthetic_frame(i)
            w.write_frame(1_700_000_000_000_000_000 + i * 33_333_333, depth=depth, pose=pose,
                          intrinsics=k, rgb=rgb)
    return path


def _ros2_mcap(tmp: Path, **bag_kw) -> Path:
    """The storage file of a ROS 2 MCAP bag of 6 synthetic frames."""
    bag = tmp / "bag"
    write_log_as_bag(write_sgtool_log(tmp / "src.mcap", n=6), bag, "ros2-mcap", **bag_kw)
    (part,) = sorted(bag.glob("*.mcap"))
    return part


def _rewrite(src: Path, dst: Path, *, shuffle: bool = False, short_names: bool = False,
             **writer_kw) -> Path:
    """``src``'s schemas, channels and messages into a new MCAP file ``dst`` written with
    ``writer_kw`` (chunking, indexes, what the summary repeats), the messages in reverse
    order with ``shuffle``, the schemas named ``pkg/Type`` with ``short_names``."""
    with open(src, "rb") as f:
        reader = make_reader(f)
        msgs = list(reader.iter_messages(log_time_order=False))
    if shuffle:
        msgs.reverse()
    with open(dst, "wb") as g:
        w = Writer(g, **writer_kw)
        w.start(profile="ros2", library="test")
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        for schema, ch, m in msgs:
            assert schema is not None
            if schema.id not in schemas:
                name = schema.name.replace("/msg/", "/") if short_names else schema.name
                schemas[schema.id] = w.register_schema(name, schema.encoding, schema.data)
            if ch.id not in channels:
                channels[ch.id] = w.register_channel(ch.topic, ch.message_encoding,
                                                     schemas[schema.id], ch.metadata)
            w.add_message(channels[ch.id], m.log_time, m.data, m.publish_time, m.sequence)
        w.finish()
    return dst


def _frames(log: Path) -> list:
    with LogReader(log) as r:
        return list(r.frames())


def _same_frames(a: Path, b: Path) -> None:
    fa, fb = _frames(a), _frames(b)
    assert len(fa) == len(fb) == 6
    for x, y in zip(fa, fb, strict=True):
        assert x.time_ns == y.time_ns and np.array_equal(x.depth, y.depth)
        assert np.allclose(x.pose, y.pose, atol=1e-9)


@pytest.mark.parametrize("layout", [
    dict(use_chunking=False),
    dict(index_types=IndexType.NONE),
    dict(repeat_channels=False, repeat_schemas=False),
    dict(use_statistics=False, use_summary_offsets=False, repeat_channels=False,
         repeat_schemas=False, index_types=IndexType.NONE),
    dict(chunk_size=2000, shuffle=True),
    dict(short_names=True),
    dict(repeat_channels=False),
    dict(repeat_schemas=False),
    dict(index_types=IndexType.CHUNK),
    dict(use_chunking=False, shuffle=True),
], ids=["unchunked", "no-index", "no-repeats", "no-summary", "chunks-out-of-order",
        "pkg-Type-schema-names", "channels-not-repeated", "schemas-not-repeated",
        "no-message-index", "unchunked-out-of-order"])
def test_mcap_layouts_import_as_the_bag_folder_does(tmp_path, layout):
    """Every layout the MCAP specification allows imports the frames the bag folder gives,
    also those the ROS bag reader alone reads as having no topic (channels not repeated in
    the summary), schemaless topics (schemas not repeated), no messages (no message
    index) or as damaged (unchunked, out of log-time order): those are read through an
    indexed copy."""
    part = _ros2_mcap(tmp_path)
    ref = tmp_path / "ref.mcap"
    import_bag(part.parent, ref, BagOptions(**OPTS))
    bare = _rewrite(part, tmp_path / "bare.mcap", **layout)
    out = tmp_path / "out.mcap"
    import_bag(bare, out, BagOptions(**OPTS))
    _same_frames(ref, out)


def test_pkg_type_schema_names_list_without_a_traceback(tmp_path):
    """Schemas named ``sensor_msgs/Image`` in a ROS 2 MCAP file: --list and the flag
    suggestions decode the first messages too (a KeyError traceback before)."""
    bare = _rewrite(_ros2_mcap(tmp_path), tmp_path / "bare.mcap", short_names=True)
    r = CliRunner().invoke(cli, ["import", "bag", str(bare), "--list"])
    assert r.exit_code == 0 and TOPICS["depth"] in r.output, r.output
    r = CliRunner().invoke(cli, ["import", "bag", str(bare), "-o", str(tmp_path / "o.mcap")])
    assert r.exit_code == 2 and "--depth" in r.output and "Traceback" not in r.output


def test_message_compressed_storage_outside_its_folder_is_named(tmp_path):
    """rosbag2's per-message compression is said only in metadata.yaml: its storage file
    alone is named as such, the folder imports."""
    from rosbags.rosbag2 import (
        CompressionFormat,
        CompressionMode,
        Reader,
        StoragePlugin,
        Writer,
    )
    from rosbags.typesys import Stores, get_typestore

    part = _ros2_mcap(tmp_path)
    ts = get_typestore(Stores.ROS2_HUMBLE)
    bag = tmp_path / "msgcomp"
    w = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    w.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    with Reader(part.parent) as r, w:
        conns = {c.id: w.add_connection(c.topic, c.msgtype, typestore=ts) for c in r.connections}
        for c, t, raw in r.messages():
            w.write(conns[c.id], t, raw)
    import_bag(bag, tmp_path / "ok.mcap", BagOptions(**OPTS))
    (storage,) = bag.glob("*.mcap")
    alone = tmp_path / "alone.mcap"
    alone.write_bytes(storage.read_bytes())
    r = CliRunner().invoke(cli, ["import", "bag", str(alone), "-o", str(tmp_path / "o.mcap"),
                                 "--quiet", "--depth", TOPICS["depth"], "--info",
                                 TOPICS["info"], "--up", "z", "--floor", "none"])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert "zstd-compressed one by one" in r.output and "metadata.yaml" in r.output


def test_a_file_compressed_whole_names_its_folder_or_zstd(tmp_path):
    """rosbag2's file compression (``*.mcap.zstd``): the file alone says to import the bag
    folder or decompress it; inside its folder it is read through the folder."""
    import zstandard

    part = _ros2_mcap(tmp_path)
    alone = tmp_path / "alone.mcap.zstd"
    alone.write_bytes(zstandard.ZstdCompressor().compress(part.read_bytes()))
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "bag", str(alone), "-o", str(out), "--quiet"])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert "a zstd-compressed file" in r.output and f"zstd -d {alone}" in r.output
    assert not out.exists()

    from rosbags.rosbag2 import CompressionFormat, CompressionMode, Reader, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    bag = tmp_path / "filecomp"
    w = Writer(bag, version=9)
    w.set_compression(CompressionMode.FILE, CompressionFormat.ZSTD)
    with Reader(part.parent) as r2, w:
        conns = {c.id: w.add_connection(c.topic, c.msgtype, typestore=ts)
                 for c in r2.connections}
        for c, t, raw in r2.messages():
            w.write(conns[c.id], t, raw)
    (storage,) = [p for p in bag.iterdir() if p.name != "metadata.yaml"]
    ref, got = tmp_path / "ref.mcap", tmp_path / "got.mcap"
    import_bag(part.parent, ref, BagOptions(**OPTS))
    import_bag(storage, got, BagOptions(**OPTS))
    _same_frames(ref, got)


def test_a_damaged_file_read_through_an_index_is_refused(tmp_path):
    """A damaged chunk in a file without a chunk index (read through an indexed copy) is
    refused in one line, as the bag reader refuses it in an indexed file: never imported
    with that chunk's messages left out without a word."""
    import struct

    bare = _rewrite(_ros2_mcap(tmp_path), tmp_path / "bare.mcap", index_types=IndexType.NONE,
                    chunk_size=2000)
    data = bytearray(bare.read_bytes())
    off, chunks = 8, []
    while data[off] != 0x0F:  # up to the data end record
        length = struct.unpack_from("<Q", data, off + 1)[0]
        if data[off] == 0x06:
            chunks.append((off, length))
        off += 9 + length
    at, length = chunks[len(chunks) // 2]
    for i in range(at + 9 + length - 30, at + 9 + length - 20):  # inside its compressed data
        data[i] ^= 0x5A
    bare.write_bytes(bytes(data))
    out = tmp_path / "out.mcap"
    r = CliRunner().invoke(cli, ["import", "bag", str(bare), "-o", str(out), "--quiet",
                                 "--depth", TOPICS["depth"], "--info", TOPICS["info"],
                                 "--up", "z", "--floor", "none"])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert "damaged or truncated bag" in r.output and "--recover" in r.output
    assert not out.exists()


@pytest.mark.parametrize("layout", [
    dict(index_types=IndexType.CHUNK),
    dict(use_chunking=False, shuffle=True),
    dict(repeat_channels=False),
], ids=["no-message-index", "unchunked-out-of-order", "channels-not-repeated"])
def test_a_bag_folder_of_such_storage_files_imports_the_same(tmp_path, layout):
    """rosbag2's storage options write such files inside a bag folder (no chunking, no
    message index): the folder, and its storage file given alone, import the frames a
    plain folder gives."""
    import shutil

    part = _ros2_mcap(tmp_path)
    ref = tmp_path / "ref.mcap"
    import_bag(part.parent, ref, BagOptions(**OPTS))
    folder = tmp_path / "rewritten"
    shutil.copytree(part.parent, folder)
    _rewrite(part, folder / part.name, **layout)
    for given, out in ((folder, tmp_path / "a.mcap"), (folder / part.name, tmp_path / "b.mcap")):
        import_bag(given, out, BagOptions(**OPTS))
        _same_frames(ref, out)
