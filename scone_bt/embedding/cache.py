"""An on-disk embedding cache keyed by model and text, so a repeated action text never costs a forward pass."""

from __future__ import annotations

import sqlite3
import threading
from collections import OrderedDict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from scone_bt.resources import default_cache_dir

__all__ = ["EmbeddingCache", "MEMORY_ENTRIES", "cache_file_for", "default_cache_dir"]

MEMORY_ENTRIES = 50_000
"""Most vectors one model's cache holds in memory (about 1.7 kB each at 384-d: 85 MB at most; a whole corpus's
recipe steps fit). Past it the least recently used go; the file keeps every vector, and a text that left memory is
read back from it, not encoded again. Without the bound a process running all day grew with every new text."""
_QUERY_CHUNK = 500
"""Texts per SELECT when reading vectors back from the file (SQLite's limit on parameters is far above)."""

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

    Lookups hit memory first (at most `MEMORY_ENTRIES` vectors, least recently used out first), then the file; the
    file is read once per model on construction (up to the bound) and written once per batch of new texts. A
    cache file that cannot be opened is ignored (the cache is an optimisation, never a failure).

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
        self._memory: OrderedDict[str, np.ndarray] = OrderedDict()
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
                "SELECT text, vector FROM embeddings WHERE model = ? LIMIT ?",
                (self.model_key, MEMORY_ENTRIES),
            ).fetchall()
        except sqlite3.Error:
            return
        self._remember(rows)

    def _remember(self, rows: Sequence[tuple[str, bytes]]) -> dict[str, np.ndarray]:
        """Keep the file's (text, vector bytes) rows in memory (a vector of the wrong length is ignored); the
        vectors read, by text (the bound may have let some go from memory already)."""
        read: dict[str, np.ndarray] = {}
        for text, blob in rows:
            vec = np.frombuffer(blob, dtype=np.float32)
            if vec.shape == (self.dim,):
                self._memory[text] = read[text] = vec
        self._trim()
        return read

    def _trim(self) -> None:
        while len(self._memory) > MEMORY_ENTRIES:
            self._memory.popitem(last=False)

    def _from_file(self, texts: list[str]) -> dict[str, np.ndarray]:
        """Read back into memory those of ``texts`` the file holds (they left memory, or another process wrote
        them); their vectors by text."""
        if self._conn is None or not texts:
            return {}
        rows: list[tuple[str, bytes]] = []
        with self._lock:
            try:
                for start in range(0, len(texts), _QUERY_CHUNK):
                    chunk = texts[start : start + _QUERY_CHUNK]
                    rows += self._conn.execute(
                        "SELECT text, vector FROM embeddings WHERE model = ? AND text IN "
                        f"({', '.join('?' * len(chunk))})",
                        (self.model_key, *chunk),
                    ).fetchall()
            except sqlite3.Error:
                return {}
        return self._remember(rows)

    def __len__(self) -> int:
        return len(self._memory)

    def __contains__(self, text: str) -> bool:
        return text in self._memory

    def get(self, text: str) -> np.ndarray | None:
        """The vector of one text held in memory (read-only view), or None."""
        vec = self._memory.get(text)
        if vec is not None:
            self._memory.move_to_end(text)
        return vec

    def lookup(self, texts: Sequence[str]) -> tuple[dict[str, np.ndarray], list[str]]:
        """The cached vectors among `texts` (from memory, else the file), and the distinct texts cached nowhere,
        in first-seen order; counts hits and misses."""
        found: dict[str, np.ndarray] = {}
        for text in dict.fromkeys(texts):
            vec = self.get(text)
            if vec is not None:
                found[text] = vec
        found.update(self._from_file([t for t in dict.fromkeys(texts) if t not in found]))
        seen: set[str] = set()
        todo = []
        for text in texts:
            if text in found:
                self.hits += 1
            else:
                self.misses += 1
                if text not in seen:
                    seen.add(text)
                    todo.append(text)
        return found, todo

    def missing(self, texts: Sequence[str]) -> list[str]:
        """Distinct texts of `texts` that are not cached yet, in first-seen order; counts hits and misses."""
        return self.lookup(texts)[1]

    def put(self, texts: Sequence[str], vectors: np.ndarray) -> None:
        """Store vectors (n, dim) for texts, in memory and in the file (one transaction)."""
        vectors = np.ascontiguousarray(vectors, dtype=np.float32)
        for text, vec in zip(texts, vectors, strict=True):
            self._memory[text] = vec
            self._memory.move_to_end(text)
        self._trim()
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
