"""Reading a log as frames against the ``mcap`` package's own reader on the same file.

Per round (rounds alternate the order of the readers; figures are frames per CPU-second,
``time.process_time``, medians over the rounds):

- ``mcap raw``: ``mcap.reader.make_reader(f).iter_messages(log_time_order=True)`` over
  every message, CRCs not checked (the package default): the floor;
- ``mcap + protobuf``: the same, with the frame topics parsed into their Foxglove
  protobuf classes;
- ``LogReader.raw_messages``: sgtool's reader, every message undecoded (what replay
  reads before it decodes the channels it needs);
- ``LogReader.frames``: sgtool's reader, frames assembled (images decoded, depth in
  metres, poses composed from the transforms), CRCs not checked (the default);
- ``LogReader.frames --verify``: the same with every chunk CRC checked.

Target (issue 20): ``LogReader.frames`` >= 0.8x ``mcap raw``.

Usage: ``python benchmarks/read_floor.py [LOG] [--rounds 5]`` (default LOG: the 10-room
benchmark log of ``benchmarks/replay.py`` when it is cached).
"""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Callable
from pathlib import Path

from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from harness import add_output_options, alternate, emit, log_given
from mcap.reader import make_reader

from sgtool.log import LogReader
from sgtool.log import schemas as S

DEFAULT = Path(tempfile.gettempdir()) / "sgtool-bench-replay" / \
    "house3_10rooms_320x240_fps4.mcap"
PROTO = {S.RGB: RawImage, S.DEPTH: RawImage, S.IDS: RawImage, S.TF: FrameTransform,
         S.CALIBRATION: CameraCalibration}


def mcap_raw(path: Path) -> int:
    with open(path, "rb") as f:
        return sum(1 for _, c, _ in make_reader(f).iter_messages(log_time_order=True)
                   if c.topic == S.DEPTH)


def mcap_protobuf(path: Path) -> int:
    n = 0
    with open(path, "rb") as f:
        for _, c, m in make_reader(f).iter_messages(log_time_order=True):
            cls = PROTO.get(c.topic)
            if cls is not None:
                cls().ParseFromString(m.data)
                n += c.topic == S.DEPTH
    return n


def ours_raw(path: Path) -> int:
    with LogReader(path) as r:
        return sum(1 for _, c, _ in r.raw_messages() if c.topic == S.DEPTH)


def ours(path: Path, verify: bool = False) -> int:
    with LogReader(path, verify=verify) as r:
        return sum(1 for _ in r.frames())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log", type=Path, nargs="?", default=DEFAULT)
    ap.add_argument("--rounds", type=int, default=5)
    a = add_output_options(ap).parse_args(argv)
    log_given(ap, a.log)
    readers: dict[str, Callable[[Path], int]] = {
        "mcap raw": mcap_raw,
        "mcap + protobuf": mcap_protobuf,
        "LogReader.raw_messages": ours_raw,
        "LogReader.frames": ours,
        "LogReader.frames --verify": lambda p: ours(p, verify=True),
    }
    counts: dict[str, int] = {}

    def case(name: str) -> Callable[[], None]:
        def run() -> None:
            counts[name] = readers[name](a.log)
        return run

    timings = alternate({name: case(name) for name in readers}, a.rounds)
    rates = {name: t.per_cpu_s(counts[name]) for name, t in timings.items()}
    floor = rates["mcap raw"]
    print(f"{a.log.name}: frames per CPU-second, median of {a.rounds} alternating rounds")
    for name, med in rates.items():
        print(f"  {name:<27}{med:>8.0f}   {med / floor:.2f}x mcap raw")
    emit({"log": str(a.log), "frames": counts, "frames_per_cpu_s": rates, "timings": timings},
         a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
