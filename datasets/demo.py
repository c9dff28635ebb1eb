"""The demo house shipped as ``data/demo_house.json`` (loaded by
:func:`sgtool.datasets.demo_house`).

A five-room house (corridor, kitchen and living room in one open plan, bathroom and
bedroom behind closed doors, closed cabinets and a closed refrigerator holding objects).
It is *not* plain generator output. Its layout - version, seed, split, rooms, walls, doors,
passages, furniture and the start positions (:data:`GENERATED_PARTS`) - is what
``generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")`` gives today; its small
objects and start yaws are an older draw of the generator, from before small objects
followed their room type (2026-12-01), kept on purpose: the demo's recorded figures (1157
frames, 21 actions) and tests built on its first frames (odometry losing track facing
plain corridor walls) stay comparable.

::

    .venv/bin/python -m sgtool.datasets.demo --check  # exit 1 unless what is said above holds
    .venv/bin/python -m sgtool.datasets.demo          # rewrites the file with today's full
                                                      # generator output (new small objects
                                                      # and yaws: the demo's figures change)

``--check`` checks that the file is canonical house-spec JSON (it loads, so every object
passes validation, and writes back to the same bytes) and that its layout equals the
generator's (:func:`layout_differences`).
"""

from __future__ import annotations

import sys
from pathlib import Path

from sgtool.datasets.generator import generate_house
from sgtool.errors import SpecError
from sgtool.house.io import load_house_text, save_house
from sgtool.house.spec import HouseSpec

DEMO_SEED = 1
DEMO_ROOMS = (5, 5)
DEMO_PATH = Path(__file__).resolve().parent / "data" / "demo_house.json"
# parts of the spec (keys of HouseSpec.to_dict) the shipped file shares with the generator;
# of "starts" only the positions and rooms (the yaws are drawn after the small objects)
GENERATED_PARTS = ("version", "seed", "split", "rooms", "walls", "doors", "passages",
                   "furniture")


def build_demo() -> HouseSpec:
    return generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")


def layout_differences(shipped: HouseSpec, generated: HouseSpec) -> list[str]:
    """Names of the parts of :data:`GENERATED_PARTS` (and "start positions") in which
    ``shipped`` differs from ``generated``; empty when the layouts agree."""
    a, b = shipped.to_dict(), generated.to_dict()
    out = [key for key in GENERATED_PARTS if a[key] != b[key]]
    if [(s.x, s.y, s.room) for s in shipped.starts] != \
            [(s.x, s.y, s.room) for s in generated.starts]:
        out.append("start positions")
    return out


def check_demo(path: Path = DEMO_PATH) -> tuple[bool, str]:
    """(ok, message) of the ``--check`` (see the module docstring)."""
    if not path.is_file():
        return False, f"demo house is missing: {path}"
    text = path.read_text(encoding="utf-8")
    try:
        shipped = load_house_text(text)
    except SpecError as e:
        return False, f"demo house is not a valid house spec: {e}"
    if shipped.to_json() != text:
        return False, "demo house is not canonical JSON: rewrite it with save_house"
    diffs = layout_differences(shipped, build_demo())
    if diffs:
        return False, (f"demo house is STALE: {', '.join(diffs)} differ from "
                       f"generate_house({DEMO_SEED}, rooms={DEMO_ROOMS}); regenerate it")
    return True, (f"demo house is up to date: its layout, furniture and start positions are "
                  f"generate_house({DEMO_SEED}, rooms={DEMO_ROOMS}) output; its "
                  f"{len(shipped.objects)} small objects and start yaws are the older draw "
                  f"kept on purpose")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--check" in argv:
        ok, message = check_demo()
        print(message)
        return 0 if ok else 1
    spec = build_demo()
    save_house(spec, DEMO_PATH)
    print(f"wrote {DEMO_PATH} ({len(spec.rooms)} rooms, {len(spec.furniture)} furniture, "
          f"{len(spec.objects)} objects)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
