"""On-disk embedding cache: one SQLite table keyed by (model id, text).

The same few thousand category names come back in every planner decision, every training
run and every test session, and encoding one is not free, so embeddings are kept on disk.
SQLite (stdlib) gives atomic writes and safe concurrent readers/writers across the
processes that run side by side (benchmark workers, tests); vectors are stored as raw
little-endian float32 bytes. The cache is an accelerator only: any SQLite error degrades to
"not cached" with one warning, never to a failure.

Location: ``$SGTOOL_CACHE/embeddings/embeddings.sqlite`` when ``SGTOOL_CACHE`` is set,
otherwise ``~/.cache/sgtool/embeddings/embeddings.sqlite``.
"""

from __future__ import annotations

import logging
import os
import sqlite3
import threading
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

log = logging.getLogger(__name__)

CACHE_ENV = "SGTOOL_CACHE"
_SCHEMA = (
    "CREATE TABLE IF NOT EXISTS embedding ("
    " model TEXT NOT NULL, text TEXT NOT NULL, dim INTEGER NOT NULL, vec BLOB NOT NULL,"
    " PRIMARY KEY (model, text))"
)
_CHUNK = 500  # SQLite's default limit on host parameters is 999 (older builds)


def cache_root() -> Path:
    """The sgtool cache folder (``$SGTOOL_CACHE`` or ``~/.cache/sgtool``)."""
    env = os.environ.get(CACHE_ENV)
    return Path(env).expanduser() if env else Path.home() / ".cache" / "sgtool"


def default_cache_path() -> Path:
    return cache_root() / "embeddings" / "embeddings.sqlite"


class EmbeddingCache:
    """Persistent map (model id, text) -> float32 vector."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else default_cache_path()
        self._default = path is None  # a copy elsewhere resolves its own default
        self._conn: sqlite3.Connection | None = None
        self._lock = threading.Lock()
        self._broken = False

    def __getstate__(self) -> dict[str, Any]:
        """The path and whether it failed: a copy (in another process) opens its own
        connection when first used."""
        return {"path": None if self._default else self.path,
                "broken": self._broken and not self._default}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["path"])  # type: ignore[misc]
        self._broken = state["broken"]

    def _connect(self) -> sqlite3.Connection | None:
        if self._broken:
            return None
        if self._conn is None:
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                conn = sqlite3.connect(str(self.path), timeout=30.0, check_same_thread=False)
                conn.execute("PRAGMA journal_mode=WAL")
                conn.execute(_SCHEMA)
                conn.commit()
                self._conn = conn
            except (sqlite3.Error, OSError) as e:
                log.warning("embedding cache %s unusable (%s); continuing without it",
                            self.path, e)
                self._broken = True
                return None
        return self._conn

    def get_many(self, model: str, texts: Sequence[str]) -> dict[str, np.ndarray]:
        """Cached vectors for those of ``texts`` that are present."""
        out: dict[str, np.ndarray] = {}
        unique = sorted(set(texts))
        with self._lock:
            conn = self._connect()
            if conn is None:
                return out
            try:
                for i in range(0, len(unique), _CHUNK):
                    chunk = unique[i : i + _CHUNK]
                    marks = ",".join("?" * len(chunk))
                    sql = ("SELECT text, dim, vec FROM embedding"
                           f" WHERE model = ? AND text IN ({marks})")
                    rows = conn.execute(sql, (model, *chunk)).fetchall()
                    for text, dim, blob in rows:
                        vec = np.frombuffer(blob, dtype="<f4")
                        if vec.shape == (dim,):
                            out[text] = vec.astype(np.float32, copy=True)
            except sqlite3.Error as e:
                log.warning("embedding cache read failed (%s); ignoring the cache", e)
        return out

    def put_many(self, model: str, items: Iterable[tuple[str, np.ndarray]]) -> None:
        rows = [
            (model, text, int(v.shape[0]), np.ascontiguousarray(v, dtype="<f4").tobytes())
            for text, v in items
        ]
        if not rows:
            return
        with self._lock:
            conn = self._connect()
            if conn is None:
                return
            try:
                conn.executemany(
                    "INSERT OR IGNORE INTO embedding (model, text, dim, vec) VALUES (?,?,?,?)",
                    rows,
                )
                conn.commit()
            except sqlite3.Error as e:
                log.warning("embedding cache write failed (%s); continuing", e)

    def count(self, model: str | None = None) -> int:
        with self._lock:
            conn = self._connect()
            if conn is None:
                return 0
            if model is None:
                return int(conn.execute("SELECT COUNT(*) FROM embedding").fetchone()[0])
            return int(
                conn.execute("SELECT COUNT(*) FROM embedding WHERE model = ?", (model,))
                .fetchone()[0]
            )

    def close(self) -> None:
        with self._lock:
            if self._conn is not None:
                self._conn.close()
                self._conn = None
