"""The sparsification of the Voronoi graph for all chains at once
(:mod:`sgtool.mapping.sparsify`) equals the loop over the chains it replaced
(tests/support/voronoi_reference.py), node for node, edge for edge, bit for bit, on
random houses and settings; and the chain lengths summed for all chains at once equal
a sum step by step."""

from __future__ import annotations

from itertools import accumulate

import numpy as np
import pytest
from support.voronoi_reference import reference_voronoi_graph

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.sparsify import chain_cumsum
from sgtool.mapping.voronoi import VoronoiConfig, ridge_graph, voronoi_graph

RES = 0.05


def random_house(rng: np.random.Generator) -> OccupancyGrid:
    """Rooms split by walls with doorways, furniture blocks, unknown patches, pillars
    (ridge loops around them)."""
    h, w = int(rng.integers(40, 120)), int(rng.integers(40, 160))
    g = np.full((h, w), FREE, dtype=np.int8)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = OCCUPIED
    for _ in range(int(rng.integers(0, 4))):
        if rng.random() < 0.5:
            c = int(rng.integers(8, w - 8))
            g[:, c] = OCCUPIED
            d = int(rng.integers(2, h - 14))
            g[d:d + int(rng.integers(6, 14)), c] = FREE
        else:
            r = int(rng.integers(8, h - 8))
            g[r, :] = OCCUPIED
            d = int(rng.integers(2, w - 14))
            g[r, d:d + int(rng.integers(6, 14))] = FREE
    for _ in range(int(rng.integers(0, 8))):
        r, c = int(rng.integers(0, h - 4)), int(rng.integers(0, w - 4))
        g[r:r + int(rng.integers(1, 6)), c:c + int(rng.integers(1, 6))] = \
            OCCUPIED if rng.random() < 0.7 else UNKNOWN
    return OccupancyGrid(g, (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3))), RES)


def assert_same_graph(got, want) -> None:  # noqa: ANN001
    for name in ("positions", "clearance", "cells", "edges", "lengths"):
        a, b = getattr(got, name), getattr(want, name)
        assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b), name
    assert len(got.edge_cells) == len(want.edge_cells)
    for a, b in zip(got.edge_cells, want.edge_cells, strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)


@pytest.mark.parametrize("seed", range(40))
def test_sparsified_graph_equals_the_chain_loop(seed: int) -> None:
    rng = np.random.default_rng(seed)
    occ = random_house(rng)
    cfg = VoronoiConfig(min_clearance=float(rng.choice([0.05, 0.1, 0.2])),
                        min_ridge=float(rng.choice([0.1, 0.3])),
                        node_spacing=float(rng.choice([0.05, 0.07, 0.2, 0.6, 1.5])),
                        min_spur=float(rng.choice([0.0, 0.3, 1.0])))
    rg = ridge_graph(occ, cfg)
    anchors = [None] + [tuple(rng.uniform(-3, 8, size=2)) for _ in range(2)]
    for anchor in anchors:
        want = reference_voronoi_graph(occ, cfg, anchor=anchor, ridge=rg)
        got = voronoi_graph(occ, cfg, anchor=anchor, ridge=rg)
        assert_same_graph(got, want)


def test_the_random_houses_cover_loops_spurs_and_parallel_pieces() -> None:
    """The houses above give what the rules treat apart: loops, dropped spurs, chains
    between the same two pixels, and more than one cut per piece."""
    seen = {"loop": 0, "spur": 0, "edges": 0}
    for seed in range(40):
        rng = np.random.default_rng(seed)
        occ = random_house(rng)
        for spur in (0.0, 1.0):
            vg = voronoi_graph(occ, VoronoiConfig(min_spur=spur, node_spacing=0.2))
            seen["edges"] += len(vg.edges)
            seen["spur"] += spur > 0 and len(vg.edges) < len(
                voronoi_graph(occ, VoronoiConfig(min_spur=0.0, node_spacing=0.2)).edges)
            seen["loop"] += len(vg.edges) >= len(vg.positions) > 0  # a cycle
    assert all(v > 3 for v in seen.values()), seen


@pytest.mark.parametrize("seed", range(6))
def test_chain_lengths_are_summed_step_by_step(seed: int) -> None:
    rng = np.random.default_rng(seed)
    sizes = rng.integers(0, 300, size=int(rng.integers(1, 60)))
    steps = rng.choice([1.0, np.sqrt(2.0), 0.1, 1e-3], size=int(sizes.sum()))
    got = chain_cumsum(steps, sizes)
    want: list[float] = []
    at = 0
    for m in sizes.tolist():
        want += list(accumulate(steps[at:at + m].tolist(), initial=0.0))
        at += m
    assert got.tolist() == want


@pytest.mark.parametrize("height", [21, 24, 31])
@pytest.mark.parametrize("pillar", [1, 3, 5])
def test_a_pillar_in_a_corridor_splits_the_second_of_two_parallel_chains(height: int,
                                                                           pillar: int) -> None:
    """The centre line forks around a pillar: two chains join the same two pixels, and
    the second one gets at least two pieces (with one each they would be one edge)."""
    g = np.full((height, 120), FREE, dtype=np.int8)
    g[0, :] = g[-1, :] = OCCUPIED
    r0 = height // 2 - pillar // 2
    g[r0:r0 + pillar, 60:60 + pillar] = OCCUPIED
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    for spacing in (0.3, 1.5, 3.0):
        cfg = VoronoiConfig(node_spacing=spacing, min_clearance=0.05, min_ridge=0.1)
        got = voronoi_graph(occ, cfg)
        assert_same_graph(got, reference_voronoi_graph(occ, cfg))
        assert len(got.edges) >= len(got.positions)  # the fork is a cycle
