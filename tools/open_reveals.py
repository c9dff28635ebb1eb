"""How often opening the container that holds the target shows it, per planner, in
``sgtool run-bench`` output folders.

The symbolic environment reveals a container's contents when it is opened; in the closed
loop the robot's camera has to see them. For every ``open`` of a piece that holds the
target (the log's instance table: an object of the query's category whose parent is that
piece) this counts whether the episode ended found on that action (the closed loop ends
an episode at the first refresh whose graph shows the target, so a found episode's last
action is the one that showed it). The rest were found later, from elsewhere, or not at
all.

    .venv/bin/python tools/open_reveals.py RUN_DIR [RUN_DIR ...]
"""

from __future__ import annotations

import collections
import sys
from pathlib import Path

from sgtool.log.reader import LogReader
from sgtool.log.records import Instances
from sgtool.results import EpisodeResult, read_jsonl


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


def reveals(result: EpisodeResult) -> tuple[int, int]:
    """(opens of a piece holding the target, those that ended the episode found) of one
    episode."""
    if not Path(result.source).is_file():
        return 0, 0
    holders = target_holders(Path(result.source), result.query)
    opens = shown = 0
    for k, step in enumerate(result.trace):
        node = step.target
        if step.skill != "open" or not node or not node.startswith("obj:"):
            continue
        if int(node.split(":", 1)[1]) not in holders:
            continue
        opens += 1
        shown += int(result.success and k == len(result.trace) - 1)
    return opens, shown


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    for folder in map(Path, argv):
        path = folder / "episodes.jsonl"
        if not path.is_file():
            print(f"{folder}: no episodes.jsonl (not a run-bench output folder)",
                  file=sys.stderr)
            return 2
        opens: collections.Counter[str] = collections.Counter()
        shown: collections.Counter[str] = collections.Counter()
        for r in read_jsonl(path):
            o, s = reveals(r)
            opens[r.planner] += o
            shown[r.planner] += s
        for planner in sorted(opens):
            print(f"{folder}: {planner}: {shown[planner]}/{opens[planner]} opens of the "
                  "target's container showed it")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
