"""The embedder interface (ζ): text in, unit vectors out, with a cache in front of every backend."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from scone_bt.embedding.cache import EmbeddingCache

__all__ = ["Embedder", "normalize_rows"]


def normalize_rows(vectors: np.ndarray) -> np.ndarray:
    """Rows scaled to unit length (float32); an all-zero row stays zero (callers avoid producing one)."""
    vectors = np.asarray(vectors, dtype=np.float32)
    norms = np.linalg.norm(vectors, axis=1, keepdims=True)
    return (vectors / np.where(norms > 0, norms, 1.0)).astype(np.float32, copy=False)


class Embedder(ABC):
    """Maps texts to float32 unit vectors of a fixed length.

    Subclasses implement `_encode` (a batch forward pass); `embed` adds the cache, so a text is encoded once per
    model (`cache_key`) and then served from memory (or, across runs, from the SQLite cache file).

    Attributes:
        name: Short name users pass to `load_embedder` ("minilm", "glove", "finetuned:<dir>", ...).
        dim: Length of each vector.
        cache_key: Identity used by the cache: the name plus a fingerprint of the weights.
    """

    name: str
    dim: int
    cache_key: str

    def __init__(self, name: str, dim: int, cache_key: str, cache_file: Path | None) -> None:
        self.name = name
        self.dim = dim
        self.cache_key = cache_key
        self.cache = EmbeddingCache(cache_key, dim, cache_file)

    @abstractmethod
    def _encode(self, texts: Sequence[str]) -> np.ndarray:
        """Vectors (n, dim) for distinct, uncached texts; need not be normalised."""

    def embed(self, texts: Sequence[str]) -> np.ndarray:
        """Unit vectors for `texts`, float32 of shape (len(texts), dim); rows follow the input order."""
        if isinstance(texts, str):
            texts = [texts]
        found, todo = self.cache.lookup(texts)
        if todo:
            vectors = normalize_rows(self._encode(todo))
            self.cache.put(todo, vectors)
            found.update(zip(todo, vectors, strict=True))  # kept here: a bounded cache may drop them
        if not texts:
            return np.zeros((0, self.dim), dtype=np.float32)
        return np.stack([found[t] for t in texts])

    def embed_uncached(self, texts: Sequence[str]) -> np.ndarray:
        """Unit vectors for distinct `texts` encoded now, in the given order, bypassing the cache.

        For training: a backend whose low bits depend on how texts were batched would give a training run
        vectors that depend on what a cache had collected before; here the same texts in the same order give the
        same bits. (The sentence-transformers backend gives each text the bits it gets alone in any batch.)
        """
        texts = [texts] if isinstance(texts, str) else list(texts)
        if len(set(texts)) != len(texts):
            raise ValueError("embed_uncached takes distinct texts")
        if not texts:
            return np.zeros((0, self.dim), dtype=np.float32)
        return normalize_rows(self._encode(texts))

    def embed_one(self, text: str) -> np.ndarray:
        """Unit vector (dim,) for one text."""
        return self.embed([text])[0]

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r}, dim={self.dim})"
