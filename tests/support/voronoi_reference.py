"""The sparsification of the Voronoi graph as a loop over the chains, as it was written
before :mod:`sgtool.mapping.sparsify` did it for all chains at once: what the tests
compare that against, bit for bit."""

from __future__ import annotations

from bisect import bisect_left
from itertools import chain

import numpy as np
from scipy.sparse import csr_matrix

from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.ridge_chains import trace_chain_arrays
from sgtool.mapping.voronoi import (
    RidgeGraph,
    VoronoiConfig,
    VoronoiGraph,
    chosen_component,
    ridge_graph,
    submatrix,
)


def reference_voronoi_graph(occ: OccupancyGrid, config: VoronoiConfig | None = None,
                  anchor: tuple[float, float] | None = None,
                  ridge: RidgeGraph | None = None) -> VoronoiGraph:
    """:func:`sgtool.mapping.voronoi.voronoi_graph` with the per-chain loop it had."""
    cfg = config or VoronoiConfig()
    rg = ridge if ridge is not None else ridge_graph(occ, cfg)
    res = occ.resolution
    dist_m = rg.clearance
    h, w = rg.ridge.shape
    empty = VoronoiGraph(None, np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2), np.int64),
                         np.zeros((0, 2), np.int64), np.zeros(0), (), rg.ridge, (h, w))
    if len(rg.flat) == 0:
        return empty
    flat, adj, comp = rg.flat, rg.adj, rg.component
    target = chosen_component(occ, rg, anchor)
    keep = np.flatnonzero(comp == target)
    flat = flat[keep]
    adj = submatrix(adj, keep)
    chains = chain_lists(adj)
    n = adj.shape[0]
    deg = np.diff(adj.indptr)
    # drop short spurs (leaf chains ending at a junction)
    spur = cfg.min_spur / res
    degree = deg.tolist()
    kept: list[tuple[list[int], list[float]]] = []
    for path, cum in chains:
        length = cum[-1]
        da, db = degree[path[0]], degree[path[-1]]
        leaf = da == 1 or db == 1
        junction = da >= 3 or db >= 3
        if leaf and junction and length < spur:
            continue
        kept.append((path, cum))
    step = cfg.node_spacing / res
    node_px: set[int] = set()
    segs: list[tuple[list[int], float]] = []
    pairs: set[tuple[int, int]] = set()
    for path, cum in kept:
        length = cum[-1]
        k = max(1, int(round(length / step)))
        a, b = path[0], path[-1]
        if a == b:
            k = max(k, 3)
        elif (min(a, b), max(a, b)) in pairs and k < 2:
            k = 2
        pairs.add((min(a, b), max(a, b)))
        last = len(path) - 1
        cuts = [0]
        for i in range(1, k):  # the first cumulative length reaching each even spacing
            j = min(max(bisect_left(cum, length * i / k), cuts[-1] + 1), last)
            if j < last:
                cuts.append(j)
        cuts.append(last)
        for s0, s1 in zip(cuts[:-1], cuts[1:], strict=True):
            segs.append((path[s0:s1 + 1], cum[s1] - cum[s0]))
            node_px.add(path[s0])
            node_px.add(path[s1])
    if not segs:
        node_px = {0} if n else set()  # a lone ridge cell
    order = sorted(node_px)  # pixels are numbered in raster order of their cells
    node_id = {p: i for i, p in enumerate(order)}
    cells_flat = flat[np.asarray(order, dtype=np.int64)]
    rows, cols = np.divmod(cells_flat, w)
    xs, ys = occ.center_of(rows, cols)
    positions = np.stack([xs, ys], axis=1)
    clearance = dist_m[rows, cols]
    best: dict[tuple[int, int], tuple[float, list[int]]] = {}
    for seg, length in segs:
        u, v = node_id[seg[0]], node_id[seg[-1]]
        if u == v:
            continue
        key = (min(u, v), max(u, v))
        lm = length * res
        if key not in best or lm < best[key][0]:
            best[key] = (lm, seg if u < v else seg[::-1])
    edge_map: dict[tuple[int, int], tuple[float, np.ndarray]] = {}
    if best:  # the cells of the chosen segments, gathered at once
        pix = [seg for _, seg in best.values()]
        cells_all = flat[np.fromiter(chain.from_iterable(pix), dtype=np.int64)]
        bounds = np.cumsum([0] + [len(p) for p in pix]).tolist()
        for i, (key, (lm, _)) in enumerate(best.items()):
            edge_map[key] = (lm, cells_all[bounds[i]:bounds[i + 1]])
    keys = sorted(edge_map)
    edges = np.asarray(keys, dtype=np.int64).reshape(-1, 2)
    lengths = np.asarray([edge_map[k][0] for k in keys], dtype=np.float64)
    edge_cells = tuple(edge_map[k][1] for k in keys)
    return VoronoiGraph(None, positions, clearance, np.stack([rows, cols], axis=1), edges,
                        lengths, edge_cells, rg.ridge, (h, w))


def chain_lists(adj: csr_matrix) -> list[tuple[list[int], list[float]]]:
    """:func:`~sgtool.mapping.ridge_chains.trace_chain_arrays` as a list of (pixel list,
    cumulative lengths in cells), one per chain, in its order."""
    ch = trace_chain_arrays(adj)
    pix, cum, start = ch.pix.tolist(), ch.cum.tolist(), ch.start.tolist()
    return [(pix[a:b], cum[a:b]) for a, b in zip(start[:-1], start[1:], strict=True)]
