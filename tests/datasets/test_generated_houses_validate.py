"""Every house the generator writes passes the house checks as a file (ids and names,
known keys, simple polygons, starts on free floor, walls and doors that agree), in both
presets, and loads back as the same spec."""

from __future__ import annotations

import pytest

from sgtool.datasets.generator import generate_house
from sgtool.house.io import load_house_text


@pytest.mark.parametrize("preset", ["default", "symsearch"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_generated_houses_load_back(preset: str, seed: int) -> None:
    spec = generate_house(seed, rooms=(4, 8), preset=preset)
    assert load_house_text(spec.to_json()) == spec
