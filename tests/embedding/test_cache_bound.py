"""The embedding cache holds at most MEMORY_ENTRIES vectors in memory; one that left is read back from the file."""

from __future__ import annotations

import numpy as np

from scone_bt.embedding import cache as cache_module
from scone_bt.embedding.base import Embedder


class _Counting(Embedder):
    """A deterministic embedder that counts the texts it encodes."""

    def __init__(self, cache_file) -> None:
        super().__init__("counting", 4, "counting@1", cache_file)
        self.encoded: list[str] = []

    def _encode(self, texts):
        self.encoded.extend(texts)
        return np.array([[len(t), t.count("a") + 1, 1.0, 2.0] for t in texts], dtype=np.float32)


def test_memory_is_bounded_and_an_evicted_text_comes_back_from_the_file(tmp_path, monkeypatch):
    monkeypatch.setattr(cache_module, "MEMORY_ENTRIES", 3)
    emb = _Counting(tmp_path / "e.sqlite")
    first = emb.embed(["a", "bb", "ccc", "dddd", "eeeee"])
    assert len(emb.cache) == 3 and emb.encoded == ["a", "bb", "ccc", "dddd", "eeeee"]
    assert "a" not in emb.cache  # the least recently used left memory...
    again = emb.embed(["a", "eeeee"])
    assert emb.encoded == [
        "a",
        "bb",
        "ccc",
        "dddd",
        "eeeee",
    ]  # ...and came back from the file, not encoded again
    assert np.array_equal(again, first[[0, 4]]) and len(emb.cache) == 3


def test_a_batch_larger_than_the_bound_still_gets_every_vector(monkeypatch):
    monkeypatch.setattr(cache_module, "MEMORY_ENTRIES", 2)
    emb = _Counting(None)  # memory only: what leaves memory is encoded again when asked
    texts = ["a", "bb", "ccc", "a", "dddd"]
    out = emb.embed(texts)
    assert out.shape == (5, 4) and np.array_equal(out[0], out[3]) and len(emb.cache) == 2
    assert emb.encoded == ["a", "bb", "ccc", "dddd"]


def test_a_new_cache_reads_at_most_the_bound_from_its_file(tmp_path, monkeypatch):
    emb = _Counting(tmp_path / "e.sqlite")
    emb.embed([f"text {i}" for i in range(10)])
    emb.cache.close()
    monkeypatch.setattr(cache_module, "MEMORY_ENTRIES", 4)
    fresh = _Counting(tmp_path / "e.sqlite")
    assert len(fresh.cache) == 4
    fresh.embed([f"text {i}" for i in range(10)])
    assert fresh.encoded == []  # the other six were in the file
