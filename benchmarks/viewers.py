"""Viewer and export figures, run by hand: `sgtool view` time and .rrd size for a synthetic
N-frame log, and `sgtool export bag` time, MB/s and bag/derived size ratio for a derived
log (ros1 and ros2), R repetitions each (median and range).

    .venv/bin/python benchmarks/viewers.py --frames 1000 --derived DERIVED.mcap -r 3

Runs against whatever `sgtool` the interpreter imports (PYTHONPATH can point at another
checkout to compare)."""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from harness import support, timed


def size(p: Path) -> int:
    return sum(f.stat().st_size for f in p.rglob("*")) if p.is_dir() else p.stat().st_size


def spread(xs: list[float]) -> str:
    return f"{statistics.median(xs):.2f} [{min(xs):.2f}, {max(xs):.2f}]"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--derived", type=Path, default=None)
    ap.add_argument("-r", "--repeat", type=int, default=3)
    a = ap.parse_args()
    write_log = support("logfixtures").write_log

    from sgtool.analysis.rerun_view import export

    tmp = Path(tempfile.mkdtemp(prefix="sgtool-viewers."))
    try:
        log = write_log(tmp / "run.mcap", n=a.frames)
        times, sizes = [], []
        for i in range(a.repeat):
            out = tmp / f"v{i}.rrd"
            _, sample = timed(lambda out=out: export(log, out))
            times.append(sample.wall_s)
            sizes.append(out.stat().st_size / 1e6)
        print(f"view {a.frames} frames: {spread(times)} s, rrd {spread(sizes)} MB "
              f"(log {log.stat().st_size / 1e6:.2f} MB)")
        if a.derived is not None:
            from sgtool.recorders.exporters.bag_export import export_bag

            mb = a.derived.stat().st_size / 1e6
            for fmt, name in (("ros2", "bag"), ("ros1", "o.bag")):
                times, ratios = [], []
                for i in range(a.repeat):
                    out = tmp / f"{i}{name}"
                    _, sample = timed(lambda out=out, fmt=fmt: export_bag(a.derived, out, fmt))
                    times.append(sample.wall_s)
                    ratios.append(size(out) / 1e6 / mb)
                print(f"export {fmt}: {spread(times)} s, {spread([mb / t for t in times])} "
                      f"derived MB/s, bag/derived {spread(ratios)} (derived {mb:.2f} MB)")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    main()
