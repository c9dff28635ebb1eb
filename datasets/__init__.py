"""House specs and their generator, BEHAVIOR-1K household knowledge, search episodes.

Modules (import them directly; this package imports nothing heavy on its own):

- :mod:`sgtool.house.spec`: the versioned JSON house spec, validation, canonical JSON;
- :mod:`sgtool.mapping.occupancy`: occupancy grid of a house, geodesics, A*;
- :mod:`sgtool.datasets.knowledge`: tables read from the ``bddl`` package (BEHAVIOR-1K);
- :mod:`sgtool.datasets.split`: the training / evaluation split of that knowledge;
- :mod:`sgtool.datasets.generator`: seeded multi-room houses furnished from the knowledge;
- :mod:`sgtool.datasets.episodes`: object-search episodes with shortest path lengths.
"""

from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sgtool.house.spec import HouseSpec

DEMO_HOUSE = "demo_house.json"


def demo_house() -> HouseSpec:
    """The small house shipped with the package (``data/demo_house.json``).

    It is ``generate_house`` output for a fixed seed; regenerate it with
    ``python -m sgtool.datasets.demo`` (see :mod:`sgtool.datasets.demo`).
    """
    from sgtool.house.spec import load_house

    text = resources.files("sgtool.datasets").joinpath("data", DEMO_HOUSE).read_text("utf-8")
    return load_house(text)
