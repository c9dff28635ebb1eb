"""Incremental assignment (issue 20): with an AssignCache carried from call to call, the
objects land on exactly the nodes (and costs) of a from-scratch run, on randomised small
houses whose walls, graph and objects change between calls."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from support.assign_reference import reference_assignment

from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.scenegraph.assign import AssignCache, AssignConfig, assign_objects

RES = 0.05


def _house(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A 6 x 4 m grid split by 1-3 walls with a doorway each; node positions on free
    cells."""
    g = np.full((80, 120), FREE, dtype=np.int8)
    for _ in range(int(rng.integers(1, 4))):
        if rng.random() < 0.5:
            c = int(rng.integers(15, 105))
            g[:, c] = OCCUPIED
            d = int(rng.integers(5, 65))
            g[d:d + 10, c] = FREE
        else:
            r = int(rng.integers(15, 65))
            g[r, :] = OCCUPIED
            d = int(rng.integers(5, 100))
            g[r, d:d + 10] = FREE
    free = np.argwhere(g == FREE)
    pick = free[rng.choice(len(free), size=40, replace=False)]
    pos = np.stack([(pick[:, 1] + 0.5) * RES, (pick[:, 0] + 0.5) * RES], axis=1)
    return g, pos


def _graph(pos: np.ndarray, rng: np.random.Generator) -> csr_matrix:
    """Each node joined to its 3 nearest neighbours (weights: distances), a few dropped."""
    n = len(pos)
    d = np.hypot(pos[:, None, 0] - pos[None, :, 0], pos[:, None, 1] - pos[None, :, 1])
    rows, cols = [], []
    for i in range(n):
        for j in np.argsort(d[i])[1:4]:
            if rng.random() > 0.1:
                rows += [i, int(j)]
                cols += [int(j), i]
    r, c = np.asarray(rows), np.asarray(cols)
    return csr_matrix((d[r, c], (r, c)), shape=(n, n))


@pytest.mark.parametrize("seed", range(8))
def test_cached_assignment_equals_from_scratch(seed):
    rng = np.random.default_rng(seed)
    g, pos = _house(rng)
    graph = _graph(pos, rng)
    room = rng.integers(-1, 4, size=len(pos))
    objs = rng.uniform((0.2, 0.2), (5.8, 3.8), size=(12, 2))
    vps = pos[rng.integers(0, len(pos), size=12)] + rng.normal(0, 0.1, size=(12, 2))
    vps[rng.random(12) < 0.2] = np.nan  # objects seen from nowhere known
    cache = AssignCache()
    for step in range(8):
        occ = OccupancyGrid(g.copy(), (0.0, 0.0), RES)
        blocked = occ.grid == OCCUPIED
        got = assign_objects(pos, room, graph, objs, vps, occ, blocked, cache=cache)
        want = assign_objects(pos, room, graph, objs, vps, occ, blocked)
        assert np.array_equal(got.node, want.node), f"step {step}"
        assert np.array_equal(got.cost, want.cost), f"step {step}"
        assert (want.node >= 0).all()
        # the house changes: a wall piece appears or goes, sometimes the graph or the
        # objects change too (new nodes, a new object seen from a new place)
        r0, c0 = int(rng.integers(0, 75)), int(rng.integers(0, 115))
        g[r0:r0 + 5, c0:c0 + 5] = OCCUPIED if rng.random() < 0.6 else FREE
        if step % 3 == 1:
            pos = pos.copy()
            pos[int(rng.integers(len(pos)))] += rng.normal(0, 0.05, 2)
            graph = _graph(pos, rng)
        if step % 4 == 2:
            objs = np.vstack([objs, rng.uniform((0.2, 0.2), (5.8, 3.8), size=(1, 2))])
            vps = np.vstack([vps, pos[int(rng.integers(len(pos)))][None]])
    assert cache.hits > 0 and cache.misses > 0  # both paths were taken


def test_cache_keeps_only_the_viewpoints_in_use():
    rng = np.random.default_rng(1)
    g, pos = _house(rng)
    graph = _graph(pos, rng)
    room = np.zeros(len(pos), dtype=np.int64)
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    cache = AssignCache()
    objs = np.array([[1.0, 1.0], [3.0, 2.0]])
    assign_objects(pos, room, graph, objs, pos[[0, 1]], occ, g == OCCUPIED, cache=cache)
    assert len(cache.sight) == 2
    assign_objects(pos, room, graph, objs[:1], pos[[0]], occ, g == OCCUPIED, cache=cache)
    assert list(cache.sight) == [(float(pos[0, 0]), float(pos[0, 1]))]
    assert cache.hits == 1  # the same viewpoint, nodes and walls: reused


@pytest.mark.parametrize("seed", range(8))
def test_searches_stopped_at_a_limit_give_the_unlimited_assignment(seed):
    """Graph distances are searched up to ``search_limit`` first; an object whose best
    cost could lie beyond it gets its viewpoint's full search: the same nodes and costs
    as unlimited searches, bit for bit, whatever the limit."""
    rng = np.random.default_rng(100 + seed)
    g, pos = _house(rng)
    graph = _graph(pos, rng)
    room = rng.integers(-1, 4, size=len(pos))
    objs = rng.uniform((0.2, 0.2), (5.8, 3.8), size=(16, 2))
    vps = pos[rng.integers(0, len(pos), size=16)] + rng.normal(0, 0.1, size=(16, 2))
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    blocked = occ.grid == OCCUPIED
    want = assign_objects(pos, room, graph, objs, vps, occ, blocked,
                          AssignConfig(search_limit=np.inf))
    full_searches = 0
    for limit in (0.3, 1.0, 2.5, 6.0, 30.0):
        cache = AssignCache()
        got = assign_objects(pos, room, graph, objs, vps, occ, blocked,
                             AssignConfig(search_limit=limit), cache)
        assert np.array_equal(got.node, want.node) and np.array_equal(got.cost, want.cost)
        if np.inf in cache.rows:  # sources searched without a limit
            full_searches += int((cache.rows[np.inf][1] >= 0).sum())
    assert full_searches > 0 and (want.node >= 0).all()


def _grown(g: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, tuple[float, float]]:
    """The grid grown by a few cells on some sides (new cells free), with its origin."""
    top, left = int(rng.integers(0, 3)), int(rng.integers(0, 3))
    bottom, right = int(rng.integers(0, 3)), int(rng.integers(0, 3))
    out = np.pad(g, ((top, bottom), (left, right)), constant_values=FREE)
    return out, (-left * RES, -top * RES)


@pytest.mark.parametrize("seed", range(12))
def test_assignment_equals_the_plain_loop(seed):
    """The vectorised assignment with a cache carried along equals the plain per-object
    loop with unlimited searches (tests/support/assign_reference.py), bit for bit, while
    walls change, the grid grows (origin moves or not), and objects without candidates
    within the radius or without a viewpoint come and go."""
    rng = np.random.default_rng(500 + seed)
    g, pos = _house(rng)
    graph = _graph(pos, rng)
    room = rng.integers(-1, 3, size=len(pos))
    objs = rng.uniform((-1.0, -1.0), (7.0, 5.0), size=(20, 2))  # some far from any node
    vps = pos[rng.integers(0, len(pos), size=20)] + rng.normal(0, 0.1, size=(20, 2))
    vps[rng.random(20) < 0.2] = np.nan
    cache = AssignCache()
    origin = (0.0, 0.0)
    for step in range(10):
        cfg = AssignConfig(search_limit=float(rng.choice([0.5, 2.0, 10.0])))
        occ = OccupancyGrid(g.copy(), origin, RES)
        blocked = occ.grid == OCCUPIED
        got = assign_objects(pos, room, graph, objs, vps, occ, blocked, cfg, cache)
        node, cost = reference_assignment(pos, room, graph, objs, vps, occ, blocked, cfg)
        assert np.array_equal(got.node, node), f"step {step}"
        assert np.array_equal(got.cost, cost), f"step {step}"
        r0, c0 = int(rng.integers(0, g.shape[0] - 5)), int(rng.integers(0, g.shape[1] - 5))
        g[r0:r0 + 5, c0:c0 + 5] = OCCUPIED if rng.random() < 0.6 else FREE
        if step % 3 == 2:
            g, (dx, dy) = _grown(g, rng)
            origin = (origin[0] + dx, origin[1] + dy)
        if step % 4 == 1:
            room = rng.integers(-1, 3, size=len(pos))
    assert cache.hits > 0 and cache.misses > 0
