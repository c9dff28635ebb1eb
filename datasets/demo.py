"""The demo house shipped as ``data/demo_house.json`` (loaded by
:func:`sgtool.datasets.demo_house`).

A five-room house (corridor, kitchen and living room in one open plan, bathroom and
bedroom behind closed doors, closed cabinets and a closed refrigerator holding objects):
what ``generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")`` gives, shipped so that
the demo runs without the knowledge the generator draws from.

::

    .venv/bin/python -m sgtool.datasets.demo --check  # exit 1 unless the file is that output
    .venv/bin/python -m sgtool.datasets.demo          # rewrites the file with it (after a
                                                      # change of the generator: the
                                                      # demo's figures change)

``--check`` checks that the file is canonical house-spec JSON (it loads, so every object
passes validation, and writes back to the same bytes) and that it equals the generator's
output part by part (:func:`spec_differences`).
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


def build_demo() -> HouseSpec:
    return generate_house(DEMO_SEED, rooms=DEMO_ROOMS, split="eval")


def spec_differences(shipped: HouseSpec, generated: HouseSpec) -> list[str]:
    """Names of the parts of the spec (keys of :meth:`HouseSpec.to_dict`) in which
    ``shipped`` differs from ``generated``, in key order; empty when they agree."""
    a, b = shipped.to_dict(), generated.to_dict()
    return [key for key in sorted(set(a) | set(b)) if a.get(key) != b.get(key)]


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
    diffs = spec_differences(shipped, build_demo())
    if diffs:
        return False, (f"demo house is STALE: {', '.join(diffs)} differ from "
                       f"generate_house({DEMO_SEED}, rooms={DEMO_ROOMS}); regenerate it")
    return True, (f"demo house is up to date: generate_house({DEMO_SEED}, rooms={DEMO_ROOMS}) "
                  f"output ({len(shipped.rooms)} rooms, {len(shipped.furniture)} furniture, "
                  f"{len(shipped.objects)} small objects)")


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
