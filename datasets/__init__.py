"""House specs and their generator, BEHAVIOR-1K household knowledge, search episodes.

Modules (import them directly; this package imports nothing heavy on its own):

- :mod:`sgtool.house` (core): the versioned JSON house spec (``spec``), its validation
  (``parse``), ``load_house`` / ``save_house`` (``io``), polygon helpers (``geometry``);
- :mod:`sgtool.mapping.occupancy` (core): occupancy grid of a house, geodesics, A*;
- :mod:`sgtool.datasets.knowledge`: tables read from the ``bddl`` package (BEHAVIOR-1K),
  with :mod:`~sgtool.datasets.synsets` (names, hypernyms) and
  :mod:`~sgtool.datasets.activities` (the BDDL parser);
- :mod:`sgtool.datasets.split`: the training / evaluation split of that knowledge;
- :mod:`sgtool.datasets.generator`: seeded multi-room houses furnished from the knowledge
  (its steps in the modules its docstring lists);
- :mod:`sgtool.datasets.episodes`: object-search episodes with shortest path lengths;
- :mod:`sgtool.datasets.demo`: the demo house shipped in ``data/`` and its check.
"""

from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sgtool.house.spec import HouseSpec

DEMO_HOUSE = "demo_house.json"


def demo_house() -> HouseSpec:
    """The small house shipped with the package (``data/demo_house.json``).

    It is ``generate_house`` output for a fixed seed. See :mod:`sgtool.datasets.demo`
    (``python -m sgtool.datasets.demo --check`` checks that it still is).
    """
    from sgtool.house.io import load_house_text

    text = resources.files("sgtool.datasets").joinpath("data", DEMO_HOUSE).read_text("utf-8")
    return load_house_text(text)
