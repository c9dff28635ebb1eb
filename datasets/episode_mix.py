"""SymSearch's mix of search episodes: small objects and furniture as targets.

SymSearch (SCOUT sec. VI) also asks for non-interactive targets, furniture-level categories
("find a dishwasher"), in about a third of its episodes. :func:`symsearch_episodes` takes
the small-object episodes from :func:`sgtool.datasets.episodes.list_episodes` and adds
furniture-target episodes: the query is a furniture category of the house (one that no
small object shares), the targets are all its pieces (seeing any one succeeds), the start
is drawn as a small object's (:func:`sgtool.datasets.episodes.draw_start`: outside every
target room when it can be, inside one when no start reaches a piece), the target is never
hidden, and the shortest path runs from the start to the nearest free cell of a target's
room within ``reach`` of the piece's footprint (the rule of :mod:`sgtool.datasets.episodes`,
with the piece itself as the parent). A category none of whose pieces has free floor
within ``reach`` is not drawn.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict

import numpy as np

from sgtool.datasets.episodes import (
    REACH,
    Episode,
    EpisodeGeometry,
    draw_start,
    list_episodes,
)
from sgtool.house.spec import Furniture, HouseSpec, spec_id_key
from sgtool.semantics.text import category_text

FURNITURE_SHARE = 1 / 3  # SymSearch: about a third of the episodes ask for furniture


def furniture_episodes(spec: HouseSpec, n: int, seed: int = 0, reach: float = REACH,
                       geometry: EpisodeGeometry | None = None) -> list[Episode]:
    """``n`` furniture-target episodes of ``spec`` drawn with ``seed`` (categories without
    replacement while they last, then again with other starts); ids ``fep_<i>``.
    ``geometry``: the house's :class:`EpisodeGeometry` with this ``reach``, to share."""
    if n <= 0 or not spec.starts:
        return []
    # spellings of one category ("Refrigerator", "refrigerator") are one query, as the
    # environments count any piece whose name reads the same as found
    small = {category_text(o.category) for o in spec.objects}
    by_cat: dict[str, list[Furniture]] = defaultdict(list)
    for f in spec.furniture:
        if category_text(f.category) not in small:
            by_cat[category_text(f.category)].append(f)
    geo = geometry or EpisodeGeometry(spec, reach=reach)
    near = {f.id: geo.near(f) for fs in by_cat.values() for f in fs}
    cats = sorted(c for c, fs in by_cat.items() if any(near[f.id] is not None for f in fs))
    if not cats:
        return []
    rng = np.random.default_rng([seed, 1])
    out: list[Episode] = []
    while len(out) < n:
        take = min(n - len(out), len(cats))
        for ci in sorted(rng.choice(len(cats), size=take, replace=False).tolist()):
            pieces = sorted(by_cat[cats[ci]], key=lambda f: spec_id_key(f.id))
            rooms = tuple(sorted({f.room for f in pieces}, key=spec_id_key))
            start, best = draw_start(spec, geo, rooms, [f.id for f in pieces], rng, seed)
            first = pieces[0]
            room = spec.room(first.room).category.replace("_", " ")
            more = f" (+{len(pieces) - 1} more)" if len(pieces) > 1 else ""
            article = "an" if first.category[:1].lower() in "aeiou" else "a"
            out.append(Episode(
                id=f"fep_{len(out)}", query=cats[ci], synset=first.synset,
                targets=tuple(f.id for f in pieces), target_rooms=rooms, start=start,
                hidden=False, shortest_path=best,
                description=f"{article} {first.category} in the {room}{more}"))
    return out


def symsearch_episodes(spec: HouseSpec, n: int, seed: int = 0,
                       furniture_share: float = FURNITURE_SHARE,
                       reach: float = REACH) -> list[Episode]:
    """``n`` episodes of ``spec``: ``round(n * furniture_share)`` furniture targets
    (:func:`furniture_episodes`), the rest small objects (:func:`list_episodes`), in an
    order drawn with ``seed`` (so any prefix holds both kinds), renumbered ``ep_<i>``."""
    if not 0.0 <= furniture_share <= 1.0:
        raise ValueError(f"furniture_share must be in [0, 1], got {furniture_share}")
    n_furn = round(n * furniture_share) if spec.objects else n
    geo = EpisodeGeometry(spec, reach=reach)  # one occupancy for both kinds
    eps = list_episodes(spec, n - n_furn, seed=seed, reach=reach, geometry=geo) \
        if n > n_furn else []
    eps += furniture_episodes(spec, n_furn, seed=seed, reach=reach, geometry=geo)
    order = np.random.default_rng([seed, 2]).permutation(len(eps))
    return [dataclasses.replace(eps[j], id=f"ep_{i}") for i, j in enumerate(order.tolist())]
