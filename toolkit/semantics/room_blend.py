"""Room priors that know what they do not know: distilled scores blended with neighbours.

The distilled containment model scores any name, but on a name far from its training
vocabulary it extrapolates, mostly towards the room types with the most training data
(kitchen, living room). :class:`RoomBlend` scores a room for a query from two sides and
leans on the second the further the query is from the names the model was trained on:

- ``learned(q, r)``: the distilled containment score, in [0, 1];
- ``knowledge(q, r)``: the evidence of the nearest known names and the room's name:

      nb_k(q, r) = mean of the k largest cos(E(q), E(t)) over the names t of room r's
                   table (:func:`sgtool.semantics.room_knowledge.room_table`: names whose
                   target in r is >= 0.5); 0 for a room type without a table entry
      x(q, r)    = (nb_k(q, r) + w cos(E(q), E(r))) / (1 + w)
      knowledge  = clip((x - low) / (high - low), 0, 1)

  The neighbour score counts how alike the query is to a room's *best* examples, not how
  many examples a room has, so a thin room type (a child's room with a few dozen names)
  competes with the kitchen's hundreds on equal terms.

- the blend, with ``sim(q) = max_t cos(E(q), E(t))`` over the training names t:

      lambda(q) = lambda_max * clip((sim(q) - novelty_lo) / (novelty_hi - novelty_lo), 0, 1)
      score(q, r) = lambda(q) learned(q, r) + (1 - lambda(q)) knowledge(q, r)

:class:`RoomBlendParams` holds k, w, low, high, novelty_lo, novelty_hi and lambda_max.
They are fitted on names held out of training (``sgtool distill --room-blend``:
:func:`fit_room_blend` on a model trained without a fifth of the names), never on the
everyday check set or a benchmark. A weights folder with a ``room_blend.json``
(:data:`BLEND_FILE`: the parameters, the room table, the training names) gives
:class:`sgtool.semantics.priors.LearnedPriors` blended room scores (:func:`load_room_blend`);
the shipped default weights have none, so their room scores are the distilled ones.
Scores are in [0, 1] and depend on (query, room) only, as the planners' memo needs.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.semantics.encoder import SentenceEncoder
from sgtool.semantics.text import category_text

BLEND_FILE = "room_blend.json"
# E(t) of the blend's training names, in their order (float32 .npy, no pickle): a planner
# then encodes only its queries and room names, not a thousand known names
VECTORS_FILE = "room_blend_vectors.npy"
BLEND_VERSION = 1


@dataclass(frozen=True)
class RoomBlendParams:
    """The blend's parameters (module doc), all dimensionless cosines or weights."""

    neighbours: int = 2  # k
    cos_weight: float = 0.5  # w
    low: float = 0.2
    high: float = 0.8
    novelty_lo: float = 0.5
    novelty_hi: float = 1.1
    lambda_max: float = 0.5

    def __post_init__(self) -> None:
        if self.neighbours < 1 or self.cos_weight < 0 or not 0 <= self.lambda_max <= 1:
            raise ValueError("neighbours >= 1, cos_weight >= 0, 0 <= lambda_max <= 1")
        if self.high <= self.low or self.novelty_hi <= self.novelty_lo:
            raise ValueError("high > low and novelty_hi > novelty_lo")


class RoomBlend:
    """The knowledge side and the blend of one room table (module doc)."""

    def __init__(self, table: Mapping[str, Sequence[str]], training_names: Sequence[str],
                 params: RoomBlendParams, encoder: SentenceEncoder,
                 vectors: np.ndarray | None = None) -> None:
        self.params = params
        self.encoder = encoder
        self.table = {category_text(r): sorted({category_text(n) for n in names})
                      for r, names in table.items()}
        self.training_names = sorted({category_text(n) for n in training_names})
        if not self.training_names:
            raise ValueError("a room blend needs the training names")
        missing = sorted({n for ns in self.table.values() for n in ns}
                         - set(self.training_names))
        if missing:
            raise ValueError(f"table names outside the training names: {missing[:3]}")
        if vectors is not None and vectors.shape[0] != len(self.training_names):
            raise ValueError(f"{vectors.shape[0]} vectors for {len(self.training_names)} names")
        self._train = None if vectors is None else np.asarray(vectors, np.float32)
        self._vectors: dict[str, np.ndarray] | None = None

    def training_vectors(self) -> np.ndarray:
        """E(t) of the training names, in their order (given, else encoded once)."""
        if self._train is None:
            self._train = np.asarray(self.encoder.encode(self.training_names), np.float32)
        return self._train

    def _tables(self) -> tuple[dict[str, np.ndarray], np.ndarray]:
        train = self.training_vectors()
        if self._vectors is None:
            row = {n: i for i, n in enumerate(self.training_names)}
            self._vectors = {r: train[[row[n] for n in names]] for r, names in self.table.items()}
        return self._vectors, train

    def parts(self, rooms: Sequence[str], query: str) -> tuple[np.ndarray, np.ndarray, float]:
        """(nb_k(q, r), cos(E(q), E(r))) per room of ``rooms`` and sim(q) (module doc)."""
        vectors, train = self._tables()
        texts = [category_text(r) for r in rooms]
        vecs = self.encoder.encode(texts + [category_text(query)])
        q = vecs[-1]
        k = self.params.neighbours
        nb = np.zeros(len(texts), np.float64)
        for i, r in enumerate(texts):
            ev = vectors.get(r)
            if ev is not None and len(ev):
                nb[i] = float(np.mean(np.sort(ev @ q)[::-1][:k]))
        return nb, (vecs[:-1] @ q).astype(np.float64), float(np.max(train @ q))

    def blend(self, rooms: Sequence[str], query: str, learned: np.ndarray) -> np.ndarray:
        """lambda(q) learned + (1 - lambda(q)) knowledge per room of ``rooms`` (module doc),
        ``learned`` the distilled scores of the same rooms."""
        nb, cos, sim = self.parts(rooms, query)
        return blend_scores(self.params, nb, cos, sim, np.asarray(learned, np.float64))

    def to_json(self) -> dict[str, Any]:
        return {"version": BLEND_VERSION, "params": asdict(self.params),
                "table": self.table, "training_names": self.training_names}


def save_room_blend(folder: Path, blend: RoomBlend, extra: Mapping[str, Any]) -> None:
    """Write ``blend`` into ``folder``: :data:`BLEND_FILE` (its :meth:`RoomBlend.to_json`
    and ``extra``, sorted keys) and :data:`VECTORS_FILE`; byte-stable, atomic per file."""
    import io

    from sgtool.files import atomic_write

    doc = {**blend.to_json(), **extra}
    atomic_write(Path(folder) / BLEND_FILE, json.dumps(doc, indent=1, sort_keys=True) + "\n")
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(blend.training_vectors(), np.float32),
            allow_pickle=False)
    atomic_write(Path(folder) / VECTORS_FILE, buf.getvalue())


def load_room_blend(folder: Path, encoder: SentenceEncoder) -> RoomBlend | None:
    """The blend of a weights folder (its :data:`BLEND_FILE`, with :data:`VECTORS_FILE`
    when present), None when it has none; one line (:class:`SgtoolError`) for a file that
    is not one."""
    path = Path(folder) / BLEND_FILE
    if not path.is_file():
        return None
    vec_path = Path(folder) / VECTORS_FILE
    try:
        vectors = np.load(vec_path, allow_pickle=False) if vec_path.is_file() else None
    except (OSError, ValueError, EOFError) as e:
        raise SgtoolError(f"{vec_path}: not the room blend's name vectors (an .npy array; "
                          f"{type(e).__name__})") from None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        names = {f.name for f in fields(RoomBlendParams)}
        params = RoomBlendParams(**{k: v for k, v in doc["params"].items() if k in names})
        return RoomBlend(doc["table"], doc["training_names"], params, encoder, vectors)
    except (OSError, KeyError, TypeError, ValueError, AttributeError) as e:
        raise SgtoolError(f"{path}: not a room blend ({type(e).__name__}: {e})") from None


# ----- fitting on held-out names -------------------------------------------------------------
PARAM_GRID: dict[str, tuple[Any, ...]] = {
    "neighbours": (2, 3),
    "cos_weight": (0.25, 0.5, 0.75),
    "low": (0.2, 0.3),
    "high": (0.6, 0.8),
    "novelty_lo": (0.3, 0.5, 0.7),
    "novelty_hi": (0.9, 1.1, 1.5),
    "lambda_max": (0.5, 1.0),
}


@dataclass(frozen=True)
class HeldOutName:
    """A name held out of training and the room types where its target is 1."""

    name: str
    best_rooms: frozenset[str]


def blend_scores(p: RoomBlendParams, nb: np.ndarray, cos: np.ndarray, sim: float,
                 learned: np.ndarray) -> np.ndarray:
    """The blend of the module doc from its parts: neighbour scores ``nb`` and room-name
    cosines ``cos`` per room, the query's ``sim`` to the training names, the distilled
    scores ``learned`` per room; values in [0, 1]."""
    x = (nb + p.cos_weight * cos) / (1.0 + p.cos_weight)
    know = np.clip((x - p.low) / (p.high - p.low), 0.0, 1.0)
    lam = p.lambda_max * float(np.clip((sim - p.novelty_lo) / (p.novelty_hi - p.novelty_lo),
                                       0.0, 1.0))
    return lam * np.clip(learned, 0.0, 1.0) + (1.0 - lam) * know


def tied_hit(scores: np.ndarray, best: np.ndarray) -> float:
    """Top-1 hit of ``scores`` against the boolean mask ``best``, ties shared: the share of
    the top-scored rooms (within 1e-9 of the maximum) that are best rooms. A blend whose
    knowledge side saturates at 1 for several rooms cannot tell them apart, and a planner
    ranking by these scores cannot either, so a tie is not a hit by list order."""
    top = scores >= float(np.max(scores)) - 1e-9
    return float(best[top].sum()) / float(top.sum())


def fit_room_blend(table: Mapping[str, Sequence[str]], training_names: Sequence[str],
                   held_out: Sequence[HeldOutName], rooms: Sequence[str],
                   learned: Callable[[Sequence[str], str], np.ndarray],
                   encoder: SentenceEncoder) -> tuple[RoomBlendParams, float]:
    """The grid point of :data:`PARAM_GRID` with the best top-1 accuracy over ``rooms`` on
    ``held_out`` (:func:`tied_hit`: the top room is one of the name's best rooms; a tie
    at the top counts the share of best rooms among the tied ones), and that accuracy.
    ``table`` and ``training_names`` must not contain the held-out names, ``learned`` is a
    model trained without them. Ties go to the first grid point in
    :func:`itertools.product` order."""
    if not held_out:
        raise ValueError("no held-out names to fit on")
    keys = list(PARAM_GRID)
    parts: dict[int, list[tuple[np.ndarray, np.ndarray, float, np.ndarray]]] = {}
    for k in PARAM_GRID["neighbours"]:
        b = RoomBlend(table, training_names, RoomBlendParams(neighbours=k), encoder)
        parts[k] = [(*b.parts(rooms, h.name), np.asarray(learned(rooms, h.name), np.float64))
                    for h in held_out]
    gold = [np.array([category_text(r) in h.best_rooms for r in rooms]) for h in held_out]
    best: tuple[float, RoomBlendParams] | None = None
    for values in itertools.product(*(PARAM_GRID[k] for k in keys)):
        p = RoomBlendParams(**dict(zip(keys, values, strict=True)))
        acc = sum(tied_hit(blend_scores(p, *q), g)
                  for g, q in zip(gold, parts[p.neighbours], strict=True)) / len(held_out)
        if best is None or acc > best[0]:
            best = (acc, p)
    assert best is not None
    return best[1], best[0]
