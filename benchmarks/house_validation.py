"""House-spec validation time against the number of small objects (linear, as documented
in sgtool.house.parse), and the time to refuse hostile input.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/house_validation.py [--max 100000]

The house is the demo house with its small objects replaced by ``n`` copies of one of
them (same parent, distinct ids); the limits are lifted for the measurement
(``SpecLimits(objects=n)``), then the default limits are shown refusing the same
document at once. Each figure is the best of three runs.
"""

from __future__ import annotations

import argparse
import copy
import json

from harness import best_of

from sgtool.datasets import demo_house
from sgtool.errors import SpecError
from sgtool.house.parse import parse_house
from sgtool.house.spec import LIMITS, SpecLimits


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max", type=int, default=100_000)
    args = ap.parse_args()
    base = json.loads(demo_house().to_json())
    one = base["objects"][0]
    print(f"{'objects':>9} {'seconds':>8} {'us/object':>10}")
    doc = base
    for n in sorted({min(k, args.max) for k in (1_000, 10_000, 100_000, args.max)}):
        doc = copy.deepcopy(base)
        doc["objects"] = [dict(one, id=f"obj_{k}") for k in range(n)]
        t = best_of(lambda d=doc, k=n: parse_house(d, SpecLimits(objects=k)), 3).wall_s
        print(f"{n:>9} {t:>8.3f} {t / n * 1e6:>10.1f}")

    doc = copy.deepcopy(base)  # one object past the default limit, whatever --max
    doc["objects"] = [dict(one, id=f"obj_{k}") for k in range(LIMITS.objects + 1)]

    def refuse() -> None:
        try:
            parse_house(doc)
        except SpecError:
            return
        raise AssertionError("not refused")
    print(f"refusing {len(doc['objects'])} objects with the default limit "
          f"({LIMITS.objects}): {best_of(refuse, 3).wall_s * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
