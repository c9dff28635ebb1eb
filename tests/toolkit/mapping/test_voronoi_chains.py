"""The chain tracer of the Voronoi sparsification (CSR entries marked walked) equals the
plain per-pixel walk it replaced (a set of walked pixel pairs), chain for chain, and the
sparse table-driven thinning equals the dense Zhang-Suen it replaced, pixel for pixel, on
random blobs, rings, lines and loops."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from support.voronoi_reference import chain_lists

from sgtool.mapping.ridge_chains import reverse_entries
from sgtool.mapping.voronoi import pixel_graph, thin


def reference_chains(adj: csr_matrix) -> list[tuple[list[int], list[float]]]:
    """The tracer as it was (set of walked (a, b) pairs)."""
    indptr, indices, data = adj.indptr.tolist(), adj.indices.tolist(), adj.data.tolist()
    n = len(indptr) - 1
    deg = [indptr[i + 1] - indptr[i] for i in range(n)]
    used: set[tuple[int, int]] = set()
    chains: list[tuple[list[int], list[float]]] = []

    def walk(start: int, k: int) -> None:
        nxt = indices[k]
        if (start, nxt) in used:
            return
        path, cum = [start], [0.0]
        prev, cur, wgt = start, nxt, data[k]
        while True:
            used.add((prev, cur))
            used.add((cur, prev))
            path.append(cur)
            cum.append(cum[-1] + wgt)
            if deg[cur] != 2 or cur == start:
                break
            a = indptr[cur]
            j = a + 1 if indices[a] == prev else a
            prev, cur, wgt = cur, indices[j], data[j]
            if (prev, cur) in used:
                break
        chains.append((path, cum))

    for p in range(n):
        if deg[p] != 2:
            for k in range(indptr[p], indptr[p + 1]):
                walk(p, k)
    for p in range(n):
        if deg[p] == 2 and (p, indices[indptr[p]]) not in used:
            walk(p, indptr[p])
    return chains


def reference_thin(mask: np.ndarray) -> np.ndarray:
    """Zhang-Suen as it was (dense, on the bounding box)."""
    if not mask.any():
        return mask.copy()
    rr, cc = np.nonzero(mask)
    r0, r1, c0, c1 = rr.min(), rr.max() + 1, cc.min(), cc.max() + 1
    img = np.pad(mask[r0:r1, c0:c1], 1).astype(np.uint8)
    while True:
        changed = False
        for step in (0, 1):
            p2, p3, p4 = img[:-2, 1:-1], img[:-2, 2:], img[1:-1, 2:]
            p5, p6, p7 = img[2:, 2:], img[2:, 1:-1], img[2:, :-2]
            p8, p9 = img[1:-1, :-2], img[:-2, :-2]
            seq = (p2, p3, p4, p5, p6, p7, p8, p9, p2)
            b = p2 + p3 + p4 + p5 + p6 + p7 + p8 + p9
            a = sum(((seq[i] == 0) & (seq[i + 1] == 1)).astype(np.uint8) for i in range(8))
            cond = (img[1:-1, 1:-1] == 1) & (b >= 2) & (b <= 6) & (a == 1)
            if step == 0:
                cond &= (p2 * p4 * p6 == 0) & (p4 * p6 * p8 == 0)
            else:
                cond &= (p2 * p4 * p8 == 0) & (p2 * p6 * p8 == 0)
            if cond.any():
                img[1:-1, 1:-1][cond] = 0
                changed = True
        if not changed:
            break
    out = np.zeros_like(mask)
    out[r0:r1, c0:c1] = img[1:-1, 1:-1].astype(bool)
    return out


def referencepixel_graph(mask: np.ndarray) -> tuple[np.ndarray, csr_matrix]:
    """The pixel graph as it was (dense shifted masks over the whole image)."""
    h, w = mask.shape
    flat = np.flatnonzero(mask.ravel())
    index = np.full(h * w, -1, dtype=np.int64)
    index[flat] = np.arange(len(flat))
    m = np.pad(mask, 1)
    core = m[1:-1, 1:-1]
    src, dst, wts = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        e = core & m[1 + dr:1 + dr + h, 1 + dc:1 + dc + w]
        if dr and dc:
            e &= ~m[1:1 + h, 1 + dc:1 + dc + w] & ~m[1 + dr:1 + dr + h, 1:1 + w]
        r, c = np.nonzero(e)
        src.append(index[r * w + c])
        dst.append(index[(r + dr) * w + (c + dc)])
        wts.append(np.full(len(r), np.sqrt(2.0) if dr and dc else 1.0))
    s, d, wt = np.concatenate(src), np.concatenate(dst), np.concatenate(wts)
    n = len(flat)
    adj = csr_matrix((np.concatenate([wt, wt]), (np.concatenate([s, d]), np.concatenate([d, s]))),
                     shape=(n, n))
    adj.sort_indices()
    return flat, adj


def random_mask(seed: int, size: int = 60) -> np.ndarray:
    rng = np.random.default_rng(seed)
    m = np.zeros((size, size), dtype=bool)
    for _ in range(int(rng.integers(3, 12))):  # filled rectangles, rings, lines
        r0, c0 = rng.integers(0, size - 4, 2)
        r1, c1 = r0 + rng.integers(2, size // 2), c0 + rng.integers(2, size // 2)
        kind = rng.integers(3)
        if kind == 0:
            m[r0:r1, c0:c1] = True
        elif kind == 1:
            m[r0:r1, c0:c1] = True
            m[r0 + 2:r1 - 2, c0 + 2:c1 - 2] = False
        else:
            m[r0, c0:c1] = True
    m |= rng.random((size, size)) < 0.02  # isolated pixels and short hairs
    return m


@pytest.mark.parametrize("seed", range(12))
def test_chains_equal_the_reference_walk(seed: int) -> None:
    mask = thin(random_mask(seed))
    _, adj = pixel_graph(mask)
    got = chain_lists(adj)
    assert got == reference_chains(adj)
    assert len(got) > 5  # the masks do have junctions, ends and loops


@pytest.mark.parametrize("seed", range(24))
def test_thinning_equals_the_dense_reference(seed: int) -> None:
    mask = random_mask(seed, size=int(20 + 7 * seed))
    if seed % 3 == 0:
        mask[0, :] = mask[:, -1] = True  # set pixels on the image border
    got = thin(mask)
    assert np.array_equal(got, reference_thin(mask))
    assert got.sum() < mask.sum()  # it did thin


@pytest.mark.parametrize("seed", range(12))
def test_pixel_graph_equals_the_dense_reference(seed: int) -> None:
    mask = random_mask(seed, size=int(20 + 9 * seed))
    mask[-1, :] = True  # pixels on the border
    for m in (mask, thin(mask)):
        flat, adj = pixel_graph(m)
        ref_flat, ref_adj = referencepixel_graph(m)
        assert np.array_equal(flat, ref_flat) and flat.dtype == ref_flat.dtype
        for part in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(adj, part), getattr(ref_adj, part))
        assert adj.nnz > 0


def test_pure_loop_andreverse_entries() -> None:
    ring = np.zeros((9, 9), dtype=bool)
    ring[2, 2:7] = ring[6, 2:7] = ring[2:7, 2] = ring[2:7, 6] = True
    _, adj = pixel_graph(ring)
    (path, cum), = chain_lists(adj)  # one loop, from its lowest pixel back to it
    assert path[0] == path[-1] == 0 and len(path) == 17 and cum[-1] == pytest.approx(16.0)
    rev = reverse_entries(adj)
    rows = np.repeat(np.arange(adj.shape[0]), np.diff(adj.indptr))
    assert (adj.indices[rev] == rows).all() and (rows[rev] == adj.indices).all()
