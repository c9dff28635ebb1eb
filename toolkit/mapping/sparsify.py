"""Step 4 of :mod:`sgtool.mapping.voronoi` on arrays: the chains of the thinned ridge
(:mod:`sgtool.mapping.ridge_chains`) cut into evenly spaced edges, for all chains at once.

The rules are those of the module doc there, in chain order:

- a chain is dropped when it is a spur: one end a leaf, one a junction, shorter than
  ``min_spur``;
- a kept chain gets ``k = max(1, round(length / spacing))`` pieces, at least 3 when it is a
  loop, at least 2 when an earlier kept chain joins the same two pixels;
- the cut before piece ``i`` is the first pixel whose cumulative length reaches
  ``length * i / k``, at least one pixel after the previous cut, never the last pixel
  (``j_i = min(max(b_i, j_{i-1} + 1), last)``, kept when below ``last``: unrolled,
  ``j_i = i + max_{l <= i}(b_l - l)`` with ``b_0 = 0``, a running maximum);
- every piece is an edge between the pixels at its cuts (the nodes), weighing its length
  along the ridge; of several pieces between the same two nodes the shortest (the first
  of equals) is kept, its cells listed from the lower node.

Cumulative lengths are summed step by step along each chain, in the order a loop would
(:func:`chain_cumsum`), so every length is the one a loop over the chains computes, bit
for bit (checked against that loop in the tests)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Chains:
    """Chains of pixels, concatenated: chain c is ``pix[start[c]:start[c + 1]]`` with the
    cumulative length (cells) at each of its pixels in ``cum`` (0.0 at its first)."""

    pix: np.ndarray  # int64
    start: np.ndarray  # int64 (C + 1,)
    cum: np.ndarray  # float64, as pix

    def __len__(self) -> int:
        return len(self.start) - 1


def chain_cumsum(steps: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Per chain of ``sizes[c]`` steps (``steps`` concatenated): 0.0, then the running sum
    of its steps, added one at a time from the first (``itertools.accumulate`` with
    ``initial=0.0``); all chains of similar length at once, as rows of a padded array."""
    c = len(sizes)
    out = np.empty(len(steps) + c, dtype=np.float64)
    if c == 0:
        return out
    step_start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    pix_start = step_start + np.arange(c)
    bits = np.zeros(c, dtype=np.int64)
    rest = sizes.astype(np.int64).copy()
    while rest.any():
        bits += rest > 0
        rest >>= 1
    for b in np.unique(bits).tolist():  # rows padded to at most twice their length
        idx = np.flatnonzero(bits == b)
        width = int(sizes[idx].max()) + 1
        mat = np.zeros((len(idx), width), dtype=np.float64)
        row = np.repeat(np.arange(len(idx)), sizes[idx])
        within = np.arange(len(row)) - np.repeat(
            np.concatenate([[0], np.cumsum(sizes[idx])[:-1]]), sizes[idx])
        mat[row, within + 1] = steps[np.repeat(step_start[idx], sizes[idx]) + within]
        acc = np.add.accumulate(mat, axis=1)
        n_pix = sizes[idx] + 1
        prow = np.repeat(np.arange(len(idx)), n_pix)
        pcol = np.arange(len(prow)) - np.repeat(np.concatenate([[0], np.cumsum(n_pix)[:-1]]),
                                                n_pix)
        out[np.repeat(pix_start[idx], n_pix) + pcol] = acc[prow, pcol]
    return out


@dataclass(frozen=True, eq=False)
class Pieces:
    """The sparsified graph on pixel ids: ``nodes`` (sorted pixel ids), ``edges`` (node
    ids, u < v, sorted), their ``lengths`` (m) and, per edge, the pixels along it from
    u (``cells[cell_start[e]:cell_start[e + 1]]``)."""

    nodes: np.ndarray
    edges: np.ndarray
    lengths: np.ndarray
    cells: np.ndarray
    cell_start: np.ndarray


def sparsify(chains: Chains, degree: np.ndarray, n: int, min_spur: float, spacing: float,
             resolution: float) -> Pieces:
    """The module doc's rules; ``degree`` per pixel, ``n`` pixels, ``min_spur`` and
    ``spacing`` in cells; lengths in metres (cells x ``resolution``; the shortest piece
    is chosen by that length)."""
    pix, start, cum = chains.pix, chains.start, chains.cum
    first, last_at = start[:-1], start[1:] - 1
    a, b = pix[first], pix[last_at]
    length = cum[last_at]
    da, db = degree[a], degree[b]
    spur = ((da == 1) | (db == 1)) & ((da >= 3) | (db >= 3)) & (length < min_spur)
    kept = np.flatnonzero(~spur)
    if len(kept) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return Pieces(np.arange(min(n, 1), dtype=np.int64), np.zeros((0, 2), np.int64),
                      np.zeros(0), empty, np.zeros(1, dtype=np.int64))
    a, b, length = a[kept], b[kept], length[kept]
    k = np.maximum(1, np.rint(length / spacing).astype(np.int64))
    pair = np.minimum(a, b) * n + np.maximum(a, b)
    _, first_of, inverse = np.unique(pair, return_index=True, return_inverse=True)
    again = first_of[inverse] != np.arange(len(kept))  # an earlier kept chain, same pair
    k = np.where(a == b, np.maximum(k, 3), np.where(again & (k < 2), 2, k))
    cuts, owner = _cuts(cum, start[kept], start[kept + 1] - start[kept], length, k)
    # pieces between consecutive cuts of a chain
    same = owner[1:] == owner[:-1]
    s0, s1 = cuts[:-1][same], cuts[1:][same]  # absolute positions in pix
    nodes = np.unique(np.concatenate([pix[s0], pix[s1]]))
    u = np.searchsorted(nodes, pix[s0])
    v = np.searchsorted(nodes, pix[s1])
    seg_len = (cum[s1] - cum[s0]) * resolution
    proper = u != v
    u, v, s0, s1, seg_len = u[proper], v[proper], s0[proper], s1[proper], seg_len[proper]
    key = np.minimum(u, v) * len(nodes) + np.maximum(u, v)
    order = np.lexsort((np.arange(len(key)), seg_len, key))  # per key: shortest, first
    lead = np.concatenate([[True], key[order][1:] != key[order][:-1]]) if len(order) else \
        np.zeros(0, dtype=bool)
    pick = order[lead]  # one piece per key, in key order
    u, v, s0, s1, seg_len = u[pick], v[pick], s0[pick], s1[pick], seg_len[pick]
    edges = np.stack([np.minimum(u, v), np.maximum(u, v)], axis=1).astype(np.int64)
    size = s1 - s0 + 1
    cell_start = np.concatenate([[0], np.cumsum(size)]).astype(np.int64)
    within = np.arange(int(cell_start[-1])) - np.repeat(cell_start[:-1], size)
    forward = np.repeat(u < v, size)
    at = np.where(forward, np.repeat(s0, size) + within, np.repeat(s1, size) - within)
    return Pieces(nodes, edges, seg_len, pix[at], cell_start)


def _cuts(cum: np.ndarray, start: np.ndarray, count: np.ndarray, length: np.ndarray,
          k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(absolute positions of every cut of every chain, in order, the chain of each):
    the module doc's rule, chains of ``count`` pixels from ``start``."""
    c = len(k)
    last = count - 1
    inner = np.maximum(k - 1, 0)
    chain = np.repeat(np.arange(c), inner)
    i = np.arange(len(chain)) - np.repeat(np.concatenate([[0], np.cumsum(inner)[:-1]]), inner)
    i += 1
    target = length[chain] * i / k[chain]
    # b: the first position whose cumulative length reaches the target (bisect_left),
    # found for all chains at once by sorting targets among the chains' lengths
    pix_chain = np.repeat(np.arange(c), count)
    before = np.concatenate([[0], np.cumsum(count)[:-1]])
    pos = np.repeat(start, count) + np.arange(int(count.sum())) - np.repeat(before, count)
    vals = np.concatenate([cum[pos], target])
    owner = np.concatenate([pix_chain, chain])
    is_pix = np.concatenate([np.ones(len(pos), dtype=np.int64), np.zeros(len(chain), np.int64)])
    order = np.lexsort((is_pix, vals, owner))
    below = np.cumsum(is_pix[order])  # pixels sorted before (or at) each place
    q = order >= len(pos)
    rank = np.empty(len(chain), dtype=np.int64)
    rank[order[q] - len(pos)] = below[q]
    b = rank - before[chain]  # pixels of the chain with a length below the target
    # j_i = i + running max of (b_l - l), with b_0 = 0 (segmented by chain offsets)
    width = int(count.max()) + int(k.max()) + 2
    base = np.arange(c, dtype=np.int64) * (2 * width)
    lead = np.concatenate([[0], np.cumsum(inner + 1)[:-1]])
    run = np.empty(len(chain) + c, dtype=np.int64)
    run[lead] = base
    rest = np.ones(len(run), dtype=bool)
    rest[lead] = False
    run[rest] = b - i + base[chain]
    j = np.maximum.accumulate(run)[rest] - base[chain] + i
    keep = j < last[chain]
    cut_chain = np.concatenate([np.arange(c), chain[keep], np.arange(c)])
    cut_pos = np.concatenate([np.zeros(c, np.int64), j[keep], last])
    rank_in = np.concatenate([np.zeros(c, np.int64), i[keep], k.astype(np.int64)])
    order = np.lexsort((rank_in, cut_chain))
    return start[cut_chain[order]] + cut_pos[order], cut_chain[order]
