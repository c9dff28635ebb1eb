"""Generator presets: how densely :func:`sgtool.datasets.generator.generate_house` furnishes
a house and where its small objects come from.

- ``default``: the generator as documented in :mod:`sgtool.datasets.generator` (about 70
  object instances and 37 small objects per house; its output is fixed by the tests).
- ``symsearch``: houses as dense as SymSearch's InteriorGS scenes (SCOUT Table I: 408
  object instances, 52 categories, 157 contained objects per scene). Per room, every
  furniture category of the room type's real inventories is included with three times its
  frequency (capped at 1) and twice its mean count (caps per room doubled); containers
  hold about 8 small objects and top faces about 6 (one category at most once per piece
  while the pool lasts), and the small objects come from the long tail of the evaluation
  knowledge (:func:`sgtool.datasets.object_candidates.candidates` with ``long_tail``):
  categories that only their own room type knows, even with a single source, are admitted,
  every candidate weighs the same, and :attr:`GeneratorPreset.novel_share` of the draws go
  to categories the training split never mentions (SymSearch's unseen queries, SCOUT
  Table IX: 61 of 142). The room-type evidence rule is kept: a category is only placed in
  a room type that has evidence for it. SymSearch's scenes are dense at the first level
  too (408 objects of which 157 contained: about 250 explorable pieces, most holding
  nothing), so each room also gets about :attr:`GeneratorPreset.extra_holders_per_m2`
  extra holders per square metre (:mod:`sgtool.datasets.first_level`: baskets, boxes,
  bins, chests, side tables, shelves from its room type's evidence), against a wall or,
  where no wall is left, on the top face of a low table or cabinet; only
  :attr:`GeneratorPreset.extra_fill_share` of them get small objects.
"""

from __future__ import annotations

from dataclasses import dataclass

from sgtool.errors import SgtoolError


@dataclass(frozen=True)
class GeneratorPreset:
    """Density and sources of a generated house (see the module docstring)."""

    name: str
    furniture_frequency_scale: float = 1.0  # inclusion probability min(1, frequency * this)
    furniture_count_scale: float = 1.0  # mean count per room multiplied by this
    furniture_cap_scale: int = 1  # per-room caps (sizes.MAX_PER_ROOM) multiplied by this
    lambda_inside: float = 2.2  # mean small objects per container (Poisson)
    lambda_ontop: float = 1.3  # mean small objects per top face (Poisson)
    long_tail: bool = False  # admit and weigh small objects as the long tail (module doc)
    novel_share: float = 0.0  # long tail: share of draws from categories unseen in training
    extra_holders_per_m2: float = 0.0  # extra first-level holders (first_level module)
    extra_fill_share: float = 1.0  # share of the extra holders that get small objects
    seen_pool_scale: float = 1.0  # mean count of a piece whose pool has no unseen category


PRESETS: dict[str, GeneratorPreset] = {
    "default": GeneratorPreset("default"),
    "symsearch": GeneratorPreset(
        "symsearch", furniture_frequency_scale=3.0, furniture_count_scale=2.0,
        furniture_cap_scale=2, lambda_inside=8.0, lambda_ontop=6.0, long_tail=True,
        novel_share=1.0, extra_holders_per_m2=2.5, extra_fill_share=0.25,
        seen_pool_scale=0.5),
}
PRESET_NAMES: tuple[str, ...] = tuple(PRESETS)


def get_preset(name: str) -> GeneratorPreset:
    """The preset called ``name``; an unknown name is a one-line :class:`SgtoolError`."""
    try:
        return PRESETS[name]
    except KeyError:
        raise SgtoolError(f"preset: expected one of {', '.join(PRESET_NAMES)}, "
                          f"got {name!r}") from None
