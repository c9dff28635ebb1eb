"""Writing the derived log: input chunks copied as they are against written message by
message (decoded, rechunked, recompressed), in one process, alternating rounds.

Per round, ``replay(LOG, OUT)`` with ``copy_chunks=True`` and ``copy_chunks=False``
(median CPU seconds, ``time.process_time``, one BLAS thread, :func:`harness.alternate`);
then both derived logs are read back and compared message for message (topic, log time,
bytes, order), and the share of input chunks the copy took as they are is printed.

Usage: ``python benchmarks/chunk_copy.py [LOG] [--rounds 3]`` (default LOG: the 10-room
benchmark log of ``benchmarks/replay.py`` when it is cached).
"""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Callable
from pathlib import Path

from harness import add_output_options, alternate, emit, log_given
from side_by_side import temporary_folder

from sgtool.blas import single_blas_thread
from sgtool.log import LogReader
from sgtool.replayers.derived_log import replay

DEFAULT = Path(tempfile.gettempdir()) / "sgtool-bench-replay" / \
    "house3_10rooms_320x240_fps4.mcap"


def read_back(path: Path) -> list[tuple[str, int, bytes]]:
    with LogReader(path) as r:
        return [(c.topic, m.log_time, bytes(m.data)) for _, c, m in r.raw_messages()]


def copied_share(log: Path, out: Path) -> tuple[int, int]:
    """(input chunks found byte for byte in ``out``, input chunks)."""
    data, derived = log.read_bytes(), out.read_bytes()
    with LogReader(log) as r:
        recs = [data[ci.chunk_start_offset:ci.chunk_start_offset + ci.chunk_length]
                for ci in r.summary.chunk_indexes]
    return sum(rec in derived for rec in recs), len(recs)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log", type=Path, nargs="?", default=DEFAULT)
    ap.add_argument("--rounds", type=int, default=3)
    a = add_output_options(ap).parse_args(argv)
    log_given(ap, a.log)
    out = temporary_folder("sgtool-chunk-copy-")
    frames: dict[bool, int] = {}

    def case(copy: bool) -> Callable[[], None]:
        def run() -> None:
            frames[copy] = replay(a.log, out / f"{copy}.mcap", copy_chunks=copy).frames
        return run

    with single_blas_thread():
        timings = alternate({"copied": case(True), "rewritten": case(False)}, a.rounds)
    same = read_back(out / "True.mcap") == read_back(out / "False.mcap")
    got, total = copied_share(a.log, out / "True.mcap")
    c, w = timings["copied"].cpu_s, timings["rewritten"].cpu_s
    n = frames[True]
    print(f"{a.log.name}: {n} frames, median CPU s of {a.rounds} alternating rounds")
    print(f"  chunks copied      {c:7.2f} s  {n / c:6.1f} frames/CPU-s")
    print(f"  message by message {w:7.2f} s  {n / w:6.1f} frames/CPU-s")
    print(f"  saved {w - c:.2f} CPU s ({(w - c) / w:.0%}); {got} of {total} input chunks "
          f"copied as they are; same messages in the same order: {same}")
    emit({"log": str(a.log), "frames": n, "timings": timings, "same": same,
          "chunks_copied": got, "chunks": total}, a.json_out)
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
