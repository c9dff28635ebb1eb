"""The training set of one relation of SCOUT's distilled priors (SCOUT sec. IV-C, Eqs. 6-7).

:class:`RelationalSet` holds (node, query) pairs with targets, whatever they come from: the
BEHAVIOR-1K knowledge (:mod:`sgtool.datasets.relational`) or an LLM
(:mod:`sgtool.semantics.llm_knowledge`). :func:`holdout_queries` picks the query categories
held out of training for the report.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RelationalSet:
    """Pairs (node text, query text) with targets, as index pairs into two vocabularies.

    ``relation`` is ``containment`` (node = room type, continuous target, MSE) or
    ``cooccurrence`` (node = object, binary target, BCE). Vocabularies are sorted; pairs
    are ordered by (query, node), so equal inputs give byte-identical sets.
    """

    relation: str
    nodes: tuple[str, ...]
    queries: tuple[str, ...]
    pairs: np.ndarray  # (K, 2) int64: node index, query index
    targets: np.ndarray  # (K,) float32 in [0, 1]

    def __len__(self) -> int:
        return int(len(self.targets))

    @property
    def positives(self) -> int:
        return int((self.targets > 0).sum())

    def fingerprint(self) -> str:
        """SHA-256 over relation, vocabularies, pairs and targets (the set's identity)."""
        h = hashlib.sha256()
        h.update(json.dumps([self.relation, self.nodes, self.queries]).encode())
        h.update(np.ascontiguousarray(self.pairs, np.int64).tobytes())
        h.update(np.ascontiguousarray(self.targets, np.float32).tobytes())
        return h.hexdigest()

    def subset_queries(self, keep: set[str]) -> RelationalSet:
        """The pairs whose query is in ``keep`` (vocabularies unchanged)."""
        qmask = np.array([q in keep for q in self.queries], dtype=bool)
        sel = qmask[self.pairs[:, 1]] if len(self.pairs) else np.zeros(0, bool)
        return RelationalSet(self.relation, self.nodes, self.queries, self.pairs[sel],
                             self.targets[sel])

    def balanced_weights(self) -> np.ndarray:
        """Per-pair loss weights: per query, positives weigh 1 and the zero-target pairs
        share the positives' total weight (so many zeros do not drown a few positives)."""
        w = np.ones(len(self.targets), np.float32)
        if not len(w):
            return w
        q = self.pairs[:, 1]
        pos = self.targets > 0
        n_pos = np.bincount(q[pos], minlength=len(self.queries))
        n_neg = np.bincount(q[~pos], minlength=len(self.queries))
        ratio = np.where(n_neg > 0, np.maximum(n_pos, 1) / np.maximum(n_neg, 1), 1.0)
        w[~pos] = ratio[q[~pos]]
        return w

    def target(self, node: str, query: str) -> float | None:
        """The target of one pair, None when the pair is not in the set."""
        try:
            i, j = self.nodes.index(node), self.queries.index(query)
        except ValueError:
            return None
        hit = np.nonzero((self.pairs[:, 0] == i) & (self.pairs[:, 1] == j))[0]
        return float(self.targets[hit[0]]) if len(hit) else None


def table_to_set(relation: str, table: dict[tuple[str, str], float]) -> RelationalSet:
    """A set from {(node text, query text): target} (any source: knowledge or an LLM)."""
    nodes = tuple(sorted({n for n, _ in table}))
    queries = tuple(sorted({q for _, q in table}))
    ni = {n: i for i, n in enumerate(nodes)}
    qi = {q: i for i, q in enumerate(queries)}
    keys = sorted(table, key=lambda nq: (qi[nq[1]], ni[nq[0]]))
    pairs = np.array([(ni[n], qi[q]) for n, q in keys], dtype=np.int64).reshape(-1, 2)
    targets = np.array([table[k] for k in keys], dtype=np.float32)
    return RelationalSet(relation, nodes, queries, pairs, targets)


def holdout_queries(queries: Iterable[str], fraction: float, seed: int) -> set[str]:
    """A deterministic share of query categories held out of training (for the report).

    A query is held out when the hash of (seed, query) falls below ``fraction``; the choice
    for one query does not depend on which other queries exist, so the held-out set is
    stable when the knowledge grows.
    """
    out = set()
    for q in queries:
        d = hashlib.sha256(f"{seed}:{q}".encode()).digest()
        if int.from_bytes(d[:8], "big") / 2**64 < fraction:
            out.add(q)
    return out
