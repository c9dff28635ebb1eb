"""How often opening the container that holds the target (or walking up to the piece that
holds it) shows it, per planner, in ``sgtool run-bench`` output folders.

The symbolic environment reveals a container's contents when it is opened; in the closed
loop the robot's camera has to see them. For every ``open`` of a piece that holds the
target (the log's instance table: an object of the query's category whose parent is that
piece) this counts whether the episode ended found on that action (the closed loop ends
an episode at the first refresh whose graph shows the target, so a found episode's last
action is the one that showed it). The rest were found later, from elsewhere, or not at
all. Walking up to a piece that holds the target (``navigate``, which examines it) is
counted the same way.

    .venv/bin/python tools/open_reveals.py RUN_DIR [RUN_DIR ...]
"""

from __future__ import annotations

import collections
import sys
from pathlib import Path

from sgtool.log.reader import LogReader
from sgtool.log.records import Instances
from sgtool.results import EpisodeResult, read_jsonl, source_log


def target_holders(log: Path, query: str) -> set[int]:
    """Instance ids of the pieces that hold an object named ``query`` in ``log``'s last
    instance table."""
    with LogReader(log) as r:
        last = next(r.records(Instances, reverse=True), None)
    if last is None:
        return set()
    table = last[1]
    return {int(i.parent) for i in table.instances
            if i.kind == "object" and i.category == query and isinstance(i.parent, int)}


def reveals(result: EpisodeResult, table: Path) -> dict[str, tuple[int, int]]:
    """Per skill (``open``, ``navigate``: walking up to a piece examines it), the actions
    on a piece holding the target in one episode and those that ended it found."""
    out = {"open": (0, 0), "navigate": (0, 0)}
    log = source_log(result, table)
    if log is None:
        return out
    holders = target_holders(log, result.query)
    for k, step in enumerate(result.trace):
        node = step.target
        if step.skill not in out or not node or not node.startswith("obj:"):
            continue
        if int(node.split(":", 1)[1]) not in holders:
            continue
        n, s = out[step.skill]
        out[step.skill] = (n + 1, s + int(result.success and k == len(result.trace) - 1))
    return out


WHAT = {"open": "opens of the target's container showed it",
        "navigate": "walks up to the target's container or supporter showed it"}


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stderr if not argv else sys.stdout)
        return 2 if not argv else 0
    for folder in map(Path, argv):
        path = folder / "episodes.jsonl"
        if not path.is_file():
            print(f"{folder}: no episodes.jsonl (not a run-bench output folder)",
                  file=sys.stderr)
            return 2
        acts: collections.Counter[tuple[str, str]] = collections.Counter()
        shown: collections.Counter[tuple[str, str]] = collections.Counter()
        for r in read_jsonl(path):
            for skill, (n, s) in reveals(r, path).items():
                acts[r.planner, skill] += n
                shown[r.planner, skill] += s
        for planner, skill in sorted(acts):
            print(f"{folder}: {planner}: {shown[planner, skill]}/{acts[planner, skill]} "
                  f"{WHAT[skill]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
