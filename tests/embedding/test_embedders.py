"""Each embedder: shapes, unit norm, cache hits (memory and disk), and the errors users can trigger."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.embedding import (
    OneHotEmbedder,
    available_embedders,
    load_embedder,
    mpnet_dir,
)
from scone_bt.errors import ModelUnavailableError, UnknownNameError

TEXTS = ["Put salt on table", "Put pepper on table", "Put sugar on table", "Season with salt and pepper"]


def _check_vectors(vectors: np.ndarray, n: int, dim: int) -> None:
    assert vectors.shape == (n, dim)
    assert vectors.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(vectors, axis=1), 1.0, atol=1e-5)


@pytest.mark.parametrize("name", ["minilm", "glove"])
def test_semantic_embedder_shapes_norm_and_meaning(name, tmp_path):
    emb = load_embedder(name, tmp_path)
    vectors = emb.embed(TEXTS)
    _check_vectors(vectors, len(TEXTS), emb.dim)
    assert emb.name == name
    sims = vectors @ vectors[3]
    # the seasoning instruction is closer to salt than to sugar
    assert sims[0] > sims[2]


def test_minilm_dimension_and_cache_hits_then_disk_cache(tmp_path):
    emb = load_embedder("minilm", tmp_path)
    assert emb.dim == 384
    first = emb.embed(TEXTS)
    assert emb.cache.misses == len(TEXTS) and emb.cache.hits == 0
    calls = []
    original = emb._encode
    emb._encode = lambda texts: calls.append(list(texts)) or original(texts)
    again = emb.embed(TEXTS[::-1])
    assert calls == []  # every text served from the cache, no forward pass
    assert emb.cache.hits == len(TEXTS)
    np.testing.assert_array_equal(again, first[::-1])
    # a new embedder object (a new run) reads the SQLite cache: still no forward pass
    fresh = load_embedder("minilm", tmp_path)
    assert len(fresh.cache) >= len(TEXTS)
    fresh._encode = lambda texts: pytest.fail(f"forward pass for cached texts {texts}")
    np.testing.assert_allclose(fresh.embed(TEXTS), first, atol=0)
    assert (tmp_path / "embeddings.sqlite").is_file()


def test_embedding_one_text_twice_in_a_batch_and_empty_batch(tmp_path):
    emb = load_embedder("glove", tmp_path, disk_cache=False)
    out = emb.embed(["Put salt on table", "Put salt on table"])
    np.testing.assert_array_equal(out[0], out[1])
    assert emb.embed([]).shape == (0, emb.dim)


def test_glove_unknown_words_get_a_stable_unit_vector(tmp_path):
    emb = load_embedder("glove", tmp_path, disk_cache=False)
    a, b = emb.embed(["qzxvbnm wpqlkj", "zzqxw vvbnmq"])
    _check_vectors(np.stack([a, b]), 2, 50)
    again = load_embedder("glove", None, disk_cache=False).embed(["qzxvbnm wpqlkj"])[0]
    np.testing.assert_allclose(a, again)
    assert abs(float(a @ b)) < 0.9


def test_onehot_grows_and_closed_vocabulary_rejects_unknown():
    emb = load_embedder("onehot")
    vectors = emb.embed(TEXTS + TEXTS[:1])
    _check_vectors(vectors, 5, emb.dim)
    np.testing.assert_allclose(vectors[:4] @ vectors[:4].T, np.eye(4))
    np.testing.assert_array_equal(vectors[0], vectors[4])
    closed = OneHotEmbedder(vocabulary=TEXTS[:2])
    assert closed.dim == 2
    _check_vectors(closed.embed(TEXTS[:2]), 2, 2)
    with pytest.raises(UnknownNameError, match="Put salt on table"):
        closed.embed(["Put milk on table"])
    tiny = OneHotEmbedder(capacity=2)
    tiny.embed(TEXTS[:2])
    with pytest.raises(Exception, match="full"):
        tiny.embed(TEXTS[2:3])


def test_unknown_name_lists_valid_ones():
    with pytest.raises(UnknownNameError, match="minilm.*|.*glove"):
        load_embedder("bert-9000")


def test_mpnet_missing_names_the_install_command(tmp_path, monkeypatch):
    monkeypatch.setenv("SCONE_BT_CACHE", str(tmp_path / "empty"))
    monkeypatch.delenv("SCONE_BT_MPNET", raising=False)
    with pytest.raises(ModelUnavailableError, match="scone-models install mpnet"):
        load_embedder("mpnet", tmp_path)
    assert not next(i for i in available_embedders(tmp_path) if i.name == "mpnet").available


def test_local_directory_loads_as_sentence_transformer(tmp_path):
    from scone_bt.embedding import minilm_dir

    emb = load_embedder(str(minilm_dir()), tmp_path)
    _check_vectors(emb.embed(TEXTS[:2]), 2, 384)
    with pytest.raises(ModelUnavailableError):
        load_embedder(str(tmp_path), tmp_path)  # a directory that is no model


@pytest.mark.skipif(mpnet_dir() is None, reason="MPNet not assembled (scone-models install mpnet)")
def test_mpnet_when_installed(tmp_path):
    emb = load_embedder("mpnet", tmp_path)
    assert emb.dim == 768
    _check_vectors(emb.embed(TEXTS), len(TEXTS), 768)


def test_a_warm_cache_serves_minilm_without_loading_the_model(tmp_path) -> None:
    from scone_bt.embedding import load_embedder

    first = load_embedder("minilm", tmp_path)
    vec = first.embed(["Put salt on table"])
    again = load_embedder("minilm", tmp_path)
    again._model = None  # a fresh embedder of the same directory: nothing loaded yet
    assert again.dim == 384
    assert (again.embed(["Put salt on table"]) == vec).all()
    assert again._model is None  # served from the on-disk cache, torch never asked
    again.embed(["Put sugar on table"])  # a miss loads the model
    assert again._model is not None
