"""Relational priors: how useful a room or an object is for finding a query.

Two scorers share one interface (``rooms(names, query)``, ``objects(names, query)`` ->
arrays of scores):

- :class:`LearnedPriors`: SCOUT's distilled models, u_q(r) = f_contain(E(r) (+) E(q))
  (Eq. 11) and u_q(o) = f_co-occur(E(o) (+) E(q)) (Eq. 10), scores in [0, 1];
- :class:`CosinePriors`: the embedding-similarity baseline, u_q(n) = cos(E(q), E(n))
  (Eqs. 14-15).

Names go through :func:`~sgtool.semantics.text.category_text` before encoding. Scores are
memoised per (query, name): a planner re-scores the same few dozen names at every step, and
after the first step a decision costs dictionary look-ups only.

Which rooms a scorer can score (:func:`can_score_room`). SCOUT's containment data comes from
an LLM that scores every room type of its room set for every object. The offline knowledge
covers some room types hardly at all: of the 927 training query categories, 3 are stated to
be found in a pantry, 2 in a storage room, 4 in a television room, 9 in a closet (against
372 in a kitchen), because no activity places things there. The model then learns "nothing
is ever in a pantry" (its pantry score averages 0.006 over the 468 training pairs; the
storage-room positives get 0.000): an absence of data, not a probability. Such a room type,
positive for fewer than :data:`MIN_ROOM_EVIDENCE` of the training queries (the weights'
``room_evidence``), is one the prior cannot score, and a planner treats a room of that type
as an uncategorised one (SCOUT Eq. 2: the default room exploration score). Names the model
was not trained on at all are scored by the model (open vocabulary: a "laundry room" scores
like the utility room, a little lower). The cut
is 1 % of the training queries, the natural "fewer than one in a hundred" (higher cuts drift
towards no room influence at all, every room at the default score; the runs that chose it
are in docs/experiments/moved-from-docstrings.md).
"""

from __future__ import annotations

import functools
import json
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.semantics.encoder import SentenceEncoder, default_encoder
from sgtool.semantics.mlp import RelationMLP, load_mlp
from sgtool.semantics.room_blend import load_room_blend
from sgtool.semantics.text import category_text

WEIGHTS_DIR = Path(__file__).resolve().parent / "weights"
# distilled on the widened room knowledge, with a held-out-fitted room blend
# (:mod:`sgtool.semantics.room_blend`; ``sgtool distill --room-blend``); loaded on request
BLEND_WEIGHTS_DIR = Path(__file__).resolve().parent / "weights_blend"
# names a user may give instead of a weights folder (``--priors blend``)
NAMED_WEIGHTS = {"shipped": WEIGHTS_DIR, "blend": BLEND_WEIGHTS_DIR}
CONTAINMENT_FILE = "containment.safetensors"
COOCCURRENCE_FILE = "cooccurrence.safetensors"
METADATA_FILE = "metadata.json"
# a trained room type is scored when its containment targets are positive for at least this
# share of the training query categories (module doc)
MIN_ROOM_EVIDENCE = 0.01


def weights_folder(weights_dir: str | os.PathLike[str] | None) -> Path:
    """The folder of distilled priors ``weights_dir`` names: the shipped priors for None or
    ``"shipped"``, the shipped room-blend priors for ``"blend"`` (unless a folder of that
    name exists), else the path itself."""
    if weights_dir is None:
        return WEIGHTS_DIR
    name = str(weights_dir)
    if name in NAMED_WEIGHTS and not Path(name).is_dir():
        return NAMED_WEIGHTS[name]
    return Path(weights_dir)


class RelationScorer(Protocol):
    name: str

    def rooms(self, names: Sequence[str], query: str) -> np.ndarray: ...

    def objects(self, names: Sequence[str], query: str) -> np.ndarray: ...


def can_score_room(scorer: object, name: str) -> bool:
    """Whether ``scorer`` has a score for rooms of category ``name`` (module doc); scorers
    without a ``can_score_room`` method score every room."""
    check = getattr(scorer, "can_score_room", None)
    return True if check is None else bool(check(name))


class _Memo:
    """Per-(relation, query) memo of name -> score, filled in batches."""

    def __init__(self) -> None:
        self._memo: dict[tuple[str, str], dict[str, float]] = {}

    def scores(self, relation: str, names: Sequence[str], query: str,
               compute: Callable[[Sequence[str], str], np.ndarray]) -> np.ndarray:
        """Scores of ``names`` for ``query``; ``compute(missing names, query)`` scores those
        not yet memoised."""
        memo = self._memo.setdefault((relation, query), {})
        missing = sorted({n for n in names if n not in memo})
        if missing:
            memo.update(zip(missing, (float(v) for v in compute(missing, query)), strict=True))
        return np.array([memo[n] for n in names], dtype=np.float64)


class LearnedPriors:
    """SCOUT's distilled containment and co-occurrence models (Eqs. 10-11)."""

    name = "learned"

    def __init__(
        self,
        encoder: SentenceEncoder | None = None,
        weights_dir: str | Path | None = None,
        min_room_evidence: float = MIN_ROOM_EVIDENCE,
    ) -> None:
        self.encoder = encoder or default_encoder()
        folder = weights_folder(weights_dir)
        self.weights_dir = folder
        self.containment: RelationMLP = load_mlp(folder / CONTAINMENT_FILE, "containment")
        self.cooccurrence: RelationMLP = load_mlp(folder / COOCCURRENCE_FILE, "cooccurrence")
        meta_path = folder / METADATA_FILE
        try:
            self.metadata: dict = json.loads(meta_path.read_text()) \
                if meta_path.is_file() else {}
        except (json.JSONDecodeError, UnicodeDecodeError) as e:
            raise SgtoolError(f"{meta_path}: not JSON ({e})") from e
        trained_with = self.containment.metadata.get("encoder")
        if trained_with and trained_with != self.encoder.model_id:
            raise SgtoolError(
                f"relational weights in {folder} were trained with encoder {trained_with!r}, "
                f"not {self.encoder.model_id!r}"
            )
        self._memo = _Memo()
        self.unscored_rooms = unscored_room_types(self.metadata.get("room_evidence"),
                                                  min_room_evidence)
        self.room_blend = load_room_blend(folder, self.encoder)

    def can_score_room(self, name: str) -> bool:
        """False for a room type the training data hardly covers (module doc)."""
        return category_text(name) not in self.unscored_rooms

    def forget_scores(self) -> None:
        """Empty the score memo. The MLP scores the names a memo misses as one batch, and a
        score's last float32 bit can depend on its batch: a unit of work that starts from an
        empty memo (a bench task) gives the same bits whatever ran before it in the process."""
        self._memo = _Memo()

    def _mlp_scores(self, mlp: RelationMLP, names: Sequence[str], query: str) -> np.ndarray:
        texts = [category_text(n) for n in names]
        vecs = self.encoder.encode(texts + [category_text(query)])
        return mlp(vecs[:-1], vecs[-1])

    def rooms(self, names: Sequence[str], query: str) -> np.ndarray:
        """p_contains(r, q) for room categories ``names`` (Eq. 11); blended with the
        neighbour knowledge by query novelty when the weights folder has a room blend
        (:mod:`sgtool.semantics.room_blend`)."""
        return self._memo.scores("containment", names, query, self._room_scores)

    def _room_scores(self, names: Sequence[str], query: str) -> np.ndarray:
        learned = self._mlp_scores(self.containment, names, query)
        if self.room_blend is None:
            return learned
        return self.room_blend.blend(names, query, learned)

    def objects(self, names: Sequence[str], query: str) -> np.ndarray:
        """p_co-occur(o, q) for object categories ``names`` (Eq. 10)."""
        return self._memo.scores(
            "cooccurrence", names, query,
            lambda ns, q: self._mlp_scores(self.cooccurrence, ns, q),
        )

    @property
    def room_types(self) -> tuple[str, ...]:
        """Room categories seen in training (the room classifier's label set)."""
        return tuple(self.metadata.get("room_types", ()))


def unscored_room_types(evidence: dict | None, min_share: float) -> frozenset[str]:
    """Room types (canonical text) positive for fewer than ``min_share`` of the training
    queries, from the ``room_evidence`` of the weights' metadata (none without it)."""
    if not evidence or min_share <= 0:
        return frozenset()
    need = min_share * float(evidence["queries"])
    return frozenset(category_text(r) for r, n in evidence["positives"].items() if n < need)


class CosinePriors:
    """SBERT cosine similarity between query and node names (SCOUT Eqs. 14-15); it has a
    score for every room name."""

    name = "cosine"

    def __init__(self, encoder: SentenceEncoder | None = None) -> None:
        self.encoder = encoder or default_encoder()
        self._memo = _Memo()

    def can_score_room(self, name: str) -> bool:
        return True

    def _cos(self, names: Sequence[str], query: str) -> np.ndarray:
        texts = [category_text(n) for n in names]
        vecs = self.encoder.encode(texts + [category_text(query)])
        return (vecs[:-1] @ vecs[-1]).astype(np.float64)

    def rooms(self, names: Sequence[str], query: str) -> np.ndarray:
        return self._memo.scores("cos", names, query, self._cos)

    def objects(self, names: Sequence[str], query: str) -> np.ndarray:
        return self._memo.scores("cos", names, query, self._cos)


class PriorsVocabularyError(SgtoolError):
    """A weights folder whose metadata does not list the queries it was trained on."""


def weights_metadata(weights_dir: str | Path | None = None) -> dict[str, Any]:
    """The ``metadata.json`` of the distilled priors in ``weights_dir`` (the shipped ones by
    default; not an object: empty); a missing or unreadable file is one
    :class:`PriorsVocabularyError` line."""
    path = weights_folder(weights_dir) / METADATA_FILE
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise PriorsVocabularyError(f"{path}: no such file; not a folder of distilled "
                                    "weights") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise PriorsVocabularyError(f"{path}: cannot read weights metadata ({e})") from None
    return meta if isinstance(meta, dict) else {}


def training_queries(weights_dir: str | Path | None = None) -> frozenset[str]:
    """The query categories (canonical text) the distilled priors in ``weights_dir`` (the
    shipped ones by default) were trained on, from the ``training_queries`` of their
    ``metadata.json`` (written by ``sgtool distill`` since metadata version 4). A query is
    *seen* by those priors when its :func:`category_text` is in this set."""
    path = weights_folder(weights_dir) / METADATA_FILE
    queries = weights_metadata(weights_dir).get("training_queries")
    if not isinstance(queries, list) or not all(isinstance(q, str) for q in queries):
        raise PriorsVocabularyError(
            f"{path}: training_queries: missing or not a list of strings (weights distilled "
            "before metadata version 4; run `sgtool distill` again)")
    return frozenset(category_text(q) for q in queries)


@functools.lru_cache(maxsize=1)
def default_priors() -> LearnedPriors:
    """The shipped distilled models with the process-wide encoder."""
    return LearnedPriors()


def forget_default_scores() -> None:
    """:meth:`LearnedPriors.forget_scores` of :func:`default_priors`, if it is loaded."""
    if default_priors.cache_info().currsize:
        default_priors().forget_scores()
