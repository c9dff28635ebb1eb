"""Failed skills per episode by reason in two ``sgtool run-bench`` output folders, over the
episodes both hold (e.g. ``--navigation house`` before, ``live`` after):

    .venv/bin/python tools/closed_loop_failures.py BEFORE_DIR AFTER_DIR
"""

from __future__ import annotations

import argparse
import collections
import sys
from pathlib import Path

from sgtool.analysis.closed_loop_bench import reason_class
from sgtool.analysis.offline import executor_message
from sgtool.log.reader import LogReader
from sgtool.log.records import Action


def failed_skills(path: Path) -> collections.Counter[str]:
    """Failed skills of one closed-loop log by reason class."""
    with LogReader(path) as r:
        return collections.Counter(reason_class(executor_message(a)) for _, a in r.records(Action)
                                   if a.outcome == "failure")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    ap.add_argument("before", type=Path, help="a run-bench output folder")
    ap.add_argument("after", type=Path, help="another one, of the same episodes")
    args = ap.parse_args(argv)
    before, after = args.before, args.after
    for folder in (before, after):
        if not folder.is_dir():
            ap.error(f"{folder}: not a folder")
    common = [p.relative_to(before) for p in sorted(before.glob("logs/*/*/*/*.mcap"))
              if (after / p.relative_to(before)).exists()]
    for name, root in ((str(before), before), (str(after), after)):
        total: collections.Counter[str] = collections.Counter()
        for rel in common:
            total += failed_skills(root / rel)
        n = max(len(common), 1)
        print(f"{name}: {len(common)} episodes, failed skills/episode "
              f"{sum(total.values()) / n:.2f}: "
              + ", ".join(f"{k} {v / n:.2f}" for k, v in sorted(total.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
