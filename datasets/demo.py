"""The demo house shipped as ``data/demo_house.json`` (loaded by
:func:`sgtool.datasets.demo_house`).

It is plain generator output: ``generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")``,
a five-room house (corridor, kitchen and living room in one open plan, bathroom and
bedroom behind closed doors, closed cabinets and a closed refrigerator holding objects).
The shipped file predates the generator's room-type-following small-object placement
(2026-12-01): rooms, walls, doors, passages and furniture equal today's output, its small
objects and start yaws are the older draw. It is kept on purpose: the demo's recorded
figures (1157 frames, 21 actions) and tests built on its first frames (odometry losing
track facing plain corridor walls) stay comparable. Regenerate it deliberately with::

    .venv/bin/python -m sgtool.datasets.demo          # rewrites datasets/data/demo_house.json
    .venv/bin/python -m sgtool.datasets.demo --check  # exit 1 if the shipped file is stale
"""

from __future__ import annotations

import sys
from pathlib import Path

from sgtool.datasets.generator import generate_house
from sgtool.house.spec import HouseSpec, save_house

DEMO_SEED = 1
DEMO_ROOMS = (5, 5)
DEMO_PATH = Path(__file__).resolve().parent / "data" / "demo_house.json"


def build_demo() -> HouseSpec:
    return generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    spec = build_demo()
    if "--check" in argv:
        same = DEMO_PATH.is_file() and DEMO_PATH.read_text(encoding="utf-8") == spec.to_json()
        print("demo house is up to date" if same else "demo house is STALE: regenerate it")
        return 0 if same else 1
    save_house(spec, DEMO_PATH)
    print(f"wrote {DEMO_PATH} ({len(spec.rooms)} rooms, {len(spec.furniture)} furniture, "
          f"{len(spec.objects)} objects)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
