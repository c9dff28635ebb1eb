"""Regenerate the golden logs of ``tests/golden`` (on purpose only; say why in the commit).

    .venv/bin/python tests/golden/regenerate.py            # re-pin from the same logs
    .venv/bin/python tests/golden/regenerate.py --record   # re-record the logs first (PyBullet)

The first after a deliberate change of the replay pipeline or of the shipped weights; the
second after a change of the recorder or of the house generator. The cases and the replay
options are :mod:`sgtool.replayers.golden`'s; pinning is ``sgtool golden pin``'s own code
(:func:`sgtool.analysis.golden_check.pin_logs`, the format users pin their logs in);
recording lives here because it needs the simulator, which the replayers never import.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from sgtool.analysis.golden_check import pin_logs
from sgtool.datasets.generator import generate_house
from sgtool.recorders.sim.camera import CameraConfig
from sgtool.recorders.sim.recording import RecordOptions, record_house
from sgtool.replayers.golden import CASES, REPLAY, GoldenCase

GOLDEN_FOLDER = Path(__file__).resolve().parent  # tests/golden of this checkout


def record_case(case: GoldenCase, folder: Path) -> Path:
    """Record the case's log (PyBullet) into ``folder``."""
    house = generate_house(case.seed, rooms=(case.rooms, case.rooms))
    out = folder / f"{case.name}.mcap"
    opts = RecordOptions(fps=case.fps, frames=case.frames,
                         camera=CameraConfig(width=case.width, height=case.height))
    record_house(house, out, opts, house_id=f"house-{case.seed}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="tests/golden/regenerate.py",
        description="Regenerate the golden logs' expected scene graphs (tests/golden).")
    ap.add_argument("--folder", type=Path, default=None,
                    help="golden folder (default: tests/golden of this checkout)")
    ap.add_argument("--record", action="store_true",
                    help="re-record the logs with PyBullet first")
    a = ap.parse_args(argv)
    folder = a.folder or GOLDEN_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    if a.record:
        for case in CASES:
            path = record_case(case, folder)
            print(f"recorded {path} ({path.stat().st_size / 1e6:.2f} MB)", file=sys.stderr)
    for case in CASES:
        pins = pin_logs([folder / f"{case.name}.mcap"], folder, REPLAY, why=case.why)
        e = pins.logs[case.name]
        print(f"{case.name}: {e.refreshes} refreshes, final {e.final_sha256[:16]}",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
