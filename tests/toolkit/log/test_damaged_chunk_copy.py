"""A chunk whose stored CRC does not match its records is never copied into another log:
``LogReader.chunks`` (what replay copies from) checks every CRC, with or without
``verify``, and ``sgtool replay`` refuses the log in one line that names the log, the
chunk's offset and ``sgtool doctor --recover``, leaving no output file; a replay that
writes the input's messages anew (not copied) checks the CRCs too, so the damage is not
hidden under a fresh CRC."""

from __future__ import annotations

import numpy as np
import pytest
from support.frames_log import NOISE_TOPIC, frames_log

from sgtool.cli import main
from sgtool.errors import LogFormatError
from sgtool.log import LogReader
from sgtool.log.recover import scan
from sgtool.replayers.derived_log import replay


def damaged_log(tmp_path):
    """A frames log with one byte changed inside its (only) chunk, in a stretch of random
    bytes that zstd stored as they are: the chunk decompresses, its CRC no longer matches.
    Returns (path, the chunk's offset)."""
    noise = np.random.default_rng(5).integers(0, 256, 20_000, dtype=np.uint8).tobytes()
    path = frames_log(tmp_path / "flip.mcap", noise=noise)
    data = bytearray(path.read_bytes())
    at = data.find(noise[10_000:10_064])
    assert at > 0 and data.find(noise[10_000:10_064], at + 1) < 0
    data[at + 10] ^= 0xFF
    path.write_bytes(bytes(data))
    with LogReader(path) as r:
        (ci,) = r.summary.chunk_indexes
        assert ci.chunk_start_offset < at < ci.chunk_start_offset + ci.chunk_length
        assert NOISE_TOPIC in r.topics()
    return path, ci.chunk_start_offset


def _one_line_refusal(args: list[str], capsys) -> str:
    """stderr of ``sgtool ARGS``, which must exit 2 with one line and no traceback."""
    with pytest.raises(SystemExit) as e:
        main(args)
    err = capsys.readouterr().err
    assert e.value.code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_the_chunks_to_copy_are_crc_checked_even_without_verify(tmp_path):
    path, offset = damaged_log(tmp_path)
    with LogReader(path) as r, pytest.raises(LogFormatError) as e:
        list(r.chunks(views=True))
    assert f"chunk at byte {offset}: CRC mismatch" in str(e.value)
    assert scan(path).status == "corrupt"  # doctor agrees
    good = frames_log(tmp_path / "good.mcap", noise=b"x" * 100)
    with LogReader(good) as r:
        assert len(list(r.chunks())) == 1


def test_replay_refuses_a_damaged_chunk_in_one_line_and_writes_nothing(tmp_path, capsys):
    path, offset = damaged_log(tmp_path)
    out = tmp_path / "flip_d.mcap"
    err = _one_line_refusal(["replay", str(path), "-o", str(out)], capsys)
    assert err.startswith(f"sgtool: error: {path}: damaged data")
    assert f"chunk at byte {offset}: CRC mismatch" in err
    assert f"`sgtool doctor {path}`" in err and "--recover" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flip.mcap"]  # no output at all


def test_a_replay_that_rewrites_the_messages_refuses_the_damage_too(tmp_path):
    path, offset = damaged_log(tmp_path)
    out = tmp_path / "rewritten.mcap"
    with pytest.raises(LogFormatError, match=f"chunk at byte {offset}: CRC mismatch"):
        replay(path, out, copy_chunks=False)
    assert not out.exists()
    good = frames_log(tmp_path / "good.mcap", noise=b"x" * 100)
    assert replay(good, out, copy_chunks=False).frames == 4  # the control


def test_view_refuses_a_damaged_chunk_in_one_line_and_writes_no_rrd(tmp_path, capsys):
    pytest.importorskip("rerun")
    path, offset = damaged_log(tmp_path)
    rrd = tmp_path / "flip.rrd"
    err = _one_line_refusal(["view", str(path), "-o", str(rrd)], capsys)
    assert f"chunk at byte {offset}: CRC mismatch" in err
    assert not rrd.exists() and not list(tmp_path.glob("*.rrd*"))


@pytest.mark.parametrize("fmt", ["ros2", "ros1"])
def test_export_bag_refuses_a_damaged_chunk_in_one_line_and_writes_no_bag(
        tmp_path, capsys, fmt):
    pytest.importorskip("rosbags")
    path, offset = damaged_log(tmp_path)
    out = tmp_path / ("flip.bag" if fmt == "ros1" else "flip_bag")
    err = _one_line_refusal(["export", "bag", str(path), "-o", str(out), "--format", fmt],
                            capsys)
    assert f"chunk at byte {offset}: CRC mismatch" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flip.mcap"]  # no bag at all
