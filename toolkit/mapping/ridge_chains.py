"""Chains of the thinned Voronoi ridge's pixel graph (step 4 of
:mod:`sgtool.mapping.voronoi`): the runs of degree-2 pixels between key pixels, traced
once each, in a fixed order."""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix

from sgtool.mapping.sparsify import Chains, chain_cumsum


def reverse_entries(adj: csr_matrix) -> np.ndarray:
    """For each stored entry (i, j) of a symmetric CSR matrix with sorted indices, the
    position of the entry (j, i)."""
    n = adj.shape[0]
    rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(adj.indptr))
    cols = adj.indices.astype(np.int64)
    return np.searchsorted(rows * n + cols, cols * n + rows)


def trace_chain_arrays(adj: csr_matrix) -> Chains:
    """Chains between key pixels (degree != 2) as (pixel list, cumulative length in cells
    along it), each once, in the order of a walk from every key pixel (ascending) along
    each of its CSR entries not walked yet; then loops without a key pixel, from their
    lowest pixel. (A step is walked in both directions at once: its CSR entry and the
    reverse entry's.)

    The chains from key pixels are found for all entries at once: every entry p -> q
    into a degree-2 pixel q has one successor (q's other entry), so the entries form
    linked lists headed by the entries of key pixels; pointer doubling gives each entry
    its head and depth. A chain and its reverse are the lists headed by its first entry
    and by the reverse of its last; the walk takes the one whose head comes first.
    Returned as :class:`~sgtool.mapping.sparsify.Chains` (cumulative lengths summed step
    by step, :func:`~sgtool.mapping.sparsify.chain_cumsum`)."""
    n = adj.shape[0]
    indptr = adj.indptr.astype(np.int64)
    indices = adj.indices.astype(np.int64)
    e = len(indices)
    if e == 0:
        return Chains(np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(0))
    deg = np.diff(indptr)
    row = np.repeat(np.arange(n, dtype=np.int64), deg)
    rev = reverse_entries(adj)
    # successor of entry k (row[k] -> q): q's other entry when q has degree 2
    q = indices
    mid = np.flatnonzero(deg[q] == 2)
    first = indptr[q[mid]]
    pred = np.full(e, -1, dtype=np.int64)
    pred[np.where(indices[first] == row[mid], first + 1, first)] = mid
    # pointer doubling towards the heads (entries without predecessor)
    up = np.where(pred >= 0, pred, np.arange(e))
    depth = (pred >= 0).astype(np.int64)
    for _ in range(max(1, int(e).bit_length() + 1)):
        nxt = up[up]
        if np.array_equal(nxt, up):
            break
        depth = depth + depth[up]
        up = nxt
    rooted = pred[up] < 0  # the rest lie on loops without a key pixel
    pix_parts: list[np.ndarray] = []
    sizes: list[np.ndarray] = []
    steps: list[np.ndarray] = []
    if rooted.any():
        ks = np.flatnonzero(rooted)
        head = up[ks]
        # the last entry of every list: the deepest of its head
        order = np.lexsort((depth[ks], head))
        ks, head = ks[order], head[order]
        starts = np.flatnonzero(np.concatenate([[True], head[1:] != head[:-1]]))
        stops = np.append(starts[1:], len(ks))
        heads = head[starts]
        walked = heads < rev[ks[stops - 1]]  # this direction's head comes first
        count = (stops - starts)[walked]
        ks = ks[np.repeat(walked, stops - starts)]
        # each chain: its head's source pixel, then the pixel each entry leads to
        off = np.concatenate([[0], np.cumsum(count + 1)[:-1]])
        pix = np.empty(int((count + 1).sum()), dtype=np.int64)
        lead = np.zeros(len(pix), dtype=bool)
        lead[off] = True
        pix[off] = row[heads[walked]]
        pix[~lead] = indices[ks]
        pix_parts.append(pix)
        sizes.append(count)
        steps.append(adj.data[ks].astype(np.float64))
    if not rooted.all():
        for path, step in _trace_loops(adj, rev, rooted):
            pix_parts.append(np.asarray(path, dtype=np.int64))
            sizes.append(np.asarray([len(step)], dtype=np.int64))
            steps.append(np.asarray(step, dtype=np.float64))
    size = np.concatenate(sizes) if sizes else np.zeros(0, np.int64)
    start = np.concatenate([[0], np.cumsum(size + 1)]).astype(np.int64)
    pix = np.concatenate(pix_parts) if pix_parts else np.zeros(0, np.int64)
    return Chains(pix, start, chain_cumsum(np.concatenate(steps) if steps else np.zeros(0),
                                          size))


def _trace_loops(adj: csr_matrix, rev: np.ndarray, walked: np.ndarray
                 ) -> list[tuple[list[int], list[float]]]:
    """The loops without a key pixel (every entry not ``walked``), each from its lowest
    pixel along that pixel's first entry, step by step: (pixels, step lengths)."""
    indptr = adj.indptr.tolist()
    indices = adj.indices.tolist()
    data = adj.data.tolist()
    revl = rev.tolist()
    used = bytearray(walked.astype(np.uint8).tobytes())
    chains: list[tuple[list[int], list[float]]] = []
    for p in np.flatnonzero(np.diff(adj.indptr) == 2).tolist():
        k = indptr[p]
        if used[k]:
            continue
        path, step, prev = [p], [], p
        while True:
            cur = indices[k]
            used[k] = used[revl[k]] = 1
            step.append(data[k])
            path.append(cur)
            if cur == p:
                break
            a = indptr[cur]
            k = a + 1 if indices[a] == prev else a
            prev = cur
            if used[k]:
                break
        chains.append((path, step))
    return chains

