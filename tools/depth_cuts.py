"""The depth each log's replay would map to, measured on its first frames.

For each LOG (globs allowed): the vertical noise of the floor at the farthest depth bin
measured and the depth the replay maps to (``sgtool.replayers.depth_range.first_frames``:
(N1)-(N2) of ``sgtool.mapping.depth_noise``), or why nothing was measured; to compare the
estimator before and after a change on the same logs:

    .venv/bin/python tools/depth_cuts.py 'scache/*/*.mcap' > after.txt
"""

from __future__ import annotations

import argparse
import glob
import sys

from sgtool.errors import SgtoolError
from sgtool.log.reader import LogReader
from sgtool.replayers.depth_range import first_frames
from sgtool.scenegraph.build_options import MAX_DEPTH_M


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("logs", nargs="+", help="sgtool logs (globs allowed)")
    args = ap.parse_args(argv)
    paths = sorted({p for a in args.logs for p in (glob.glob(a) or [a])})
    failed = 0
    for path in paths:
        try:
            with LogReader(path) as r:
                recorded = (r.last_record("episode") or {}).get("extra", {}).get("mapping")
                n = first_frames(r, MAX_DEPTH_M).noise
        except SgtoolError as e:
            print(f"{path}: error: {e}")
            failed += 1
            continue
        if recorded is not None:  # a closed-loop log: replay maps as its live map did
            depth = recorded.get("max_depth", MAX_DEPTH_M)
            print(f"{path}: records its live map's depth: maps to {depth:g} m")
        elif n is None:
            print(f"{path}: not measured (no floor at height 0, or too few points below it)")
        else:
            depth = f"{n.max_depth:g} m" if n.max_depth is not None else f"{MAX_DEPTH_M:g} m"
            print(f"{path}: sigma {n.sigma[-1]:.4f} m at {n.depths[-1]:g} m; maps to {depth}")
    return 2 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
