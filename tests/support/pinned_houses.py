"""Houses simulator tests were written against, pinned as files in ``houses/``: generator
output of an earlier tree (``generated-SEED-rooms-N[-M]``: ``generate_house(SEED,
rooms=(N, M))`` before the generator kept container fronts clear) and the demo house as
shipped until then. A test that relies on one house's layout (a closed door between two
rooms, a turn facing plain corridor walls, a target a drive passes) loads its house here,
so that a change of the generator does not change what the test checks."""

from __future__ import annotations

from pathlib import Path

from sgtool.house.io import load_house
from sgtool.house.spec import HouseSpec

HOUSES = Path(__file__).resolve().parent / "houses"


def pinned_house_path(name: str) -> Path:
    """The file of the pinned house ``name`` (its file name without ``.json``)."""
    path = HOUSES / f"{name}.json"
    if not path.is_file():
        raise FileNotFoundError(f"no pinned house {name!r} in {HOUSES}")
    return path


def pinned_house(name: str) -> HouseSpec:
    """The pinned house ``name`` (see the module doc)."""
    return load_house(pinned_house_path(name))
