"""An on-disk embedding cache keyed by model and text, so a repeated action text never costs a forward pass."""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from scone_bt.resources import default_cache_dir

__all__ = ["EmbeddingCache", "cache_file_for", "default_cache_dir"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS embeddings (
    model TEXT NOT NULL,
    text TEXT NOT NULL,
    vector BLOB NOT NULL,
    PRIMARY KEY (model, text)
) WITHOUT ROWID
"""


def cache_file_for(cache_dir: Path | None) -> Path:
    """The SQLite embedding cache inside `cache_dir` (default: default_cache_dir())."""
    return Path(cache_dir if cache_dir is not None else default_cache_dir()) / "embeddings.sqlite"


class EmbeddingCache:
    """Unit vectors of one model, in memory and (optionally) in an SQLite file shared by every model.

    Lookups hit a dict first; the file is read once per model on construction and written once per batch of
    new texts. A cache file that cannot be opened is ignored (the cache is an optimisation, never a failure).

    Args:
        model_key: Identity of the model (name plus a fingerprint of its weights).
        dim: Vector length.
        path: SQLite file, or None for a memory-only cache.
    """

    def __init__(self, model_key: str, dim: int, path: Path | None) -> None:
        self.model_key = model_key
        self.dim = dim
        self.path = path
        self.hits = 0
        self.misses = 0
        self._memory: dict[str, np.ndarray] = {}
        self._lock = threading.Lock()
        self._conn: sqlite3.Connection | None = None
        if path is not None:
            self._conn = self._open(path)
            if self._conn is not None:
                self._load()

    def _open(self, path: Path) -> sqlite3.Connection | None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            conn = sqlite3.connect(path, timeout=10.0, check_same_thread=False)
            conn.execute("PRAGMA journal_mode=WAL")
            conn.execute(_SCHEMA)
            conn.commit()
            return conn
        except (OSError, sqlite3.Error):
            return None

    def _load(self) -> None:
        assert self._conn is not None
        try:
            rows = self._conn.execute(
                "SELECT text, vector FROM embeddings WHERE model = ?", (self.model_key,)
            ).fetchall()
        except sqlite3.Error:
            return
        for text, blob in rows:
            vec = np.frombuffer(blob, dtype=np.float32)
            if vec.shape == (self.dim,):
                self._memory[text] = vec

    def __len__(self) -> int:
        return len(self._memory)

    def __contains__(self, text: str) -> bool:
        return text in self._memory

    def get(self, text: str) -> np.ndarray | None:
        """The cached vector of one text (read-only view), or None."""
        return self._memory.get(text)

    def missing(self, texts: Sequence[str]) -> list[str]:
        """Distinct texts of `texts` that are not cached yet, in first-seen order; counts hits and misses."""
        seen: set[str] = set()
        out = []
        for text in texts:
            if text in self._memory:
                self.hits += 1
            else:
                self.misses += 1
                if text not in seen:
                    seen.add(text)
                    out.append(text)
        return out

    def put(self, texts: Sequence[str], vectors: np.ndarray) -> None:
        """Store vectors (n, dim) for texts, in memory and in the file (one transaction)."""
        vectors = np.ascontiguousarray(vectors, dtype=np.float32)
        for text, vec in zip(texts, vectors, strict=True):
            self._memory[text] = vec
        if self._conn is None:
            return
        rows = [(self.model_key, t, v.tobytes()) for t, v in zip(texts, vectors, strict=True)]
        with self._lock:
            try:
                with self._conn:
                    self._conn.executemany("INSERT OR REPLACE INTO embeddings VALUES (?, ?, ?)", rows)
            except sqlite3.Error:
                pass  # a read-only or busy cache file must not stop the robot

    def close(self) -> None:
        """Close the file (memory entries stay usable)."""
        if self._conn is not None:
            self._conn.close()
            self._conn = None
