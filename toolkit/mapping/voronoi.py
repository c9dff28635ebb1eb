"""Generalized Voronoi graph of explored free space, clearance-filtered and sparsified.

MoMa-LLM (paper sec. III-B) computes the generalized Voronoi diagram (GVD) of the inflated
BEV map: the points with equal clearance to the two closest obstacles, filtered to free,
explored space away from obstacles; the largest connected component is the navigation graph
(ours keeps every component the robot's trajectory passed through:
:func:`visited_components`), sparsified to fewer nodes. Their implementation runs
``scipy.spatial.Voronoi`` over every obstacle pixel, then an all-pairs Dijkstra to sparsify
(O(N^2)). We compute the same diagram on the grid instead:

1. **Ridge cells.** The feature transform of the distance field
   (:func:`sgtool.mapping.esdf.distance_field`) gives every free cell its nearest obstacle
   cell. Two neighbouring cells whose nearest obstacles are far apart (more than
   ``min_ridge``) straddle the GVD: the one of the two closer to being equidistant from
   both obstacles is a ridge cell. (A threshold relative to the clearance, as in
   ``ridge_ratio``, would suppress hairs from bumpy walls but also the bisector of a
   doorway's two jambs seen from more than a door width away, disconnecting rooms; it is
   off by default.) Between two
   walls that is the centre line; from a room corner, its bisector; along one straight wall
   nothing (neighbouring cells share nearly the same nearest wall cell), so the "hairs" a
   point-site Voronoi grows between adjacent wall pixels never appear. Obstacles are
   occupied *and unknown* cells (the explored/unexplored border bounds the diagram, as in
   MoMa-LLM), and ridge cells must have at least ``min_clearance`` to the nearest obstacle
   (the inflation; MoMa-LLM clips the distance field at 3 px of 7.5 cm).
2. **Thinning.** Zhang-Suen thinning (1984) makes the ridge one cell wide; the pixel graph
   joins 8-neighbours, skipping a diagonal step when a 4-neighbour path exists.
3. **Component.** The component holding the ridge cell nearest to ``anchor`` (the robot),
   else the largest (ties: the one with the lowest cell); with a trajectory, also every
   component it passed through (:func:`visited_components`).
4. **Sparsification** (MoMa-LLM: keep nodes of degree != 2, join them along degree-2
   chains, re-insert a node every 0.6 m): chains are traced once (linear time), spurs
   shorter than ``min_spur`` ending in a junction are dropped, and each chain gets
   ``round(length / node_spacing) - 1`` evenly spaced intermediate nodes. Edges weigh their
   length along the ridge and keep the cells they follow (for the door cut of
   :mod:`sgtool.scenegraph.room_segmentation`). All chains are cut at once, on arrays
   (:mod:`sgtool.mapping.sparsify`, which states the rules exactly).

Nodes are numbered in raster order of their cells, edges are sorted: the same grid always
gives the same graph.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from sgtool.mapping.esdf import obstacles
from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.ridge_chains import trace_chain_arrays
from sgtool.mapping.ridge_window import (
    RidgeFields,
    ridge_fields,
    update_fields,
)
from sgtool.mapping.sparsify import sparsify

if TYPE_CHECKING:  # networkx is imported only when the view is built (start-up time)
    import networkx as nx

_SQRT2 = math.sqrt(2.0)


@dataclass(frozen=True)
class VoronoiConfig:
    min_clearance: float = 0.2  # m from the nearest obstacle (or unknown) cell
    min_ridge: float = 0.3  # m: nearest obstacles of neighbouring cells this far apart
    ridge_ratio: float = 0.0  # ... and at least this x their clearance (0: off)
    node_spacing: float = 0.6  # m between sparsified nodes along a chain (MoMa-LLM)
    min_spur: float = 0.3  # m: dead ends shorter than this are dropped


@dataclass(frozen=True, eq=False)
class VoronoiGraph:
    """The sparsified graph. ``graph`` is a networkx Graph on nodes ``0..n-1`` with node
    attributes ``pos`` (x, y), ``clearance`` (m), ``cell`` (row, col) and edge attributes
    ``weight`` (m along the ridge); the same data is in the arrays, which is what the
    pipeline uses: the networkx view is built from them on first use (``built`` None)."""

    built: nx.Graph | None
    positions: np.ndarray  # (n, 2) world x, y
    clearance: np.ndarray  # (n,) m
    cells: np.ndarray  # (n, 2) row, col
    edges: np.ndarray  # (m, 2) node ids, u < v, sorted
    lengths: np.ndarray  # (m,) m
    edge_cells: tuple[np.ndarray, ...]  # per edge: flat cell indices along the ridge
    ridge: np.ndarray = field(repr=False)  # bool grid: thinned ridge (all components)
    shape: tuple[int, int] = (0, 0)

    def __post_init__(self) -> None:
        # read-only: a refresh hands these out and the next refresh may reuse them, so a
        # caller's edit would otherwise reach later graphs
        for a in (self.positions, self.clearance, self.cells, self.edges, self.lengths,
                  self.ridge, *self.edge_cells):
            a.setflags(write=False)

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def graph(self) -> nx.Graph:
        """The networkx view (class doc), built once from the arrays."""
        if self.built is None:
            object.__setattr__(self, "built", _networkx_graph(
                self.positions, self.clearance, self.cells, self.edges, self.lengths))
        assert self.built is not None
        return self.built

    def csgraph(self, keep: np.ndarray | None = None) -> csr_matrix:
        """Symmetric sparse adjacency (weights in m); ``keep`` masks edges. The whole graph
        (no ``keep``) is built once per graph; callers must not change it."""
        if keep is None:
            whole = self.__dict__.get("_whole")
            if whole is None:
                whole = self._adjacency(self.edges, self.lengths)
                object.__setattr__(self, "_whole", whole)
            return whole
        return self._adjacency(self.edges[keep], self.lengths[keep])

    def edge_cells_flat(self) -> tuple[np.ndarray, np.ndarray]:
        """(the cells of every edge, concatenated in edge order; where each edge's start),
        built once per graph (edges without cells: none, every edge has its ends)."""
        got = self.__dict__.get("_edge_cells_flat")
        if got is None:
            m = len(self.edge_cells)
            sizes = np.fromiter((len(c) for c in self.edge_cells), dtype=np.int64, count=m)
            got = (np.concatenate(self.edge_cells) if m else np.zeros(0, dtype=np.int64),
                   np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64))
            object.__setattr__(self, "_edge_cells_flat", got)
        return got

    def _adjacency(self, e: np.ndarray, w: np.ndarray) -> csr_matrix:
        n = len(self.positions)
        if len(e) == 0:
            return csr_matrix((n, n))
        rows = np.concatenate([e[:, 0], e[:, 1]])
        cols = np.concatenate([e[:, 1], e[:, 0]])
        return csr_matrix((np.concatenate([w, w]), (rows, cols)), shape=(n, n))


def _zhang_suen_tables() -> tuple[np.ndarray, np.ndarray]:
    """Per 8-neighbourhood code (bit i: neighbour p(i+2) of Zhang-Suen's p2 (north), p3,
    ... p9 clockwise), whether the pixel is deleted in the first and second sub-iteration:
    2 <= B <= 6 neighbours, A == 1 0->1 transition around, and the sub-iteration's two
    products zero."""
    first = np.zeros(256, dtype=bool)
    second = np.zeros(256, dtype=bool)
    for code in range(256):
        p = [(code >> i) & 1 for i in range(8)]  # p2 .. p9
        b = sum(p)
        a = sum(1 for i in range(8) if p[i] == 0 and p[(i + 1) % 8] == 1)
        if not (2 <= b <= 6 and a == 1):
            continue
        p2, _, p4, _, p6, _, p8, _ = p
        first[code] = p2 * p4 * p6 == 0 and p4 * p6 * p8 == 0
        second[code] = p2 * p4 * p8 == 0 and p2 * p6 * p8 == 0
    return first, second


_ZS_FIRST, _ZS_SECOND = _zhang_suen_tables()


def thin(mask: np.ndarray) -> np.ndarray:
    """Zhang-Suen thinning of a boolean image. Each sub-iteration looks only at the pixels
    still set (neighbourhood codes gathered from the padded image, deletion by table), all
    against the image as the sub-iteration found it, as the parallel algorithm says."""
    if not mask.any():
        return mask.copy()
    h, w = mask.shape
    ww = w + 2
    img = np.zeros((h + 2) * ww, dtype=np.uint8)
    img.reshape(h + 2, ww)[1:-1, 1:-1] = mask
    idx = np.flatnonzero(img)
    offsets = (-ww, -ww + 1, 1, ww + 1, ww, ww - 1, -1, -ww - 1)  # p2 .. p9
    while True:
        changed = False
        for table in (_ZS_FIRST, _ZS_SECOND):
            code = np.zeros(len(idx), dtype=np.uint8)
            for bit, off in enumerate(offsets):
                code |= img[idx + off] << np.uint8(bit)
            gone = table[code]
            if gone.any():
                img[idx[gone]] = 0
                idx = idx[~gone]
                changed = True
        if not changed:
            break
    return img.reshape(h + 2, ww)[1:-1, 1:-1].astype(bool)


def pixel_graph(mask: np.ndarray) -> tuple[np.ndarray, csr_matrix]:
    """(flat indices of the mask's pixels in raster order, adjacency with step lengths in
    cells): 4-neighbours always, diagonal neighbours only without a 4-neighbour detour.
    Neighbours are looked up for the set pixels only, in the zero-padded image."""
    h, w = mask.shape
    ww = w + 2
    img = np.zeros((h + 2) * ww, dtype=bool)
    img.reshape(h + 2, ww)[1:-1, 1:-1] = mask
    pidx = np.flatnonzero(img)
    n = len(pidx)
    pr, pc = np.divmod(pidx, ww)
    flat = (pr - 1) * w + (pc - 1)
    index = np.full(img.size, -1, dtype=np.int64)
    index[pidx] = np.arange(n)
    src: list[np.ndarray] = []
    dst: list[np.ndarray] = []
    wts: list[np.ndarray] = []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        e = img[pidx + dr * ww + dc]
        if dr and dc:
            e &= ~img[pidx + dc] & ~img[pidx + dr * ww]
        s = np.flatnonzero(e)
        src.append(s)
        dst.append(index[pidx[s] + dr * ww + dc])
        wts.append(np.full(len(s), _SQRT2 if dr and dc else 1.0))
    s, d, wt = np.concatenate(src), np.concatenate(dst), np.concatenate(wts)
    adj = csr_matrix((np.concatenate([wt, wt]), (np.concatenate([s, d]), np.concatenate([d, s]))),
                     shape=(n, n))
    adj.sort_indices()
    return flat, adj


@dataclass(frozen=True, eq=False)
class RidgeGraph:
    """The thinned ridge as a pixel graph, before choosing a component (what depends on
    the free cells only; the builder caches it while they do not change, and the next
    one is computed from it: :mod:`sgtool.mapping.ridge_window`)."""

    ridge: np.ndarray  # bool grid
    clearance: np.ndarray  # m per cell
    flat: np.ndarray  # flat cell index of each ridge pixel, raster order
    adj: csr_matrix  # pixel adjacency, step lengths in cells
    component: np.ndarray  # component label per pixel
    fields: RidgeFields | None = None  # what the ridge was computed from


def ridge_graph(occ: OccupancyGrid, config: VoronoiConfig | None = None,
                previous: RidgeGraph | None = None) -> RidgeGraph:
    """Steps 1-2 of the module doc: ridge cells, thinning, pixel graph, components.
    ``previous``: the ridge graph of an earlier grid of the same size; the distance field
    and the ridge cells are then recomputed only around the cells whose freedom changed
    (:func:`sgtool.mapping.ridge_window.update_fields`; the same result)."""
    cfg = config or VoronoiConfig()
    free = ~obstacles(occ)
    fields = None
    if previous is not None and previous.fields is not None:
        fields = update_fields(previous.fields, free, occ.resolution, cfg)
    if fields is None:
        fields = ridge_fields(free, occ.resolution, cfg)
    ridge = thin(fields.ridge0)
    flat, adj = pixel_graph(ridge)
    if len(flat):
        _, comp = connected_components(adj, directed=False)
    else:
        comp = np.zeros(0, dtype=np.int32)
    return RidgeGraph(ridge, fields.dist_m, flat, adj, comp, fields)


def submatrix(graph: csr_matrix, nodes: np.ndarray, where: np.ndarray | None = None
              ) -> csr_matrix:
    """``graph[nodes][:, nodes]`` for sorted ``nodes`` of a CSR matrix with sorted
    indices, the same arrays in the same order, without scipy's general fancy indexing
    (called per room and per refresh, its overhead dominated); ``where``: scratch space of
    the matrix's size, -1 everywhere (as it is left)."""
    if where is None:
        where = np.full(graph.shape[0], -1, dtype=np.int64)
    k = len(nodes)
    where[nodes] = np.arange(k)
    start, stop = graph.indptr[nodes], graph.indptr[nodes + 1]
    count = stop - start
    entry = np.repeat(start - np.concatenate([[0], np.cumsum(count)[:-1]]), count) + np.arange(
        int(count.sum()))
    col = where[graph.indices[entry]]
    ok = col >= 0
    row_len = np.bincount(np.repeat(np.arange(k), count)[ok], minlength=k)
    indptr = np.concatenate([[0], np.cumsum(row_len)])
    where[nodes] = -1
    return csr_matrix((graph.data[entry[ok]], col[ok], indptr), shape=(k, k))


def chosen_component(occ: OccupancyGrid, rg: RidgeGraph,
                     anchor: tuple[float, float] | None) -> int:
    """The ridge component the graph is built on: the one of the ridge pixel nearest to
    ``anchor`` (the robot), else the largest (ties: the lowest label); -1 without ridge."""
    if len(rg.flat) == 0:
        return -1
    if anchor is not None:
        pr, pc = np.divmod(rg.flat, rg.ridge.shape[1])
        px, py = occ.center_of(pr, pc)
        d2 = (px - anchor[0]) ** 2 + (py - anchor[1]) ** 2
        return int(rg.component[int(np.argmin(d2))])
    sizes = np.bincount(rg.component)
    return int(np.flatnonzero(sizes == sizes.max())[0])


def visited_components(occ: OccupancyGrid, rg: RidgeGraph,
                       anchor: tuple[float, float] | None,
                       trajectory: np.ndarray | None = None) -> tuple[int, ...]:
    """The ridge components the graph is built on, sorted: :func:`chosen_component` and
    every component the ``trajectory`` (k, 2 world x, y) passed through. A trajectory
    point passed through the component of its nearest ridge pixel when it lies within
    that pixel's clearance (inside the free disc the pixel stands for); the robot drove
    there, so a phantom obstacle that splits the ridge (a stray voxel in a doorway) does
    not drop the rooms behind it. Empty without ridge."""
    first = chosen_component(occ, rg, anchor)
    if first < 0:
        return ()
    if trajectory is None or len(trajectory) == 0 or int(rg.component.max()) == 0:
        return (first,)
    from scipy.spatial import cKDTree

    pr, pc = np.divmod(rg.flat, rg.ridge.shape[1])
    px, py = occ.center_of(pr, pc)
    pts = np.asarray(trajectory, dtype=np.float64).reshape(-1, 2)
    dist, near = cKDTree(np.stack([px, py], axis=1)).query(pts)
    inside = dist <= rg.clearance[pr[near], pc[near]]
    comps = np.unique(np.append(rg.component[near[inside]], first))
    return tuple(int(c) for c in comps)


def voronoi_graph(occ: OccupancyGrid, config: VoronoiConfig | None = None,
                  anchor: tuple[float, float] | None = None,
                  ridge: RidgeGraph | None = None,
                  trajectory: np.ndarray | None = None,
                  components: tuple[int, ...] | None = None) -> VoronoiGraph:
    """The sparsified generalized Voronoi graph of the explored free space of ``occ``
    (``ridge``: a :func:`ridge_graph` of the same grid, to skip steps 1-2); with a
    ``trajectory``, over every component it passed through
    (:func:`visited_components`), else over the anchor's; ``components``: what
    :func:`visited_components` gives for these arguments, when the caller has it."""
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
    targets = (components if components is not None
               else visited_components(occ, rg, anchor, trajectory))
    keep = np.flatnonzero(np.isin(comp, np.asarray(targets, dtype=comp.dtype)))
    flat = flat[keep]
    adj = submatrix(adj, keep)
    pieces = sparsify(trace_chain_arrays(adj), np.diff(adj.indptr), adj.shape[0],
                      cfg.min_spur / res, cfg.node_spacing / res, res)
    cells_flat = flat[pieces.nodes]
    rows, cols = np.divmod(cells_flat, w)
    xs, ys = occ.center_of(rows, cols)
    positions = np.stack([xs, ys], axis=1)
    clearance = dist_m[rows, cols]
    cells_all = flat[pieces.cells]
    bounds = pieces.cell_start.tolist()
    edge_cells = tuple(cells_all[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True))
    edges, lengths = pieces.edges, pieces.lengths
    return VoronoiGraph(None, positions, clearance, np.stack([rows, cols], axis=1), edges,
                        lengths, edge_cells, rg.ridge, (h, w))


def _networkx_graph(positions: np.ndarray, clearance: np.ndarray, cells: np.ndarray,
                    edges: np.ndarray, lengths: np.ndarray) -> nx.Graph:
    import networkx as nx

    g = nx.Graph()
    g.add_nodes_from(
        (i, {"pos": (x, y), "clearance": c, "cell": (r, q)})
        for i, (x, y, c, r, q) in enumerate(zip(
            positions[:, 0].tolist(), positions[:, 1].tolist(), clearance.tolist(),
            cells[:, 0].tolist(), cells[:, 1].tolist(), strict=True)))
    g.add_edges_from((u, v, {"weight": lm}) for (u, v), lm in zip(
        edges.tolist(), lengths.tolist(), strict=True))
    return g
