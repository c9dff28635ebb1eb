"""``sgtool golden check`` against replaying the same logs, side by side.

The target: checking N pinned logs of 10-room houses on ``-w 2`` takes at most 1.2x the
time of replaying them on the same 2 workers (a check is a replay plus reading the pins,
comparing canonical JSON, scoring the final graph and re-asking a planner for episode
logs).

Logs: ``--houses K`` evaluation houses of ``--rooms`` rooms (``generate_house(seed,
rooms=(R, R))``) recorded once with PyBullet's scripted tour (``--width`` x ``--height``,
``--fps``, at most ``--frames`` frames; cached under ``--cache``), copied round-robin to
``--logs N`` files (each pinned under its own name), or ``--source LOG...`` instead of
recording. Then, ``--repeats`` times in alternating order, with one executor of
``--workers`` processes each:

- **replay**: every log replayed without output (:func:`sgtool.replay`, nothing kept), the
  work a check cannot avoid;
- **check**: :func:`sgtool.check_pins` over the pin folder (the same replays, plus the
  comparison; every log must be checked, unchanged or changed).

Printed: per run the wall seconds of each (the work runs in the executor's processes, so
this process's CPU seconds do not measure it), the medians, and the ratio check/replay
(median, and min..max over the paired runs). Pinning is timed once for information.
``--json PATH`` writes the same figures (:mod:`harness`'s samples per round) as JSON.

Usage: ``python benchmarks/golden_check.py [--logs 20] [--houses 2] [--rooms 10] [-w 2]``
(the full target; on a shared machine fewer or smaller logs, e.g. ``--logs 6 --houses 1
--frames 200``, and say so).
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

from harness import Sample, add_output_options, alternate, emit, timed

from sgtool.analysis.executor import LocalExecutor, Task
from sgtool.analysis.golden_check import check_pins, pin_logs
from sgtool.replayers.derived_log import ReplayOptions, replay


def recorded(seed: int, rooms: int, a: argparse.Namespace) -> Path:
    """A cached PyBullet recording of a ``rooms``-room house (the scripted tour)."""
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.recording import RecordOptions, record_house

    a.cache.mkdir(parents=True, exist_ok=True)
    log = a.cache / f"house{seed}_{rooms}rooms_{a.width}x{a.height}_fps{a.fps:g}_{a.frames}.mcap"
    if not log.exists():
        rep, took = timed(lambda: record_house(
            generate_house(seed, rooms=(rooms, rooms)), log,
            RecordOptions(fps=a.fps, frames=a.frames,
                          camera=CameraConfig(width=a.width, height=a.height)),
            house_id=f"house-{seed}"))
        print(f"recorded {log.name}: {rep.frames} frames in {took.wall_s:.0f} s",
              file=sys.stderr)
    return log


def replay_only(log: str) -> int:
    """Replay ``log`` without output; its number of refreshes (a worker task)."""
    return replay(log, None, ReplayOptions()).refreshes


def replay_all(logs: list[Path], workers: int) -> None:
    """Replay every log on ``workers`` processes, nothing kept; all must succeed."""
    out = LocalExecutor(workers).run(replay_only, [Task(str(p), str(p)) for p in logs])
    assert all(o.ok for o in out), [o.error for o in out if not o.ok]


def check_all(folder: Path, workers: int) -> None:
    """One check of the pin folder; every log must be checked (changed is allowed: the
    mapping code may change under a long run, and a change costs one diff of one
    refresh)."""
    report = check_pins(folder, executor=LocalExecutor(workers))
    assert report.exit_code != 2, [c.error for c in report.logs if c.status == "error"]
    print(f"  check: {report.counts()}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--logs", type=int, default=20, help="pinned logs")
    ap.add_argument("--houses", type=int, default=2, help="distinct recordings")
    ap.add_argument("--rooms", type=int, default=10)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--fps", type=float, default=2.0)
    ap.add_argument("--frames", type=int, default=None, help="frame budget per recording")
    ap.add_argument("--source", nargs="*", type=Path, default=None,
                    help="use these logs instead of recording")
    ap.add_argument("-w", "--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cache", type=Path,
                    default=Path(tempfile.gettempdir()) / "sgtool-bench-golden")
    add_output_options(ap)
    a = ap.parse_args(argv)
    sources = a.source or [recorded(1000 + i, a.rooms, a) for i in range(a.houses)]
    with tempfile.TemporaryDirectory(prefix="sgtool-golden-bench-") as tmp:
        logs = []
        for i in range(a.logs):
            p = Path(tmp) / "logs" / f"log{i:02d}.mcap"
            p.parent.mkdir(exist_ok=True)
            shutil.copyfile(sources[i % len(sources)], p)
            logs.append(p)
        folder = Path(tmp) / "pins"
        _, pinned = timed(lambda: pin_logs(logs, folder, executor=LocalExecutor(a.workers)))
        print(f"{a.logs} logs ({len(sources)} distinct, "
              f"{sum(p.stat().st_size for p in logs) / 1e6:.1f} MB), -w {a.workers}; pinned in "
              f"{pinned.wall_s:.1f} s "
              f"({sum(f.stat().st_size for f in folder.iterdir()) / 1e3:.0f} kB of pins)")
        this_round: dict[str, float] = {}

        def show(r: int, name: str, sample: Sample) -> None:
            this_round[name] = sample.wall_s
            if len(this_round) == 2:
                rp, ck = this_round["replay"], this_round["check"]
                print(f"run {r + 1}: replay {rp:.1f} s, check {ck:.1f} s "
                      f"(ratio {ck / rp:.3f})")
                this_round.clear()

        timings = alternate({"replay": lambda: replay_all(logs, a.workers),
                             "check": lambda: check_all(folder, a.workers)},
                            a.repeats, on_sample=show)
    replays = [s.wall_s for s in timings["replay"].samples]
    checks = [s.wall_s for s in timings["check"].samples]
    ratios = [c / r for c, r in zip(checks, replays, strict=True)]
    print(f"median: replay {statistics.median(replays):.1f} s, check "
          f"{statistics.median(checks):.1f} s; check/replay {statistics.median(ratios):.3f} "
          f"(paired runs {min(ratios):.3f}..{max(ratios):.3f}; target <= 1.2)")
    emit({"logs": a.logs, "distinct": len(sources), "workers": a.workers, "pin": pinned,
          "replay": timings["replay"], "check": timings["check"], "ratios": ratios,
          "ratio_median": statistics.median(ratios)}, a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
