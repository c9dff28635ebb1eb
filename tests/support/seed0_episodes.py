"""The closed-loop tests' episodes: drawn with seed 0.

These tests were written around situations of particular episodes (a closed door on the
way, a container opened from the side) of houses 1 and 6 as the listing drew them with
seed 0, before the listing took the house's own seed by default. Drawing them with seed 0
keeps each test on its situation."""

from __future__ import annotations

from sgtool.datasets.episodes import Episode, list_episodes
from sgtool.house.spec import HouseSpec


def seed0_episode(house: HouseSpec, index: int) -> tuple[int, Episode]:
    """(index, episode) of ``house``'s search episodes drawn with seed 0."""
    return index, list_episodes(house, seed=0)[index]
